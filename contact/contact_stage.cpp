#include "contact/contact_stage.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_set>

#include "contact/detection.hpp"
#include "contact/potential_contact_kernels.hpp"
#include "contact/tet_distance.hpp"
#include "core/error.hpp"
#include "core/tet_kernels.hpp"

namespace fdem {

namespace {
// Auto penalty: 10 E keeps the kinetic energy recovered in an impact above 99 % (docs/references.md
// 2) and the penetration under 10 % of the element size at the material's strength scale.
constexpr double auto_penalty_factor = 10.0;

// From the piece's body: no table per piece (a rank may not know every piece of the model).
bool piece_fixed(const Model& model, std::int32_t piece) {
  return model.body_fixed[model.pieces.body_of(piece)];
}
}  // namespace

ContactStage::ContactStage(const Model& model, ContactSettings settings) {
  for (const MaterialProperties& m : model.materials) {
    penalty_.push_back(m.contact.auto_penalty ? auto_penalty_factor * m.young : m.contact.penalty);
    friction_coefficient_.push_back(m.contact.friction);
    damping_ratio_.push_back(m.contact.damping);
  }
  x_at_detection_ = model.nodes.x;  // no detection yet: detected_ says one is due
  skip_enclosed_ = settings.skip_enclosed;
  exact_narrowing_ = settings.exact_narrowing;
  // The anchors' lag: long against the contact's vibrations (following the centroid at once, a
  // column of blocks on an incline rings at ~600 Hz ever louder and breaks away; with 0.01 s its
  // vibration still grows, slowly), short against the shift of a rocking block's load onto its
  // toe (never following, a block at 0.975 μ on a tilting table turns about the normal and
  // slides).  docs/verification.md, "Static friction on an incline".
  FDEM_VERIFY(settings.friction_anchor_lag > 0.0, "friction anchor lag > 0");
  friction_anchor_lag_ = settings.friction_anchor_lag;
  body_cracked_.assign(static_cast<std::size_t>(std::max(model.pieces.bodies(), 0)), 0);
  buffer_ = settings.buffer;
  if (buffer_ < 0) {
    std::vector<double> size = tet_sizes(model);
    std::nth_element(size.begin(), size.begin() + size.size() / 2, size.end());
    buffer_ = auto_buffer(size[size.size() / 2]);
  }
}

std::vector<double> ContactStage::tet_sizes(const Model& model) {
  const TetArrays& tets = model.tets;
  const double* x = model.nodes.x.data();
  std::vector<double> size;
  size.reserve(static_cast<std::size_t>(tets.size()));
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    if (!tets.is_owned(t)) continue;
    double largest = 0.0;
    for (int k = 0; k < 3; ++k) {
      double lo = x[3 * tets.nodes[4 * t] + k], hi = lo;
      for (int c = 1; c < 4; ++c) {
        lo = std::min(lo, x[3 * tets.nodes[4 * t + c] + k]);
        hi = std::max(hi, x[3 * tets.nodes[4 * t + c] + k]);
      }
      largest = std::max(largest, hi - lo);
    }
    size.push_back(largest);
  }
  return size;
}

bool ContactStage::needed(const Model& model) {
  std::int64_t free_pieces = 0;
  for (std::int32_t b = 0; b < model.pieces.bodies(); ++b)
    free_pieces += model.body_fixed[b] ? 0 : model.pieces.pieces_in_body(b);
  // A jointed body is one piece of many contact groups: its tets meet once joints break.
  const bool grouped =
      model.tets.contact_group.size() > 0 &&
      *std::max_element(model.tets.contact_group.begin(), model.tets.contact_group.end()) >= 1;
  return (model.pieces.size() >= 2 || grouped) && free_pieces >= 1;
}

double ContactStage::critical_time_step(const Model& model) const {
  const TetArrays& tets = model.tets;
  double dt = std::numeric_limits<double>::infinity();
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    if (!tets.is_owned(t)) continue;  // each tet counts once, on its owner
    Vec3 x[4];
    for (int c = 0; c < 4; ++c) x[c] = vec3_at(model.nodes.x.data(), tets.nodes[4 * t + c]);
    const double h = smallest_altitude(x);
    const double omega2 =
        96.0 * penalty_[tets.material[t]] / (model.materials[tets.material[t]].density * h * h);
    const double xi = damping_ratio_[tets.material[t]];
    dt = std::min(dt, 2.0 / std::sqrt(omega2) * (std::sqrt(1.0 + xi * xi) - xi));
  }
  return dt;
}

