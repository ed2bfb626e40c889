// Pieces' clips replayed from the step before (contact/clip_replay.hpp): a pair evaluated with
// its record of the step before gives the fresh evaluation's results bit for bit, whether the
// record is replayed (every vertex kept its side of every plane) or falls back to a fresh clip.
#include <catch2/catch.hpp>
#include <cstring>
#include <random>
#include <vector>

#include "contact/clip_replay.hpp"
#include "contact/potential_contact_kernels.hpp"
#include "test_potential_contact_support.hpp"

using namespace fdem;
using namespace fdem::test_contact;

namespace {

bool same_bits(const ContactPairResult& a, const ContactPairResult& b) {
  const auto same = [](const auto& x, const auto& y) {
    return std::memcmp(&x, &y, sizeof(x)) == 0;
  };
  bool equal = a.overlapping == b.overlapping && same(a.energy, b.energy) &&
               same(a.overlap_volume, b.overlap_volume) && same(a.normal_force, b.normal_force) &&
               same(a.centroid_weights_contactor, b.centroid_weights_contactor) &&
               same(a.centroid_weights_target, b.centroid_weights_target);
  for (int v = 0; v < 4; ++v)
    equal =
        equal &&
        std::memcmp(a.force_contactor[v].data(), b.force_contactor[v].data(), 3 * sizeof(double)) ==
            0 &&
        std::memcmp(a.force_target[v].data(), b.force_target[v].data(), 3 * sizeof(double)) == 0;
  return equal && std::memcmp(a.normal.data(), b.normal.data(), 3 * sizeof(double)) == 0 &&
         std::memcmp(a.centroid.data(), b.centroid.data(), 3 * sizeof(double)) == 0;
}

// A pair followed over `steps` steps, each corner moving by up to `step` (m) per step (a random
// rigid drift plus noise), evaluated fresh and with the record of the step before.
struct Followed {
  long evaluations = 0, mismatches = 0;
  std::uint64_t replayed = 0, clipped = 0;
};

void follow(std::mt19937_64& rng, TetCorners c, TetCorners t, int steps, double step,
            double sliver_tolerance, Followed& out) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Vec3 drift = step * random_unit(rng);
  PairClipRecords records;
  for (int s = 0; s < steps; ++s) {
    for (int v = 0; v < 4; ++v) {
      c.x[v] += drift + 0.3 * step * Vec3(u(rng), u(rng), u(rng));
      t.x[v] += 0.3 * step * Vec3(u(rng), u(rng), u(rng));
    }
    PreparedContactor prepared;
    prepare_contactor(c, prepared);
    TetGeometry geometry;
    compute_tet_geometry(t, geometry);
    const ContactPairResult fresh = potential_contact(prepared, geometry, 1e9, sliver_tolerance);
    ClipMemo memo = records.next();
    const ContactPairResult replayed =
        potential_contact(prepared, geometry, 1e9, sliver_tolerance, &memo);
    ++out.evaluations;
    out.mismatches += same_bits(fresh, replayed) ? 0 : 1;
    out.replayed += memo.replayed;
    out.clipped += memo.clipped;
  }
}

}  // namespace

TEST_CASE("a pair replayed from its record of the step before equals a fresh clip bit for bit",
          "[contact][clip_replay]") {
  std::mt19937_64 rng(20261129);
  for (const double tolerance : {0.0, 1e-6}) {
    Followed slow, fast;
    for (int p = 0; p < 150; ++p) {
      TetCorners c, t;
      random_overlapping_pair(rng, Vec3::Zero(), c, t);
      follow(rng, c, t, 30, 1e-5, tolerance, slow);  // a lasting contact: sides rarely change
      follow(rng, c, t, 30, 2e-2, tolerance, fast);  // sides change often: many fresh clips
    }
    INFO("tolerance " << tolerance << ": slow " << slow.replayed << " replayed, " << slow.clipped
                      << " clipped; fast " << fast.replayed << " replayed, " << fast.clipped
                      << " clipped");
    CHECK(slow.mismatches == 0);
    CHECK(fast.mismatches == 0);
    // Most of a slow pair's pieces replay; a fast pair's fall back to the clipper often.
    CHECK(slow.replayed > 10 * slow.clipped);
    CHECK(fast.clipped > fast.replayed / 10);
    CHECK(fast.replayed > 0);
  }
}

