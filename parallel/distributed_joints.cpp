#include "parallel/distributed_joints.hpp"

#include <algorithm>
#include <array>
#include <functional>
#include <limits>
#include <numeric>

#include "core/error.hpp"
#include "core/joint_placement.hpp"
#include "core/travelling_state.hpp"
#include "parallel/boundary_matching.hpp"
#include "parallel/directory_hash.hpp"
#include "parallel/enclosed_tets.hpp"

namespace fdem {

namespace {

using Key = std::array<std::int64_t, 3>;

int face_rank(std::int32_t body, const std::int64_t* key, int ranks) {
  return directory_rank({body, key[0], key[1], key[2]}, ranks);
}

int block_owner(const std::vector<GlobalId>& block, GlobalId g) {
  return static_cast<int>(std::upper_bound(block.begin(), block.end(), g) - block.begin()) - 1;
}

// A face of a local tet: sorted mesh node numbers, body, the tet (index in face_tets).
struct LocalFace {
  Key key;
  std::int32_t body;
  LocalIndex tet;
};

// A face travelling to its face directory.
struct FaceRecord {
  std::int64_t key[3];  // sorted mesh node numbers
  GlobalId tet;
  GlobalId node[3];       // the tet's model node at key[i]
  double volume, extent;  // the tet's volume (m³) and largest box side (m)
  std::int32_t body, piece;
};
// Two faces of one block that paired where they are: only their count travels (a third face
// elsewhere makes the mesh non-manifold).
struct FacePresence {
  std::int64_t key[3];
  std::int32_t body, count;
};
// A boundary face, back to its tet's owner.
struct BoundaryNotice {
  GlobalId tet;
  std::int64_t key[3];
};
// Is `key` (sorted partner nodes) a boundary face of `body`?  Asked by the owner of the tet of
// a boundary face whose node i has partner[i].
struct FaceQuery {
  std::int64_t key[3];
  std::int64_t partner[3];
  GlobalId tet;
  GlobalId node[3];
  double volume, extent;
  std::int32_t body, group, counter, unused;
};
// A joint found (role 0, to the owner of tet A) or the bond of tet B (role 1, to its owner).
struct DraftRecord {
  GlobalId tet[2];      // A (smaller gid), B
  GlobalId a[3], b[3];  // model nodes, b[i] coincident with a[i]
  double volume[2], extent[2];
  std::int32_t group, role;
};

DraftRecord make_draft(GlobalId tet_a, const GlobalId (&a)[3], double volume_a, double extent_a,
                       GlobalId tet_b, const GlobalId (&b)[3], double volume_b, double extent_b,
                       std::int32_t group) {
  DraftRecord d{{tet_a, tet_b},
                {a[0], a[1], a[2]},
                {b[0], b[1], b[2]},
                {volume_a, volume_b},
                {extent_a, extent_b},
                group,
                0};
  if (d.tet[0] > d.tet[1]) {  // canonical: A has the smaller gid
    std::swap(d.tet[0], d.tet[1]);
    for (int i = 0; i < 3; ++i) std::swap(d.a[i], d.b[i]);
    std::swap(d.volume[0], d.volume[1]);
    std::swap(d.extent[0], d.extent[1]);
  }
  return d;
}

// Errors, ordered as the serial builder meets them: per body (stage = body) the non-manifold
// check (kind 0), a node too far from the origin to match (1), no touching pieces (2); then per
// interface k (stage = bodies + k) a node of B too far (0), of A (1), no match (2).  Details:
// the face's sorted mesh nodes (and the node's place in it).
struct ErrorKey {
  std::int64_t stage = std::numeric_limits<std::int64_t>::max(), kind = 0, detail[4] = {0, 0, 0, 0};
  bool operator<(const ErrorKey& o) const {
    if (stage != o.stage) return stage < o.stage;
    if (kind != o.kind) return kind < o.kind;
    return std::lexicographical_compare(detail, detail + 4, o.detail, o.detail + 4);
  }
};

class FirstError {
 public:
  void offer(const ErrorKey& key, const std::function<std::string()>& message) {
    if (key < key_) {
      key_ = key;
      message_ = message();
    }
  }
  // Collective: every rank throws the error the serial builder would have met first.
  void raise(const Communicator& comm) const {
    const std::vector<ErrorKey> all = comm.allgather(key_);
    const auto first = std::min_element(all.begin(), all.end());  // lowest rank among equals
    if (first->stage == ErrorKey{}.stage) return;
    const bool mine = first - all.begin() == comm.rank();
    comm.run_collectively([&] {
      if (mine) throw InputError(message_);
    });
  }