void ContactStage::compute_boxes(const Model& model, const double* x) {
  const TetArrays& tets = model.tets;
  lo_.resize(3 * tets.size());
  hi_.resize(3 * tets.size());
  for (LocalIndex t = 0; t < tets.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      double lo = x[3 * tets.nodes[4 * t] + k], hi = lo;
      for (int c = 1; c < 4; ++c) {
        const double v = x[3 * tets.nodes[4 * t + c] + k];
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      lo_[3 * t + k] = lo;
      hi_[3 * t + k] = hi;
    }
}

namespace {

// True if two tets have a node at the same reference position (nodes split from one mesh node).
bool share_reference_node(const Model& model, LocalIndex a, LocalIndex b) {
  const double* x0 = model.nodes.x0.data();
  for (int i = 0; i < 4; ++i) {
    const double* p = x0 + 3 * model.tets.nodes[4 * a + i];
    for (int j = 0; j < 4; ++j) {
      const double* q = x0 + 3 * model.tets.nodes[4 * b + j];
      if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) return true;
    }
  }
  return false;
}

// True if a face plane of one tet has every node of the other more than `distance` beyond it —
// then the two tets are more than `distance` apart.
bool tets_farther_than(const Model& model, const double* positions, LocalIndex a, LocalIndex b,
                       double distance) {
  Vec3 x[2][4];
  for (int c = 0; c < 4; ++c) {
    x[0][c] = vec3_at(positions, model.tets.nodes[4 * a + c]);
    x[1][c] = vec3_at(positions, model.tets.nodes[4 * b + c]);
  }
  for (int side = 0; side < 2; ++side) {
    const Vec3(&p)[4] = x[side];
    const Vec3(&q)[4] = x[1 - side];
    for (int k = 0; k < 4; ++k) {  // face opposite node k
      const Vec3& o = p[(k + 1) % 4];
      Vec3 n = (p[(k + 2) % 4] - o).cross(p[(k + 3) % 4] - o);
      const double length = n.norm();
      if (!(length > 0.0)) continue;
      n /= length;
      if (n.dot(p[k] - o) > 0.0) n = -n;  // outward
      double nearest = n.dot(q[0] - o);
      for (int c = 1; c < 4; ++c) nearest = std::min(nearest, n.dot(q[c] - o));
      if (nearest > distance) return true;
    }
  }
  return false;
}

}  // namespace

bool ContactStage::detection_due(const Model& model) const {
  const NodeArrays& nodes = model.nodes;
  return !detected_ ||
         detection_needed(
             max_node_displacement(nodes.x.data(), x_at_detection_.data(), nodes.n_owned), buffer_);
}

bool ContactStage::detect_if_needed(const Model& model) {
  if (!detection_due(model)) return false;
  detect(model);
  return true;
}

void ContactStage::detect(const Model& model) {
  run_detection(model, model.nodes.x.data());
  // Stick springs of pairs that left the list are released (their energy leaves the contact
  // energy; the ledger counts it as dissipated, docs/verification.md "Impact energy").
  if (!friction_.empty()) {
    std::unordered_set<PairId, PairIdHash> kept;
    kept.reserve(pairs_.size());
    for (const CandidatePair& p : pairs_) kept.insert({model.tets.gid[p.a], model.tets.gid[p.b]});
    for (auto it = friction_.begin(); it != friction_.end();)
      it = kept.count(it->first) ? std::next(it) : friction_.erase(it);
  }
  x_at_detection_ = model.nodes.x;
  detected_ = true;
  ++detections_;
}

// Enclosed tets of bodies whose joints all hold take no part (TetJointState::enclosed).
void ContactStage::mark_left_out(const Model& model) {
  const TetArrays& tets = model.tets;
  left_out_.assign(static_cast<std::size_t>(tets.size()), 0);
  left_out_count_ = 0;
  if (skip_enclosed_ && !joint_state_.empty())
    for (LocalIndex t = 0; t < tets.size(); ++t)
      if (joint_state_[t] == JointState::enclosed &&
          !body_cracked_[static_cast<std::size_t>(model.pieces.body_of(tets.piece[t]))]) {
        left_out_[t] = 1;
        ++left_out_count_;
      }
}