TEST_CASE("pressed faces sliding on unmatched meshes replay bit for bit",
          "[contact][clip_replay]") {
  // The upper tet's bottom face 1e-6 … 1e-3 into the lower tet's top face (z = 0), shifted and
  // turned in the plane, then sliding: the contact of blocks resting on blocks.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Followed total;
  for (int p = 0; p < 200; ++p) {
    const double depth = std::pow(10.0, -6.0 + 3.0 * u(rng));
    TetCorners lower, upper;
    face_on_face(rng, depth, lower, upper);
    follow(rng, upper, lower, 20, 0.01 * depth, 1e-6, total);
  }
  INFO(total.replayed << " replayed, " << total.clipped << " clipped");
  CHECK(total.mismatches == 0);
  CHECK(total.replayed > 5 * total.clipped);
}

TEST_CASE("a clip log replays the clipper's own vertices", "[contact][clip_replay]") {
  // One sub-tet-like piece cut by four planes through its interior, logged, then replayed on the
  // same values: the replay makes the same vertices and faces; a changed side is refused.
  using namespace piece_clip;
  Piece piece;
  piece.count = 4;
  const double other[4][4] = {
      {0.6, 0.2, -0.3, 0.5}, {-0.2, 0.7, 0.4, 0.1}, {0.3, -0.4, 0.6, 0.5}, {0.4, 0.5, 0.3, -0.2}};
  for (int s = 0; s < 4; ++s) {
    for (int a = 0; a < 4; ++a) piece.v[s].lam[a] = a == s ? 1.0 : 0.0;
    for (int b = 0; b < 4; ++b) piece.v[s].lam[4 + b] = other[s][b];
    for (int e = 0; e < 3; ++e) piece.v[s].next[e] = kTetNeighbours[s][e];
    piece.v[s].planes = 0;
  }
  Piece fresh = piece;
  ClipLog log;
  bool alive = true;
  for (int b = 0; b < 4 && alive; ++b)
    alive = clip_piece(fresh, 4 + b, 1u << (kOtherFaceShift + b), &log);
  REQUIRE(alive);
  PieceFaces faces;
  REQUIRE(walk_faces(fresh, faces));
  log_faces(faces, log);
  REQUIRE(log.valid);
  CHECK(fresh.count >= 7);  // every plane cut something

  Piece pool = piece;
  const PieceVertex* vertex[kMaxVertices];
  int n = 0;
  PieceFaces replayed_faces;
  REQUIRE(replay_piece(pool, log.bytes, log.bytes + log.size, vertex, n, replayed_faces) ==
          Replay::kept);
  REQUIRE(n == fresh.count);
  // The same coordinates bit for bit.  (The replay leaves the vertices' plane tags unset: the
  // faces it hands out carry their planes, compared below.)
  for (int v = 0; v < n; ++v)
    CHECK(std::memcmp(vertex[v]->lam, fresh.v[v].lam, sizeof(fresh.v[v].lam)) == 0);
  REQUIRE(replayed_faces.count == faces.count);
  REQUIRE(replayed_faces.length() == faces.length());
  CHECK(replayed_faces.bytes != replayed_faces.walked);  // read in place from the record
  CHECK(std::memcmp(replayed_faces.bytes, faces.bytes, static_cast<std::size_t>(faces.length())) ==
        0);

  // Corner 1 moved across plane 0 (outside before, inside now): refused, the corners untouched.
  Piece moved = piece;
  moved.v[1].lam[4] = 0.1;
  const Piece before = moved;
  REQUIRE(replay_piece(moved, log.bytes, log.bytes + log.size, vertex, n, replayed_faces) ==
          Replay::side_changed);
  for (int s = 0; s < 4; ++s)
    CHECK(std::memcmp(moved.v[s].lam, before.v[s].lam, sizeof(before.v[s].lam)) == 0);
}