 private:
  ErrorKey key_;
  std::string message_;
};

struct Roles {
  std::vector<char> jointed, bonded;
  std::vector<std::vector<std::int32_t>> as_a, as_b;  // per body: interfaces it is side A / B of
  explicit Roles(const Scene& scene)
      : jointed(scene.bodies.size()),
        bonded(scene.bodies.size()),
        as_a(scene.bodies.size()),
        as_b(scene.bodies.size()) {
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
      jointed[b] = scene.bodies[b].joints == JointPlacement::all;
      bonded[b] = scene.bodies[b].joints == JointPlacement::interfaces;
    }
    for (std::size_t k = 0; k < scene.interfaces.size(); ++k) {
      as_a[static_cast<std::size_t>(scene.interfaces[k].body_a)].push_back(
          static_cast<std::int32_t>(k));
      as_b[static_cast<std::size_t>(scene.interfaces[k].body_b)].push_back(
          static_cast<std::int32_t>(k));
    }
  }
  // Whether the body's boundary faces are matched by position.
  bool matched(std::size_t b) const { return bonded[b] || !as_a[b].empty() || !as_b[b].empty(); }
};

// The law keys the whole model's joints use, ascending, from each rank's: the (group, size bin)
// pairs are gathered (a few per group), the strength bins travel as one flag per (pair,
// bin) over each group's range of bins in a max-reduction — so no rank gathers every rank's
// keys, which with a strength distribution would be hundreds per pair.
std::vector<JointLawKey> global_law_keys(std::vector<JointLawKey> local, std::int64_t n_groups,
                                         const Communicator& comm) {
  using Pair = std::array<std::int64_t, 2>;
  std::vector<Pair> pairs;
  std::vector<std::int64_t> lowest(static_cast<std::size_t>(n_groups),
                                   std::numeric_limits<std::int64_t>::max());
  std::vector<std::int64_t> highest(static_cast<std::size_t>(n_groups),
                                    std::numeric_limits<std::int64_t>::min());
  std::sort(local.begin(), local.end());
  local.erase(std::unique(local.begin(), local.end()), local.end());
  for (const JointLawKey& k : local) {
    pairs.push_back({k.group, k.size_bin});
    auto g = static_cast<std::size_t>(k.group);
    lowest[g] = std::min(lowest[g], k.strength_bin);
    highest[g] = std::max(highest[g], k.strength_bin);
  }
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  pairs = comm.allgatherv(pairs);
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  comm.min_in_place(lowest);
  comm.max_in_place(highest);
  // Flag of (pair p, strength bin b): offset[p] + b − lowest[group].
  std::vector<std::int64_t> offset(pairs.size() + 1, 0);
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const auto g = static_cast<std::size_t>(pairs[p][0]);
    offset[p + 1] = offset[p] + highest[g] - lowest[g] + 1;
  }
  std::vector<std::int32_t> used(static_cast<std::size_t>(offset.back()), 0);
  for (const JointLawKey& k : local) {
    const auto p = static_cast<std::size_t>(
        std::lower_bound(pairs.begin(), pairs.end(), Pair{k.group, k.size_bin}) - pairs.begin());
    used[static_cast<std::size_t>(offset[p] + k.strength_bin -
                                  lowest[static_cast<std::size_t>(k.group)])] = 1;
  }
  comm.max_in_place(used);
  std::vector<JointLawKey> keys;
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const std::int64_t low = lowest[static_cast<std::size_t>(pairs[p][0])];
    for (std::int64_t f = offset[p]; f < offset[p + 1]; ++f)
      if (used[static_cast<std::size_t>(f)])
        keys.push_back({pairs[p][0], pairs[p][1], low + f - offset[p]});
  }
  return keys;
}

}  // namespace