// Whether detection keeps the pair (a, b) whose inflated boxes overlap, at positions x.
bool ContactStage::keeps(const Model& model, const double* x, LocalIndex a, LocalIndex b) const {
  const TetArrays& tets = model.tets;
  if (left_out_[a] || left_out_[b]) return false;
  // A pair between two tets this rank does not compute is left to the ranks that do.
  if (!tets.active.empty() && !tets.active[a] && !tets.active[b]) return false;
  if (tets.group_of(a) == tets.group_of(b) ||
      (piece_fixed(model, tets.piece[a]) && piece_fixed(model, tets.piece[b])))
    return false;
  if (!bonds_.empty()) {
    const LocalIndex* bonded = bonds_.data() + 4 * static_cast<std::size_t>(a);
    if (bonded[0] == b || bonded[1] == b || bonded[2] == b || bonded[3] == b) return false;
    // Tets of one jointed continuum that met at a mesh node at t = 0 (their nodes were split
    // from one) cannot overlap while all their joints hold: the joints carry that compression,
    // and leaving them out keeps contact to the pairs around cracks.
    const auto holds = [&](LocalIndex t) {
      return joint_state_[t] == JointState::intact || joint_state_[t] == JointState::enclosed;
    };
    if (holds(a) && holds(b) && share_reference_node(model, a, b)) return false;
  }
  // Narrowed as the boxes are tested, so that only kept pairs are ever stored (box overlaps of
  // sliver tets across a joint between blocks outnumber the kept pairs several times): every
  // point of a tet stays within buffer/2 of where it was at detection (a convex combination of
  // node moves ≤ buffer/2), so a pair whose tets are now more than `buffer` apart cannot touch
  // before the next detection.
  if (tets_farther_than(model, x, a, b, buffer_)) return false;
  if (!exact_narrowing_) return true;
  // No face plane separates them by a buffer; their exact distance may (tets of one jointed
  // body near its surface, sliver tets across an interface): kept pairs cost every step.
  Vec3 corners[2][4];
  for (int c = 0; c < 4; ++c) {
    corners[0][c] = vec3_at(x, tets.nodes[4 * a + c]);
    corners[1][c] = vec3_at(x, tets.nodes[4 * b + c]);
  }
  return tets_within(corners[0], corners[1], buffer_);
}

void ContactStage::run_detection(const Model& model, const double* x) {
  ++broad_phase_passes_;
  compute_boxes(model, x);
  mark_left_out(model);
  const auto keep = [&](LocalIndex a, LocalIndex b) { return keeps(model, x, a, b); };
  detector_.detect(lo_.data(), hi_.data(), model.tets.size(), buffer_, pairs_, keep);
  may_hold_friction_.assign(pairs_.size(), 1);
}

// The pairs a detection at the positions of the last one would add after the eligibility of the
// `changed` tets widened (and no other's): each changed tet's inflated box against every box,
// the same box overlap and keeps() as the detector, merged into the sorted list.  A few tets'
// pairs cost a pass over the boxes each; many, a detection.
void ContactStage::add_pairs_of(const Model& model, const std::vector<LocalIndex>& changed) {
  const LocalIndex n = model.tets.size();
  if (changed.size() > 64) {
    run_detection(model, x_at_detection_.data());
    return;
  }
  const double* x = x_at_detection_.data();
  compute_boxes(model, x);
  const double half = 0.5 * buffer_;
  const auto box_of = [&](LocalIndex t, double(&box)[6]) {
    for (int k = 0; k < 3; ++k) {
      box[k] = lo_[3 * t + k] - half;
      box[3 + k] = hi_[3 * t + k] + half;
    }
  };
  std::vector<CandidatePair> added;
  for (const LocalIndex c : changed) {
    double box_c[6], box_t[6];
    box_of(c, box_c);
    for (LocalIndex t = 0; t < n; ++t) {
      box_of(t, box_t);
      if (t == c || !boxes_overlap(box_c, box_t)) continue;
      const CandidatePair pair{std::min(c, t), std::max(c, t)};
      if (!std::binary_search(pairs_.begin(), pairs_.end(), pair) &&
          keeps(model, x, pair.a, pair.b))
        added.push_back(pair);
    }
  }
  std::sort(added.begin(), added.end());
  added.erase(std::unique(added.begin(), added.end()), added.end());
  const std::size_t old_size = pairs_.size();
  pairs_.insert(pairs_.end(), added.begin(), added.end());
  std::inplace_merge(pairs_.begin(), pairs_.begin() + static_cast<std::ptrdiff_t>(old_size),
                     pairs_.end());
  may_hold_friction_.assign(pairs_.size(), 1);
}