TEST_CASE("a piece whose record no longer fits finds a clip met before, bit for bit",
          "[contact][clip_replay]") {
  // Aligned meshes: the upper tet's corners hover over the lower tet's side planes, so a piece's
  // clip swings between a few graphs.  Each pair here is evaluated at two positions in turn: after
  // the first two evaluations every clip has been met, and none is clipped afresh again.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  long mismatches = 0;
  std::uint64_t found = 0, clipped_later = 0;
  for (int p = 0; p < 100; ++p) {
    TetCorners lower, upper;
    face_on_face(rng, 1e-4, lower, upper);
    TetCorners shifted = upper;  // every corner moved across some plane and back
    for (int v = 0; v < 4; ++v) shifted.x[v] += 0.05 * Vec3(u(rng), u(rng), 0.0);
    PairClipRecords records;
    for (int step = 0; step < 6; ++step) {
      const TetCorners& now = step % 2 ? shifted : upper;
      PreparedContactor prepared;
      prepare_contactor(now, prepared);
      TetGeometry geometry;
      compute_tet_geometry(lower, geometry);
      const ContactPairResult fresh = potential_contact(prepared, geometry, 1e9, 1e-6);
      ClipMemo memo = records.next();
      const ContactPairResult replayed = potential_contact(prepared, geometry, 1e9, 1e-6, &memo);
      mismatches += same_bits(fresh, replayed) ? 0 : 1;
      if (step >= 2) {
        found += memo.found;
        clipped_later += memo.clipped;
      }
    }
  }
  INFO(found << " found, " << clipped_later << " clipped afresh after the first two steps");
  CHECK(mismatches == 0);
  CHECK(found > 100);
  CHECK(clipped_later == 0);
}