bool body_has_faces(const Scene& scene, std::size_t body) {
  if (scene.bodies[body].joints != JointPlacement::none) return true;
  for (const InterfaceSpec& i : scene.interfaces)
    if (i.body_a == static_cast<int>(body) || i.body_b == static_cast<int>(body)) return true;
  return false;
}

BlockJoints place_block_joints(const Scene& scene, const std::vector<std::string>& sources,
                               const Model& block, const std::vector<double>& tet_extent,
                               const std::vector<FaceTet>& face_tets,
                               const std::vector<GlobalId>& tet_block, double tol,
                               const Communicator& comm) {
  const int ranks = comm.size(), me = comm.rank();
  const GlobalId first_tet = tet_block[static_cast<std::size_t>(me)];
  const TetArrays& tets = block.tets;
  // Local index of a tet of this block, checked in 64 bits before it is narrowed.
  const auto block_tet = [&](GlobalId tet) {
    FDEM_VERIFY(tet >= first_tet && tet - first_tet < tets.size(), "a tet of this rank's block");
    return static_cast<LocalIndex>(tet - first_tet);
  };
  const NodeArrays& nodes = block.nodes;
  const std::int32_t n_bodies = static_cast<std::int32_t>(scene.bodies.size());
  const std::int32_t n_materials = static_cast<std::int32_t>(scene.materials.size());
  const Roles roles(scene);
  FirstError error;
  BlockJoints out;
  out.bonded.assign(static_cast<std::size_t>(tets.size()), 0);
  out.partner_extent.assign(static_cast<std::size_t>(tets.size()), 0.0);
  const auto material_of = [&](std::int32_t b) { return scene.bodies[b].material; };
  // The local node of a face tet at mesh node m.
  const auto node_at = [&](const FaceTet& ft, std::int64_t m) {
    for (int c = 0; c < 4; ++c)
      if (ft.mesh_node[c] == m) return tets.nodes[4 * static_cast<std::size_t>(ft.tet) + c];
    FDEM_VERIFY(false, "a face's mesh node is a corner of its tet");
    return LocalIndex{-1};
  };
  const auto face_record = [&](const FaceTet& ft, const Key& key) {
    FaceRecord r{};
    std::copy_n(key.data(), 3, r.key);
    r.tet = tets.gid[ft.tet];
    for (int i = 0; i < 3; ++i) r.node[i] = nodes.gid[node_at(ft, key[i])];
    r.volume = tets.volume0[ft.tet];
    r.extent = tet_extent[static_cast<std::size_t>(ft.tet)];
    r.body = ft.body;
    r.piece = tets.piece[ft.tet];
    return r;
  };
  // At the owner of tet A: the joint oriented, its area and size bin (role 0).  At the owner of
  // a tet: it is bonded, to a tet of that extent.
  struct Placed {
    StartJoint joint;
    std::int32_t group;
    std::int64_t bin;
  };
  std::vector<Placed> placed;
  const auto bonded = [&](GlobalId tet, double partner_extent) {
    const LocalIndex t = block_tet(tet);  // a joint reaches the owners of its tets
    out.bonded[static_cast<std::size_t>(t)] = 1;
    double& extent = out.partner_extent[static_cast<std::size_t>(t)];
    extent = std::max(extent, partner_extent);
    return t;
  };
  const std::function<void(const DraftRecord&)> bond = [&](const DraftRecord& d) {
    bonded(d.tet[1], d.extent[0]);
  };
  const std::function<void(const DraftRecord&)> place = [&](const DraftRecord& d) {
    const LocalIndex t = bonded(d.tet[0], d.extent[1]);
    Placed p{};
    StartJoint& j = p.joint;
    j.tets[0] = d.tet[0];
    j.tets[1] = d.tet[1];
    LocalIndex a[3] = {-1, -1, -1}, opposite = -1;
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = tets.nodes[4 * static_cast<std::size_t>(t) + c];
      bool on_face = false;
      for (int i = 0; i < 3; ++i)
        if (nodes.gid[n] == d.a[i]) {
          a[i] = n;
          on_face = true;
        }
      if (!on_face) opposite = n;
    }
    FDEM_VERIFY(a[0] >= 0 && a[1] >= 0 && a[2] >= 0 && opposite >= 0,
                "a joint's face nodes are three corners of its tet A");
    GlobalId b[3] = {d.b[0], d.b[1], d.b[2]};
    if (joint_face_turned(nodes.x0(a[0]), nodes.x0(a[1]), nodes.x0(a[2]), nodes.x0(opposite))) {
      std::swap(a[1], a[2]);
      std::swap(b[1], b[2]);
    }
    for (int i = 0; i < 3; ++i) {
      j.nodes[i] = nodes.gid[a[i]];
      j.nodes[3 + i] = b[i];
    }
    j.area0 = joint_face_area(nodes.x0(a[0]), nodes.x0(a[1]), nodes.x0(a[2]));
    p.group = d.group;
    p.bin = joint_size_bin(tets.volume0[t], d.volume[1], j.area0);
    placed.push_back(p);
  };
  // Joints found here go to the owners of their tets (this rank's: at once).
  std::vector<std::vector<DraftRecord>> drafts(static_cast<std::size_t>(ranks));
  const auto send_draft = [&](const DraftRecord& d) {
    const int owner_a = block_owner(tet_block, d.tet[0]),
              owner_b = block_owner(tet_block, d.tet[1]);
    if (owner_a == me)
      place(d);
    else
      drafts[static_cast<std::size_t>(owner_a)].push_back(d);
    if (owner_b == me) {
      bond(d);
    } else {
      DraftRecord b = d;
      b.role = 1;
      drafts[static_cast<std::size_t>(owner_b)].push_back(b);
    }
  };

  // 1  Faces of the local tets; pairs within the block are joined here.
  std::vector<std::vector<FaceRecord>> face_out(static_cast<std::size_t>(ranks));
  std::vector<std::vector<FacePresence>> presence_out(static_cast<std::size_t>(ranks));
  {
    std::vector<LocalFace> faces;
    faces.reserve(4 * face_tets.size());
    for (std::size_t i = 0; i < face_tets.size(); ++i)
      for (int skip = 0; skip < 4; ++skip) {
        LocalFace f{{0, 0, 0}, face_tets[i].body, static_cast<LocalIndex>(i)};
        int k = 0;
        for (int c = 0; c < 4; ++c)
          if (c != skip) f.key[k++] = face_tets[i].mesh_node[c];
        std::sort(f.key.begin(), f.key.end());
        faces.push_back(f);
      }
    std::sort(faces.begin(), faces.end(), [](const LocalFace& a, const LocalFace& b) {
      if (a.body != b.body) return a.body < b.body;
      return a.key != b.key ? a.key < b.key : a.tet < b.tet;
    });
    for (std::size_t i = 0; i < faces.size();) {
      std::size_t j = i + 1;
      while (j < faces.size() && faces[j].body == faces[i].body && faces[j].key == faces[i].key)
        ++j;
      const LocalFace& f = faces[i];
      const int rank = face_rank(f.body, f.key.data(), ranks);
      if (j - i == 1) {
        face_out[static_cast<std::size_t>(rank)].push_back(face_record(face_tets[f.tet], f.key));
      } else {
        presence_out[static_cast<std::size_t>(rank)].push_back(
            {{f.key[0], f.key[1], f.key[2]}, f.body, static_cast<std::int32_t>(j - i)});
        if (j - i == 2 && roles.jointed[static_cast<std::size_t>(f.body)]) {
          const FaceRecord p = face_record(face_tets[f.tet], f.key);
          const FaceRecord q = face_record(face_tets[faces[i + 1].tet], f.key);
          send_draft(make_draft(p.tet, p.node, p.volume, p.extent, q.tet, q.node, q.volume,
                                q.extent, material_of(f.body)));
        }
      }
      i = j;
    }
  }

  // 1b Face directory: counts, joints across blocks, boundary faces.
  std::vector<FaceRecord> boundary;  // boundary faces this rank answers for, by (body, key)
  std::vector<BoundaryMeshNode> jointed_boundary;  // their nodes, in `joints: all` bodies
  std::vector<std::vector<BoundaryNotice>> notices(static_cast<std::size_t>(ranks));
  {
    std::vector<FaceRecord> singles = comm.exchange(face_out);
    release(face_out);
    std::vector<FacePresence> presences = comm.exchange(presence_out);
    release(presence_out);
    // Both kinds as (body, key, count, single or −1), grouped by face.
    struct Entry {
      std::int32_t body;
      Key key;
      std::int32_t count;
      std::int64_t single;
    };
    std::vector<Entry> entries;
    entries.reserve(singles.size() + presences.size());
    for (std::size_t i = 0; i < singles.size(); ++i)
      entries.push_back({singles[i].body,
                         {singles[i].key[0], singles[i].key[1], singles[i].key[2]},
                         1,
                         static_cast<std::int64_t>(i)});
    for (const FacePresence& p : presences)
      entries.push_back({p.body, {p.key[0], p.key[1], p.key[2]}, p.count, -1});
    release(presences);
    std::sort(entries.begin(), entries.end(), [&](const Entry& a, const Entry& b) {
      if (a.body != b.body) return a.body < b.body;
      if (a.key != b.key) return a.key < b.key;
      const GlobalId ta = a.single < 0 ? -1 : singles[static_cast<std::size_t>(a.single)].tet;
      const GlobalId tb = b.single < 0 ? -1 : singles[static_cast<std::size_t>(b.single)].tet;
      return ta < tb;
    });
    std::vector<const FaceRecord*> here;  // the singles of one face
    for (std::size_t i = 0; i < entries.size();) {
      std::size_t j = i;
      std::int64_t count = 0;
      here.clear();
      while (j < entries.size() && entries[j].body == entries[i].body &&
             entries[j].key == entries[i].key) {
        count += entries[j].count;
        if (entries[j].single >= 0)
          here.push_back(&singles[static_cast<std::size_t>(entries[j].single)]);
        ++j;
      }
      const std::int32_t b = entries[i].body;
      const Key& key = entries[i].key;
      i = j;
      if (count >= 3) {
        error.offer({b, 0, {key[0], key[1], key[2], 0}},
                    [&] { return non_manifold_message(scene.bodies[b].name, sources[b], key); });
      } else if (count == 2 && here.size() == 2 && roles.jointed[static_cast<std::size_t>(b)]) {
        const FaceRecord &p = *here[0], &q = *here[1];
        send_draft(make_draft(p.tet, p.node, p.volume, p.extent, q.tet, q.node, q.volume, q.extent,
                              material_of(b)));
      }
      if (count == 1 && roles.jointed[static_cast<std::size_t>(b)])
        for (int k = 0; k < 3; ++k) jointed_boundary.push_back({b, key[k]});
      if (count == 1 && roles.matched(static_cast<std::size_t>(b))) {
        boundary.push_back(*here[0]);
        notices[static_cast<std::size_t>(block_owner(tet_block, here[0]->tet))].push_back(
            {here[0]->tet, {key[0], key[1], key[2]}});
      }
    }
  }

  // 2–3  Owners of boundary faces: their nodes' partners (parallel/boundary_matching).
  struct OwnedBoundary {
    Key key;
    LocalIndex tet;
    std::int32_t body;
    LocalIndex node[3];
  };
  std::vector<OwnedBoundary> owned_boundary;
  std::vector<NodeMatch> matches;  // partners of this rank's boundary nodes
  for (const BoundaryNotice& n : comm.exchange(notices)) {
    const LocalIndex t = block_tet(n.tet);
    const auto it = std::lower_bound(face_tets.begin(), face_tets.end(), t,
                                     [](const FaceTet& f, LocalIndex v) { return f.tet < v; });
    FDEM_VERIFY(it != face_tets.end() && it->tet == t, "a boundary face's tet is a face tet");
    OwnedBoundary f{{n.key[0], n.key[1], n.key[2]}, t, it->body, {}};
    for (int i = 0; i < 3; ++i) f.node[i] = node_at(*it, f.key[i]);
    owned_boundary.push_back(f);
  }
  release(notices);
  {
    // Each boundary node once (a split body's copies of one mesh node: once).
    std::vector<BoundaryPoint> points;
    for (const OwnedBoundary& f : owned_boundary)
      for (int i = 0; i < 3; ++i) {
        const Vec3 x = nodes.x0(f.node[i]);
        points.push_back({f.body, nodes.piece[f.node[i]], f.key[i], {x[0], x[1], x[2]}});
      }
    const auto by_node = [](const BoundaryPoint& a, const BoundaryPoint& b) {
      return a.body != b.body ? a.body < b.body : a.mesh_node < b.mesh_node;
    };
    std::sort(points.begin(), points.end(), by_node);
    points.erase(std::unique(points.begin(), points.end(),
                             [](const BoundaryPoint& a, const BoundaryPoint& b) {
                               return a.body == b.body && a.mesh_node == b.mesh_node;
                             }),
                 points.end());
    std::vector<std::string> far;
    matches = match_boundary_points(scene, points, tol, comm, &far);
    // A node too far from the origin to match: where the serial builder meets it first.
    for (const OwnedBoundary& f : owned_boundary)
      for (int i = 0; i < 3; ++i) {
        const BoundaryPoint probe{f.body, 0, f.key[i], {0, 0, 0}};
        const std::size_t at = static_cast<std::size_t>(
            std::lower_bound(points.begin(), points.end(), probe, by_node) - points.begin());
        if (far[at].empty()) continue;
        const auto b = static_cast<std::size_t>(f.body);
        const auto offer = [&](std::int64_t stage, std::int64_t kind) {
          error.offer({stage, kind, {f.key[0], f.key[1], f.key[2], i}}, [&] { return far[at]; });
        };
        if (roles.bonded[b]) offer(f.body, 1);
        for (std::int32_t k : roles.as_b[b]) offer(n_bodies + k, 0);
        for (std::int32_t k : roles.as_a[b]) offer(n_bodies + k, 1);
      }
  }

  // 4  Owners of boundary faces: the partner triangles, asked of their face directories.
  {
    const auto partner = [&](std::int32_t body, std::int64_t mesh_node, std::int32_t target) {
      const NodeMatch probe{mesh_node, 0, body, target};
      const auto it = std::lower_bound(matches.begin(), matches.end(), probe, match_order);
      return it != matches.end() && it->body == body && it->mesh_node == mesh_node &&
                     it->target == target
                 ? it->partner
                 : std::int64_t{-1};
    };
    std::vector<std::vector<FaceQuery>> queries(static_cast<std::size_t>(ranks));
    for (const OwnedBoundary& f : owned_boundary) {
      const auto b = static_cast<std::size_t>(f.body);
      FaceQuery q{};
      q.tet = tets.gid[f.tet];
      for (int i = 0; i < 3; ++i) q.node[i] = nodes.gid[f.node[i]];
      q.volume = tets.volume0[f.tet];
      q.extent = tet_extent[static_cast<std::size_t>(f.tet)];
      const auto ask = [&](std::int32_t target, std::int32_t body, std::int32_t group,
                           std::int32_t counter) {
        for (int i = 0; i < 3; ++i)
          if ((q.partner[i] = partner(f.body, f.key[i], target)) < 0) return;
        std::copy_n(q.partner, 3, q.key);
        std::sort(q.key, q.key + 3);
        q.body = body;
        q.group = group;
        q.counter = counter;
        queries[static_cast<std::size_t>(face_rank(body, q.key, ranks))].push_back(q);
      };
      if (roles.bonded[b]) {
        const NodeMatch probe{f.key[0], 0, f.body, 0};
        auto it = std::lower_bound(matches.begin(), matches.end(), probe, match_order);
        for (; it != matches.end() && it->body == f.body && it->mesh_node == f.key[0]; ++it)
          ask(it->target, f.body, material_of(f.body), f.body);
      }
      for (std::int32_t k : roles.as_a[b])
        ask(-1 - k, scene.interfaces[static_cast<std::size_t>(k)].body_b, n_materials + k,
            n_bodies + k);
    }
    release(owned_boundary);

    // 5  Face directory: a partner triangle that is a boundary face makes a joint.
    std::vector<std::int64_t> counts(static_cast<std::size_t>(n_bodies) + scene.interfaces.size(),
                                     0);
    const auto by_face = [](const FaceRecord& p, const FaceRecord& q) {
      if (p.body != q.body) return p.body < q.body;
      return std::lexicographical_compare(p.key, p.key + 3, q.key, q.key + 3);
    };
    std::sort(boundary.begin(), boundary.end(), by_face);
    for (const FaceQuery& q : comm.exchange(queries)) {
      FaceRecord probe{};
      std::copy_n(q.key, 3, probe.key);
      probe.body = q.body;
      const auto it = std::lower_bound(boundary.begin(), boundary.end(), probe, by_face);
      if (it == boundary.end() || by_face(probe, *it)) continue;  // not one boundary triangle
      GlobalId b_nodes[3];
      for (int i = 0; i < 3; ++i) {
        const int at = static_cast<int>(std::find(it->key, it->key + 3, q.partner[i]) - it->key);
        FDEM_VERIFY(at < 3, "a partner triangle holds the partner nodes");
        b_nodes[i] = it->node[at];
      }
      send_draft(make_draft(q.tet, q.node, q.volume, q.extent, it->tet, b_nodes, it->volume,
                            it->extent, q.group));
      ++counts[static_cast<std::size_t>(q.counter)];
    }
    comm.sum_in_place(counts);
    for (std::int32_t b = 0; b < n_bodies; ++b)
      if (roles.bonded[static_cast<std::size_t>(b)] && counts[static_cast<std::size_t>(b)] == 0)
        error.offer({b, 2, {0, 0, 0, 0}}, [&] {
          return no_touching_pieces_message(scene, static_cast<std::size_t>(b), sources[b]);
        });
    for (std::size_t k = 0; k < scene.interfaces.size(); ++k)
      if (counts[static_cast<std::size_t>(n_bodies) + k] == 0)
        error.offer({n_bodies + static_cast<std::int64_t>(k), 2, {0, 0, 0, 0}},
                    [&] { return no_interface_match_message(scene, k, tol); });
  }
  error.raise(comm);

  // 6  Owners of tet A (joints) and of tet B (bonds) not reached yet.
  std::vector<DraftRecord> arrived = comm.exchange(drafts);
  release(drafts);
  for (const DraftRecord& d : arrived) (d.role == 0 ? place : bond)(d);
  release(arrived);

  // 7  Joint gids in ascending (gid A, gid B); laws in ascending key over all ranks.
  std::sort(placed.begin(), placed.end(), [](const Placed& p, const Placed& q) {
    return p.joint.tets[0] != q.joint.tets[0] ? p.joint.tets[0] < q.joint.tets[0]
                                              : p.joint.tets[1] < q.joint.tets[1];
  });
  const std::vector<std::int64_t> per_rank =
      comm.allgather(static_cast<std::int64_t>(placed.size()));
  const GlobalId base =
      block.gid_offset + std::accumulate(per_rank.begin(), per_rank.begin() + me, std::int64_t{0});
  out.n_joints = std::accumulate(per_rank.begin(), per_rank.end(), std::int64_t{0});
  std::vector<JointLawKey> law_key(placed.size());
  for (std::size_t i = 0; i < placed.size(); ++i) {
    placed[i].joint.gid = base + static_cast<GlobalId>(i);
    law_key[i] = {
        placed[i].group, placed[i].bin,
        joint_strength_bin(scene, placed[i].group, placed[i].joint.gid, block.gid_offset)};
  }
  const std::int64_t n_groups =
      static_cast<std::int64_t>(scene.materials.size() + scene.interfaces.size());
  const std::vector<JointLawKey> keys = global_law_keys(law_key, n_groups, comm);
  for (const JointLawKey& k : keys) out.laws.push_back(joint_law(scene, k));
  out.joints.reserve(placed.size());
  for (std::size_t i = 0; i < placed.size(); ++i) {
    StartJoint j = placed[i].joint;
    j.law = static_cast<std::int32_t>(std::lower_bound(keys.begin(), keys.end(), law_key[i]) -
                                      keys.begin());
    out.joints.push_back(j);
  }
  // 8  Enclosed tets (bonded on all four faces): their joint state says so.
  const std::vector<std::uint8_t> enclosed =
      enclosed_face_tets(std::move(jointed_boundary), face_tets, roles.jointed, comm);
  for (std::size_t i = 0; i < face_tets.size(); ++i)
    if (enclosed[i])
      out.bonded[static_cast<std::size_t>(face_tets[i].tet)] =
          static_cast<std::uint8_t>(TetJointState::enclosed);
  return out;
}

}  // namespace fdem