void ContactStage::rebind(const Model& model, std::vector<double> x_at_detection,
                          std::vector<std::uint8_t> tet_joint_state,
                          const std::vector<FrictionEntry>& friction, bool detected,
                          const std::vector<GidPair>* candidates) {
  const TetArrays& tets = model.tets;
  FDEM_VERIFY(x_at_detection.size() == model.nodes.x.size(), "positions at detection per node");
  FDEM_VERIFY(
      tet_joint_state.empty() || tet_joint_state.size() == static_cast<std::size_t>(tets.size()),
      "joint state per tet");
  std::vector<std::pair<LocalIndex, LocalIndex>> bonds;
  for (LocalIndex j = 0; j < model.joints.size(); ++j)
    if (!model.joints.broken[j])
      bonds.emplace_back(model.joints.tets[2 * j], model.joints.tets[2 * j + 1]);
  if (!tet_joint_state.empty()) {  // the scene has joints: bonds and joint states filter pairs
    set_bonds(tets.size(), bonds);
    for (LocalIndex t = 0; t < tets.size(); ++t)
      joint_state_[t] = static_cast<JointState>(tet_joint_state[t]);
  }
  std::unordered_map<GlobalId, LocalIndex> local;
  for (LocalIndex t = 0; t < tets.size(); ++t) local.emplace(tets.gid[t], t);
  friction_.clear();
  for (const FrictionEntry& e : friction) {
    PairFriction& pf = friction_[PairId{e.a, e.b}];
    pf.history.tangential_spring = e.spring;
    std::copy_n(e.anchor_a, 4, pf.history.anchor_contactor);
    std::copy_n(e.anchor_b, 4, pf.history.anchor_target);
    pf.stiffness = e.stiffness;
    const auto it = local.find(e.a);
    pf.owned = it != local.end() && tets.is_owned(it->second);
  }
  x_at_detection_ = std::move(x_at_detection);
  detected_ = detected;
  pairs_.clear();
  if (!detected_) return;
  if (!candidates) {
    run_detection(model, x_at_detection_.data());
    return;
  }
  // The pairs this rank computes (run_detection's `eligible` keeps a pair with an active tet; the
  // rest of it holds on every rank alike): local tets are in ascending gid, so gid order is the
  // local order the broad phase gives.
  mark_left_out(model);
  pairs_.reserve(candidates->size());
  for (const GidPair& c : *candidates) {
    const auto a = local.find(c.a), b = local.find(c.b);
    if (a == local.end() || b == local.end()) continue;
    if (!tets.is_active(a->second) && !tets.is_active(b->second)) continue;
    pairs_.push_back({a->second, b->second});
  }
  std::sort(pairs_.begin(), pairs_.end());
  may_hold_friction_.assign(pairs_.size(), 1);
}

std::vector<GidPair> ContactStage::candidate_gids(const Model& model) const {
  std::vector<GidPair> out;
  out.reserve(pairs_.size());
  for (const CandidatePair& p : pairs_) out.push_back({model.tets.gid[p.a], model.tets.gid[p.b]});
  return out;  // pairs_ is in ascending (a, b) and local tets in ascending gid
}

void ContactStage::release_until_rebind() {
  pairs_ = {};
  overlapping_ = {};
  may_hold_friction_ = {};
  records_ = {};
  lo_ = {};
  hi_ = {};
  x_at_detection_ = {};
  friction_ = {};
  detector_.release_workspace();
}

std::vector<FrictionEntry> ContactStage::friction_entries() const {
  std::vector<FrictionEntry> out;
  out.reserve(friction_.size());
  for (const auto& [key, pf] : friction_) {
    FrictionEntry e;
    e.a = key.a;
    e.b = key.b;
    e.spring = pf.history.tangential_spring;
    e.stiffness = pf.stiffness;
    std::copy_n(pf.history.anchor_contactor, 4, e.anchor_a);
    std::copy_n(pf.history.anchor_target, 4, e.anchor_b);
    out.push_back(e);
  }
  std::sort(out.begin(), out.end(), [](const FrictionEntry& p, const FrictionEntry& q) {
    return p.a != q.a ? p.a < q.a : p.b < q.b;
  });
  return out;
}