TEST_CASE("the clips met before keep one node per graph and find each by its masks",
          "[contact][clip_replay]") {
  using namespace piece_clip;
  // A sub-tet's corners with the other tet's barycentrics; clipped and added, then walked.
  const auto piece_with = [](const double(&other)[4][4]) {
    Piece piece;
    piece.count = 4;
    for (int s = 0; s < 4; ++s) {
      for (int a = 0; a < 4; ++a) piece.v[s].lam[a] = a == s ? 1.0 : 0.0;
      for (int b = 0; b < 4; ++b) piece.v[s].lam[4 + b] = other[s][b];
      for (int e = 0; e < 3; ++e) piece.v[s].next[e] = kTetNeighbours[s][e];
      piece.v[s].planes = 0;
    }
    return piece;
  };
  const double cut[4][4] = {
      {0.6, 0.2, -0.3, 0.5}, {-0.2, 0.7, 0.4, 0.1}, {0.3, -0.4, 0.6, 0.5}, {0.4, 0.5, 0.3, -0.2}};
  const double away[4][4] = {
      {-0.6, 0.2, 0.3, 0.5}, {-0.2, 0.7, 0.4, 0.1}, {-0.3, 0.4, 0.6, 0.5}, {-0.4, 0.5, 0.3, 0.2}};
  ClipTopologies topologies;
  const PieceVertex* vertex[kMaxVertices];
  int n = 0;
  PieceFaces faces;
  std::uint32_t terminal = ClipTopologies::kNone;
  Piece unknown = piece_with(cut);
  CHECK(walk_topologies(unknown, 2, topologies, terminal, vertex, n, faces) ==
        Replay::side_changed);

  Piece fresh = piece_with(cut);
  ClipLog log;
  for (int b = 0; b < 4; ++b) REQUIRE(clip_piece(fresh, 4 + b, 1u << (kOtherFaceShift + b), &log));
  PieceFaces fresh_faces;
  REQUIRE(walk_faces(fresh, fresh_faces));
  log_faces(fresh_faces, log);
  REQUIRE(log.valid);
  const std::uint32_t added = topologies.add(2, log.bytes, log.size);
  REQUIRE(added != ClipTopologies::kNone);
  const std::size_t nodes = topologies.size();
  CHECK(topologies.add(2, log.bytes, log.size) == added);  // the same graph: no new node
  CHECK(topologies.size() == nodes);
  CHECK(topologies.depth(added) == 4);

  Piece again = piece_with(cut);
  REQUIRE(walk_topologies(again, 2, topologies, terminal, vertex, n, faces) == Replay::kept);
  CHECK(terminal == added);
  REQUIRE(n == fresh.count);
  for (int v = 0; v < n; ++v)
    CHECK(std::memcmp(vertex[v]->lam, fresh.v[v].lam, sizeof(fresh.v[v].lam)) == 0);
  REQUIRE(faces.length() == fresh_faces.length());
  CHECK(std::memcmp(faces.bytes, fresh_faces.bytes, static_cast<std::size_t>(faces.length())) == 0);
  // Another sub-tet has its own root: the same masks do not lead there.
  Piece other_root = piece_with(cut);
  CHECK(walk_topologies(other_root, 1, topologies, terminal, vertex, n, faces) ==
        Replay::side_changed);

  // A piece every corner of which lies outside plane 0: cut off whole, found as such once added.
  Piece gone = piece_with(away);
  ClipLog gone_log;
  REQUIRE_FALSE(clip_piece(gone, 4, 1u << kOtherFaceShift, &gone_log));
  REQUIRE(gone_log.valid);
  const std::uint32_t cut_off = topologies.add(2, gone_log.bytes, gone_log.size);
  REQUIRE(cut_off != ClipTopologies::kNone);
  Piece gone_again = piece_with(away);
  CHECK(walk_topologies(gone_again, 2, topologies, terminal, vertex, n, faces) ==
        Replay::clipped_away);
  CHECK(terminal == cut_off);
}

TEST_CASE("clip records keep their bytes as the buffer grows, shrinks and is cleared",
          "[contact][clip_replay]") {
  RecordBytes record;
  REQUIRE(record.empty());
  std::vector<std::uint8_t> expected;
  // Appends of every length from 0 to 40 bytes, well past the first capacity (256 B).
  for (int length = 0; length <= 40; ++length) {
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(length));
    for (int j = 0; j < length; ++j) bytes[static_cast<std::size_t>(j)] = std::uint8_t(length + j);
    record.append_pair(std::uint8_t(length), std::uint8_t(255 - length));
    expected.push_back(std::uint8_t(length));
    expected.push_back(std::uint8_t(255 - length));
    record.append(bytes.data(), bytes.size());
    expected.insert(expected.end(), bytes.begin(), bytes.end());
  }
  REQUIRE(record.size() == expected.size());
  REQUIRE(std::memcmp(record.data(), expected.data(), expected.size()) == 0);
  // A pair's record dropped: back to where it started; shrinking never grows.
  record.shrink_to(100);
  REQUIRE(record.size() == 100);
  record.shrink_to(200);
  REQUIRE(record.size() == 100);
  REQUIRE(std::memcmp(record.data(), expected.data(), 100) == 0);
  // Cleared, it keeps its storage for the next step's records.
  const std::uint8_t* storage = record.data();
  record.clear();
  REQUIRE(record.empty());
  record.append_pair(7, 9);
  REQUIRE(record.data() == storage);
  REQUIRE(record.data()[0] == 7);
  REQUIRE(record.data()[1] == 9);
  record.release();
  REQUIRE(record.empty());
  REQUIRE(record.data() == nullptr);
}
