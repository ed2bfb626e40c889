// The contact stage's detection (contact_stage.hpp): boxes, the rule that keeps a detected pair,
// and the bonds and joint states that decide which tets may pair.
#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_set>

#include "contact/contact_stage.hpp"
#include "contact/detection.hpp"
#include "contact/tet_distance.hpp"
#include "core/error.hpp"

namespace fdem {

void ContactStage::compute_boxes(const Model& model, const double* x,
                                 const std::vector<LocalIndex>* members) {
  const TetArrays& tets = model.tets;
  const std::size_t n = members ? members->size() : static_cast<std::size_t>(tets.size());
  boxes_.resize(6 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const LocalIndex t = members ? (*members)[i] : static_cast<LocalIndex>(i);
    for (int k = 0; k < 3; ++k) {
      double lo = x[3 * tets.nodes[4 * t] + k], hi = lo;
      for (int c = 1; c < 4; ++c) {
        const double v = x[3 * tets.nodes[4 * t + c] + k];
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      if (!std::isfinite(lo) || !std::isfinite(hi))
        throw NumericalFailure("contact detection: tet " + std::to_string(tets.gid[t]) +
                               " has a non-finite bounding box (its nodes left the finite "
                               "range); reduce the time step or check the loads.");
      boxes_[6 * i + k] = lo;
      boxes_[6 * i + 3 + k] = hi;
    }
  }
}

namespace {

// True if two tets have a node at the same reference position (nodes split from one mesh node).
bool share_reference_node(const Model& model, LocalIndex a, LocalIndex b) {
  const NodeArrays& nodes = model.nodes;
  for (int i = 0; i < 4; ++i) {
    const double* p = nodes.x0(model.tets.nodes[4 * a + i]).data();
    for (int j = 0; j < 4; ++j) {
      const double* q = nodes.x0(model.tets.nodes[4 * b + j]).data();
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
  return !detected_ || detection_needed(travel_since_detection(model), buffer_);
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
  keep_positions(model, model.nodes.x.data());
  travel_bound_ = 0.0;
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
  mark_left_out(model);
  // Left-out tets (keeps() rejects every pair of theirs) do not enter the broad phase: boxes and
  // grids for the others only.  Their indices in `members` ascend with the tets', so the
  // detector's sorted pairs map to the same sorted pairs of tets.  None left out: every tet.
  std::vector<LocalIndex> members;
  if (left_out_count_ > 0) {
    members.reserve(static_cast<std::size_t>(model.tets.size() - left_out_count_));
    for (LocalIndex t = 0; t < model.tets.size(); ++t)
      if (!left_out_[static_cast<std::size_t>(t)]) members.push_back(t);
  }
  const bool all = left_out_count_ == 0;
  const auto tet = [&](LocalIndex i) { return all ? i : members[static_cast<std::size_t>(i)]; };
  compute_boxes(model, x, all ? nullptr : &members);
  const auto keep = [&](LocalIndex a, LocalIndex b) { return keeps(model, x, tet(a), tet(b)); };
  const auto n = all ? model.tets.size() : static_cast<LocalIndex>(members.size());
  detector_.detect(std::move(boxes_), n, buffer_, pairs_, keep);  // inflated in place there
  // Boxes and grids are rebuilt by every detection: not held between them (~100 B per tet that may
  // pair, most of what a large jointed body's run holds above its model).
  detector_.release_workspace();
  release(boxes_);
  if (!all)
    for (CandidatePair& p : pairs_) p = {tet(p.a), tet(p.b)};
  candidates_changed();
}

// The pairs a detection at the positions of the last one would add after the eligibility of the
// `changed` tets widened (and no other's): each changed tet's inflated box against every box,
// the same box overlap and keeps() as the detector, merged into the sorted list.  A few tets'
// pairs cost a pass over the boxes each; many, a detection.
void ContactStage::add_pairs_of(const Model& model, const std::vector<LocalIndex>& changed) {
  const LocalIndex n = model.tets.size();
  // Positions at the last detection of every node (those of left-out tets, whose pairs keeps()
  // rejects, where they are now).
  std::vector<double> all_positions;
  if (!every_node_kept_) all_positions = positions_at_detection(model);
  const double* x = every_node_kept_ ? x_at_detection_.data() : all_positions.data();
  if (changed.size() > 64) {
    run_detection(model, x);
    return;
  }
  compute_boxes(model, x);
  const double half = 0.5 * buffer_;
  const auto box_of = [&](LocalIndex t, double(&box)[6]) {
    for (int k = 0; k < 3; ++k) {
      box[k] = boxes_[6 * static_cast<std::size_t>(t) + k] - half;
      box[3 + k] = boxes_[6 * static_cast<std::size_t>(t) + 3 + k] + half;
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
  release(boxes_);
  std::sort(added.begin(), added.end());
  added.erase(std::unique(added.begin(), added.end()), added.end());
  const std::size_t old_size = pairs_.size();
  pairs_.insert(pairs_.end(), added.begin(), added.end());
  std::inplace_merge(pairs_.begin(), pairs_.begin() + static_cast<std::ptrdiff_t>(old_size),
                     pairs_.end());
  candidates_changed();
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
          // Its nodes' positions at the last detection were not kept: detect anew (its body's
          // crack, told first, has already asked for that).
          detected_ = false;
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

}  // namespace fdem