std::vector<std::uint8_t> ContactStage::tet_joint_states() const {
  std::vector<std::uint8_t> out(joint_state_.size());
  for (std::size_t t = 0; t < joint_state_.size(); ++t)
    out[t] = static_cast<std::uint8_t>(joint_state_[t]);
  return out;
}

void ContactStage::set_bonds(LocalIndex n_tets,
                             const std::vector<std::pair<LocalIndex, LocalIndex>>& pairs) {
  bonds_.assign(4 * static_cast<std::size_t>(n_tets), -1);
  joint_state_.assign(n_tets, JointState::none);
  for (const auto& [a, b] : pairs) {
    joint_state_[a] = joint_state_[b] = JointState::intact;
    const LocalIndex tets[2] = {a, b};
    for (int side = 0; side < 2; ++side) {
      const LocalIndex t = tets[side], other = tets[1 - side];
      FDEM_VERIFY(t >= 0 && t < n_tets, "bonded tet index");
      LocalIndex* slot = bonds_.data() + 4 * static_cast<std::size_t>(t);
      int k = 0;
      while (k < 4 && slot[k] >= 0) ++k;
      FDEM_VERIFY(k < 4, "a tet has at most four bonded faces");
      slot[k] = other;
    }
  }
  detected_ = false;
}

void ContactStage::enclose(const std::vector<std::uint8_t>& enclosed) {
  if (enclosed.empty() || joint_state_.empty()) return;
  FDEM_VERIFY(enclosed.size() == joint_state_.size(), "an enclosed flag per tet");
  for (std::size_t t = 0; t < enclosed.size(); ++t)
    if (enclosed[t] && joint_state_[t] == JointState::intact)
      joint_state_[t] = JointState::enclosed;
}

void ContactStage::crack_body(std::int32_t body) {
  FDEM_VERIFY(body >= 0 && static_cast<std::size_t>(body) < body_cracked_.size(), "body index");
  if (!body_cracked_[static_cast<std::size_t>(body)]) detected_ = false;
  body_cracked_[static_cast<std::size_t>(body)] = 1;
}

void ContactStage::release_bonds(const Model& model,
                                 const std::vector<std::pair<LocalIndex, LocalIndex>>& pairs) {
  std::vector<LocalIndex> changed;  // tets whose eligibility widened
  for (const auto& [a, b] : pairs)
    for (int side = 0; side < 2; ++side) {
      const LocalIndex t = side == 0 ? a : b, other = side == 0 ? b : a;
      if (t < 0) continue;  // that tet is not held here (parallel runs)
      bool widened = false;
      if (!joint_state_.empty() && joint_state_[t] != JointState::cracked) {
        if (!left_out_.empty() && left_out_[t]) {  // enclosed, and its body had not cracked
          left_out_[t] = 0;
          --left_out_count_;
        }
        joint_state_[t] = JointState::cracked;
        widened = true;
      }
      if (!bonds_.empty() && other >= 0)  // a bond is held with both its tets
        for (int k = 0; k < 4; ++k)
          if (bonds_[4 * static_cast<std::size_t>(t) + k] == other) {
            bonds_[4 * static_cast<std::size_t>(t) + k] = -1;
            widened = true;
          }
      if (widened) changed.push_back(t);
    }
  // Only widened eligibility at unchanged positions: every pair of the list is found again.
  if (!changed.empty() && detected_) add_pairs_of(model, changed);
}

ContactForceSummary ContactStage::add_forces(Model& model, double dt) {
  ContactForceSummary out;
  const TetArrays& tets = model.tets;
  NodeArrays& nodes = model.nodes;
  records_.clear();
  out.candidate_pairs = static_cast<std::int64_t>(pairs_.size());  // held here, not unique
  overlapping_.assign(pairs_.size(), 0);
  may_hold_friction_.resize(pairs_.size(), 1);
  // The friction and dashpot force arrays (3 per node) exist from the first step that writes to
  // them and are cleared only after a step that did: bodies apart or at rest cost neither memory
  // nor a pass over the nodes.
  const std::size_t values = 3 * static_cast<std::size_t>(nodes.size());
  const auto clear = [&](std::vector<double>& force, bool& written) {
    if (force.size() != values && !force.empty())
      force.clear();  // the local nodes changed (redistribution)
    else if (written)
      std::fill(force.begin(), force.end(), 0.0);
    written = false;
  };
  const auto writable = [&](std::vector<double>& force, bool& written) {
    if (force.empty()) force.assign(values, 0.0);
    written = true;
    return force.data();
  };
  clear(friction_force_, friction_written_);
  clear(damping_force_, damping_written_);
  for (std::size_t index = 0; index < pairs_.size(); ++index) {
    const CandidatePair& pair = pairs_[index];
    TetCorners a, b;
    for (int c = 0; c < 4; ++c) {
      a.x[c] = vec3_at(nodes.x.data(), tets.nodes[4 * pair.a + c]);
      b.x[c] = vec3_at(nodes.x.data(), tets.nodes[4 * pair.b + c]);
    }
    const int ma = tets.material[pair.a], mb = tets.material[pair.b];
    const double penalty = std::min(penalty_[ma], penalty_[mb]);
    const double mu = std::min(friction_coefficient_[ma], friction_coefficient_[mb]);
    const ContactPairResult r = potential_contact(a, b, penalty);
    const PairId key{tets.gid[pair.a], tets.gid[pair.b]};
    // Every rank that holds a pair computes it; the owner of its first tet reports its energies.
    const double share = tets.is_owned(pair.a) ? 1.0 : 0.0;
    if (!r.overlapping) {
      if (mu > 0.0 && may_hold_friction_[index])
        friction_.erase(key);  // contact lost: the stick spring is released
      may_hold_friction_[index] = 0;
      continue;
    }
    overlapping_[index] = 1;
    may_hold_friction_[index] = 1;
    out.active_pairs += share > 0.0 ? 1 : 0;
    out.energy += share * r.energy;
    for (int c = 0; c < 4; ++c) {
      vec3_at(nodes.f.data(), tets.nodes[4 * pair.a + c]) += r.force_contactor[c];
      vec3_at(nodes.f.data(), tets.nodes[4 * pair.b + c]) += r.force_target[c];
    }
    Vec3 va[4], vb[4];
    for (int c = 0; c < 4; ++c) va[c] = vb[c] = Vec3::Zero();
    const double xi = std::max(damping_ratio_[ma], damping_ratio_[mb]);
    if (mu > 0.0 || xi > 0.0)
      for (int c = 0; c < 4; ++c) {
        va[c] = vec3_at(nodes.v.data(), tets.nodes[4 * pair.a + c]);
        vb[c] = vec3_at(nodes.v.data(), tets.nodes[4 * pair.b + c]);
      }
    // A round-off sliver (overlap below 1e-12 of the smaller tet, e.g. coplanar faces touching
    // at t = 0) has no meaningful secant stiffness F²/(2U) (seen 1.6e23 N/m from F = 6e-41 N,
    // U = 1e-104 J): no dashpot on it.
    const double sliver =
        1e-12 * std::min(std::abs(tets.volume0[pair.a]), std::abs(tets.volume0[pair.b]));
    if (xi > 0.0 && r.energy > 0.0 && r.normal_force > 0.0 && r.overlap_volume > sliver) {
      // Normal dashpot c = 2ξ√(k m): k = F²/(2U) is the pair's secant stiffness (exact for U ∝ d²),
      // m the reduced mass of the two tets (a fixed partner has infinite mass).  The dashpot never
      // pulls harder than the elastic push, so it cannot make the contact sticky.
      const double k = r.normal_force * r.normal_force / (2.0 * r.energy);
      const double m_a = model.materials[ma].density * std::abs(tets.volume0[pair.a]);
      const double m_b = model.materials[mb].density * std::abs(tets.volume0[pair.b]);
      const bool a_fixed = piece_fixed(model, tets.piece[pair.a]),
                 b_fixed = piece_fixed(model, tets.piece[pair.b]);
      const double m = a_fixed ? m_b : b_fixed ? m_a : m_a * m_b / (m_a + m_b);
      const double v_n = relative_velocity_at_centroid(r, va, vb).dot(r.normal);
      const double f_n = std::max(-2.0 * xi * std::sqrt(k * m) * v_n,
                                  -r.normal_force);  // on the contactor, along n
      double* damping_force = writable(damping_force_, damping_written_);
      for (int c = 0; c < 4; ++c) {
        const Vec3 on_a = r.centroid_weights_contactor[c] * f_n * r.normal;
        const Vec3 on_b = -r.centroid_weights_target[c] * f_n * r.normal;
        vec3_at(nodes.f.data(), tets.nodes[4 * pair.a + c]) += on_a;
        vec3_at(nodes.f.data(), tets.nodes[4 * pair.b + c]) += on_b;
        vec3_at(damping_force, tets.nodes[4 * pair.a + c]) += on_a;
        vec3_at(damping_force, tets.nodes[4 * pair.b + c]) += on_b;
      }
    }
    Vec3 tangential = Vec3::Zero();
    if (mu > 0.0) {
      // Stick spring k_t = p·s (N/m) with s the pair's size: as stiff as the normal contact.
      const double size =
          std::cbrt(std::abs(tets.volume0[pair.a]) + std::abs(tets.volume0[pair.b]));
      const FrictionLaw law{mu, penalty * size};
      PairFriction& pair_friction = friction_[key];
      pair_friction.stiffness = law.tangential_stiffness;
      pair_friction.owned = share > 0.0;
      FrictionHistory& history = pair_friction.history;
      // The spring joins two material points, anchored at the first real overlap's centroid (a
      // round-off sliver's centroid is noise) and following the centroid with a lag; it acts
      // midway between them (friction_kernels.hpp).
      if (r.overlap_volume > sliver) {
        if (!history.attached())
          history.attach(r);
        else
          history.follow(r, -std::expm1(-dt / friction_anchor_lag_));
      }
      FrictionPoint point = centroid_point(r);
      if (history.attached()) spring_point(history, a, b, point);
      const FrictionResult f =
          coulomb_friction(law, r, point, relative_velocity_at(point, va, vb), dt, history);
      if (f.slipping && history.attached()) slide_anchors(history, a, b, f.slip);
      double* friction_force = writable(friction_force_, friction_written_);
      for (int c = 0; c < 4; ++c) {
        vec3_at(nodes.f.data(), tets.nodes[4 * pair.a + c]) += f.force_contactor[c];
        vec3_at(nodes.f.data(), tets.nodes[4 * pair.b + c]) += f.force_target[c];
        vec3_at(friction_force, tets.nodes[4 * pair.a + c]) += f.force_contactor[c];
        vec3_at(friction_force, tets.nodes[4 * pair.b + c]) += f.force_target[c];
      }
      out.friction_spring_energy += share * f.spring_energy;
      tangential = f.tangential_force;
    }
    if (share > 0.0) records_.push_back({r.centroid, r.normal_force * r.normal, tangential});
  }
  // Owned nodes hold the whole force of every pair they take part in (the halo guarantees it).
  out.work_before = work_against(model, dt);
  return out;
}

ContactWork ContactStage::work_after(const Model& model, double dt) const {
  return work_against(model, dt);
}

// −Σ F·v·dt/2 over the owned nodes at their current velocities (J), for the friction and the
// dashpot forces of the last add_forces.
ContactWork ContactStage::work_against(const Model& model, double dt) const {
  ContactWork w;
  const double* v = model.nodes.v.data();
  const std::size_t n = 3 * static_cast<std::size_t>(model.nodes.n_owned);
  if (friction_written_)
    for (std::size_t i = 0; i < n; ++i) w.friction -= 0.5 * dt * friction_force_[i] * v[i];
  if (damping_written_)
    for (std::size_t i = 0; i < n; ++i) w.damping -= 0.5 * dt * damping_force_[i] * v[i];
  return w;
}

std::vector<PairRecord> friction_records(const std::vector<FrictionEntry>& entries) {
  std::vector<PairRecord> records(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const FrictionEntry& e = entries[i];
    PairRecord& r = records[i];
    r.a = e.a;
    r.b = e.b;
    r.value[0] = e.spring.x();
    r.value[1] = e.spring.y();
    r.value[2] = e.spring.z();
    r.value[3] = e.stiffness;
    std::copy_n(e.anchor_a, 4, r.value + 4);
    std::copy_n(e.anchor_b, 4, r.value + 8);
  }
  return records;
}

std::vector<FrictionEntry> friction_entries(const std::vector<PairRecord>& records) {
  std::vector<FrictionEntry> entries(records.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    const PairRecord& r = records[i];
    entries[i].a = r.a;
    entries[i].b = r.b;
    entries[i].spring = Vec3(r.value[0], r.value[1], r.value[2]);
    entries[i].stiffness = r.value[3];
    std::copy_n(r.value + 4, 4, entries[i].anchor_a);
    std::copy_n(r.value + 8, 4, entries[i].anchor_b);
  }
  return entries;
}

}  // namespace fdem
