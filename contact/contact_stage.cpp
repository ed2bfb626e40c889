#include "contact/contact_stage.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "contact/clip_replay.hpp"
#include "contact/corner_contact.hpp"
#include "contact/dashpot_kernels.hpp"
#include "contact/detection.hpp"
#include "contact/potential_contact_kernels.hpp"
#include "core/error.hpp"
#include "core/tet_kernels.hpp"

namespace fdem {

namespace {
// Auto penalty: 10 E keeps the kinetic energy recovered in an impact above 99 % (docs/references.md
// 2) and the penetration under 10 % of the element size at the material's strength scale.
constexpr double auto_penalty_factor = 10.0;
}  // namespace

// From the piece's body: no table per piece (a rank may not know every piece of the model).
bool ContactStage::piece_fixed(const Model& model, std::int32_t piece) {
  return model.body_fixed[model.pieces.body_of(piece)];
}

ContactStage::ContactStage(const Model& model, ContactSettings settings) {
  for (const MaterialProperties& m : model.materials) {
    penalty_.push_back(m.contact.auto_penalty ? auto_penalty_factor * m.young : m.contact.penalty);
    friction_coefficient_.push_back(m.contact.friction);
    damping_ratio_.push_back(std::max(m.contact.damping, settings.least_damping_ratio));
  }
  skip_enclosed_ = settings.skip_enclosed;
  exact_narrowing_ = settings.exact_narrowing;
  // The anchors' lag: long against the contact's vibrations (following the centroid at once, a
  // column of blocks on an incline rings at ~600 Hz ever louder and breaks away; with 0.01 s its
  // vibration still grows, slowly), short against the shift of a rocking block's load onto its
  // toe (never following, a block at 0.975 μ on a tilting table turns about the normal and
  // slides).  docs/verification.md, "Static friction on an incline".
  FDEM_VERIFY(settings.friction_anchor_lag > 0.0, "friction anchor lag > 0");
  friction_anchor_lag_ = settings.friction_anchor_lag;
  body_dashpot_ = settings.body_dashpot;
  FDEM_VERIFY(settings.sliver_tolerance >= 0.0, "sliver tolerance >= 0");
  sliver_tolerance_ = settings.sliver_tolerance;
  clip_replay_ = settings.clip_replay;
  corners_ = settings.corners;
  if (corners_) {
    FDEM_VERIFY(model.tets.contact_faces.size() == 2 * static_cast<std::size_t>(model.tets.size()),
                "corner contact has the tets' contact faces (core/contact_faces.hpp)");
    clip_replay_ = false;  // the replay records potential contact's clips
  }
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
  return contact_possible(model);
}

double ContactStage::critical_time_step(const Model& model) const {
  const TetArrays& tets = model.tets;
  double dt = std::numeric_limits<double>::infinity();
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    if (!tets.is_owned(t)) continue;  // each tet counts once, on its owner
    const double h = smallest_altitude(tet_corners(model, t).x);
    const double omega2 =
        96.0 * penalty_[tets.material[t]] / (model.materials[tets.material[t]].density * h * h);
    const double xi = damping_ratio_[tets.material[t]];
    dt = std::min(dt, 2.0 / std::sqrt(omega2) * (std::sqrt(1.0 + xi * xi) - xi));
  }
  return dt;
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
  detected_ = detected;
  travel_bound_ = std::numeric_limits<double>::infinity();  // x_at_detection is not x now
  pairs_.clear();
  candidates_changed();
  release(x_at_detection_);
  release(kept_nodes_);
  every_node_kept_ = true;
  if (!detected_) return;  // positions at detection are taken by the first detection
  // The positions the last detection saw: of the nodes it looks at, once left_out_ is known.
  const auto keep = [&] {
    if (left_out_count_ == 0)
      x_at_detection_ = std::move(x_at_detection);
    else
      keep_positions(model, x_at_detection.data());
  };
  if (!candidates) {
    run_detection(model, x_at_detection.data());
    keep();
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
  candidates_changed();
  keep();
}

void ContactStage::keep_positions(const Model& model, const double* x) {
  const std::size_t n_nodes = static_cast<std::size_t>(model.nodes.size());
  if (left_out_count_ == 0) {
    every_node_kept_ = true;
    release(kept_nodes_);
    x_at_detection_.assign(x, x + 3 * n_nodes);
    return;
  }
  every_node_kept_ = false;
  const TetArrays& tets = model.tets;
  std::vector<std::uint8_t> kept(n_nodes, 0);
  for (LocalIndex t = 0; t < tets.size(); ++t)
    if (!left_out_[static_cast<std::size_t>(t)])
      for (int c = 0; c < 4; ++c) kept[static_cast<std::size_t>(tets.nodes[4 * t + c])] = 1;
  const std::size_t count = static_cast<std::size_t>(std::count(kept.begin(), kept.end(), 1));
  std::vector<LocalIndex> nodes;  // sized exactly: no slack kept between detections
  nodes.reserve(count);
  std::vector<double> positions(3 * count);
  for (std::size_t i = 0; i < n_nodes; ++i) {
    if (!kept[i]) continue;
    std::copy_n(x + 3 * i, 3, positions.data() + 3 * nodes.size());
    nodes.push_back(static_cast<LocalIndex>(i));
  }
  kept_nodes_ = std::move(nodes);
  x_at_detection_ = std::move(positions);
}

std::vector<double> ContactStage::positions_at_detection(const Model& model) const {
  if (every_node_kept_ && x_at_detection_.size() == model.nodes.x.size()) return x_at_detection_;
  std::vector<double> out = model.nodes.x;
  if (!every_node_kept_)
    for (std::size_t k = 0; k < kept_nodes_.size(); ++k)
      std::copy_n(x_at_detection_.data() + 3 * k, 3,
                  out.data() + 3 * static_cast<std::size_t>(kept_nodes_[k]));
  return out;
}

double ContactStage::travel_since_detection(const Model& model) const {
  if (!detected_) return 0.0;
  const double* x = model.nodes.x.data();
  if (every_node_kept_)
    return max_node_displacement(x, x_at_detection_.data(), model.nodes.n_owned);
  // Owned nodes come first: the kept ones below n_owned.
  const auto owned = static_cast<std::size_t>(
      std::lower_bound(kept_nodes_.begin(), kept_nodes_.end(), model.nodes.n_owned) -
      kept_nodes_.begin());
  return max_node_displacement(x, x_at_detection_.data(), kept_nodes_.data(), owned);
}

bool ContactStage::detection_due_after_step(const Model& model, double step_travel,
                                            double largest_coordinate) {
  // x_n+1 = fl(x_n + Δx) differs from x_n + Δx by at most 2^-53·|x| per component, so a node's
  // travel in the step is at most |Δx|·(1 + 2^-48) + 2^-51·max|x| (the first factor covers the
  // rounding of |Δx| as measured).  The sum stays an upper bound of the travel since detection.
  travel_bound_ += step_travel * (1.0 + 0x1p-48) + 0x1p-51 * largest_coordinate;
  if (travel_bound_ * (1.0 + 1e-9) <= 0.5 * buffer_) return false;
  return detection_needed(travel_since_detection(model), buffer_);
}

std::vector<GidPair> ContactStage::candidate_gids(const Model& model) const {
  std::vector<GidPair> out;
  out.reserve(pairs_.size());
  for (const CandidatePair& p : pairs_) out.push_back({model.tets.gid[p.a], model.tets.gid[p.b]});
  return out;  // pairs_ is in ascending (a, b) and local tets in ascending gid
}

void ContactStage::candidates_changed() {
  may_hold_friction_.assign(pairs_.size(), 1);
  release(friction_of_pair_);
  release(clip_record_at_);
  release(apart_at_);
  pair_slots_.clear();
  pair_tets_.clear();
}

void ContactStage::index_pair_tets() {
  pair_tets_.clear();
  pair_tets_.reserve(2 * pairs_.size());
  for (const CandidatePair& p : pairs_) {
    pair_tets_.push_back(p.a);
    pair_tets_.push_back(p.b);
  }
  std::sort(pair_tets_.begin(), pair_tets_.end());
  pair_tets_.erase(std::unique(pair_tets_.begin(), pair_tets_.end()), pair_tets_.end());
  pair_tets_.shrink_to_fit();
  pair_slots_.resize(2 * pairs_.size());
  const auto slot = [&](LocalIndex t) {
    return static_cast<std::int32_t>(std::lower_bound(pair_tets_.begin(), pair_tets_.end(), t) -
                                     pair_tets_.begin());
  };
  for (std::size_t i = 0; i < pairs_.size(); ++i) {
    pair_slots_[2 * i] = slot(pairs_[i].a);
    pair_slots_[2 * i + 1] = slot(pairs_[i].b);
  }
}

void ContactStage::update_tet_geometry(const Model& model) {
  const bool indexed = pair_slots_.size() != 2 * pairs_.size();
  if (indexed) {
    index_pair_tets();
    apart_pairs_.reset(pair_tets_.size());
  }
  tet_boxes_.resize(pair_tets_.size());
  tet_geometry_.resize(pair_tets_.size());
  for (std::size_t i = 0; i < pair_tets_.size(); ++i) {
    const TetCorners corners = tet_corners(model, pair_tets_[i]);
    // (the travel sums serve the skip of pairs kept apart: with clip_replay, and under corners)
    if ((clip_replay_ || corners_) && !indexed)
      apart_pairs_.moved(i, tet_geometry_[i].corners, corners);
    tet_boxes_[i] = tet_box(corners);
    compute_tet_geometry(corners, tet_geometry_[i]);
  }
  if (corners_ && (indexed || corner_tets_.size() != pair_tets_.size())) {
    FDEM_VERIFY(model.tets.contact_faces.size() == 2 * static_cast<std::size_t>(model.tets.size()),
                "every local tet carries its contact faces (migration, halo)");
    corner_tets_.resize(pair_tets_.size());
    for (std::size_t i = 0; i < pair_tets_.size(); ++i)
      corner_tets_[i] = corner_tet(model, pair_tets_[i]);
  }
}

void ContactStage::release_until_rebind() {
  release(pairs_);
  release(overlapping_);
  release(may_hold_friction_);
  release(friction_of_pair_);
  release(clip_record_at_);
  release(apart_at_);
  apart_pairs_.release();
  clip_records_[0].release();
  clip_records_[1].release();
  clip_topologies_.clear();
  release(pair_tets_);
  release(pair_slots_);
  release(corner_tets_);
  release(tet_boxes_);
  release(tet_geometry_);
  release(records_);
  release(boxes_);
  release(x_at_detection_);
  release(kept_nodes_);
  release(friction_);
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
  update_tet_geometry(model);
  // Pairs come in contactor order: each contactor is prepared once for all its pairs.
  PreparedContactor contactor;
  LocalIndex prepared = -1;
  // Share of the way to the overlap centroid an attached spring's anchors follow in one step.
  const double anchor_follow = -std::expm1(-dt / friction_anchor_lag_);
  const auto friction_of = [&](const CandidatePair& pair) {
    return std::min(friction_coefficient_[tets.material[pair.a]],
                    friction_coefficient_[tets.material[pair.b]]);
  };
  // This step's clip records go to the other buffer; every pair's offset is renewed or cleared.
  const RecordBytes& clip_read = clip_records_[clip_parity_];
  RecordBytes& clip_written = clip_records_[clip_parity_ ^ 1];
  clip_written.clear();
  clip_parity_ ^= 1;
  const std::size_t pair_count = pairs_.size();
  for (std::size_t index = 0; index < pair_count; ++index) {
    const std::int32_t slot_a = pair_slots_[2 * index], slot_b = pair_slots_[2 * index + 1];
    // Apart by more than its tets have moved since (apart_pairs.hpp): as it was, with no record.
    if (apart_pairs_.still_apart(index, slot_a, slot_b)) {
      ++pair_steps_kept_apart_;
      continue;
    }
    std::uint32_t clip_read_at = kNoClipRecord;
    if (!clip_record_at_.empty()) std::swap(clip_read_at, clip_record_at_[index]);
    std::uint8_t apart_before = ClipMemo::kNotApart;  // renewed below where the kernel runs
    if (!apart_at_.empty()) std::swap(apart_before, apart_at_[index]);
    const CandidatePair& pair = pairs_[index];
    const auto lost = [&] {  // not overlapping: a stick spring is released
      if (!may_hold_friction_[index]) return;
      if (friction_of(pair) > 0.0) {
        friction_.erase(PairId{tets.gid[pair.a], tets.gid[pair.b]});
        if (!friction_of_pair_.empty()) friction_of_pair_[index] = nullptr;
      }
      may_hold_friction_[index] = 0;
    };
    // (a corner may hold just outside its face's tet, beside a fold: corners_ tests every pair)
    if (!corners_ && !boxes_intersect(tet_boxes_[slot_a], tet_boxes_[slot_b])) {
      if (clip_replay_)
        apart_pairs_.found(index, pair_count, slot_a, slot_b,
                           box_gap(tet_boxes_[slot_a], tet_boxes_[slot_b]));
      lost();
      continue;
    }
    const TetGeometry& geometry_a = tet_geometry_[slot_a];
    const TetGeometry& geometry_b = tet_geometry_[slot_b];
    const int ma = tets.material[pair.a], mb = tets.material[pair.b];
    const double mu = friction_of(pair);
    if (!corners_ && pair.a != prepared) {
      prepare_contactor(geometry_a, contactor);
      prepared = pair.a;
    }
    const double penalty = std::min(penalty_[ma], penalty_[mb]);
    ClipMemo memo;
    memo.apart_before = apart_before;
    std::size_t record_start = 0;
    if (clip_replay_) {
      if (clip_record_at_.size() != pair_count) {
        clip_record_at_.assign(pair_count, kNoClipRecord);
        apart_at_.assign(pair_count, ClipMemo::kNotApart);
      }
      if (clip_read_at != kNoClipRecord) {
        const std::uint8_t* const at = clip_read.data() + clip_read_at;
        memo.previous = at + 2;
        memo.previous_end = memo.previous + (at[0] | (at[1] << 8));
      }
      record_start = clip_written.size();
      clip_written.append_pair(0, 0);  // the pair's length, once known
      memo.record = &clip_written;
      memo.topologies = &clip_topologies_;
    }
    const ContactPairResult r =
        corners_ ? corner_contact(geometry_a, corner_tets_[slot_a], geometry_b,
                                  corner_tets_[slot_b], penalty)
                 : potential_contact(contactor, geometry_b, penalty, sliver_tolerance_,
                                     clip_replay_ ? &memo : nullptr);
    if (clip_replay_) {
      const std::size_t length = clip_written.size() - record_start - 2;
      if (length == 0 || length > 0xFFFFu || record_start >= kNoClipRecord) {
        clip_written.shrink_to(record_start);
      } else {
        clip_written.data()[record_start] = static_cast<std::uint8_t>(length & 0xFFu);
        clip_written.data()[record_start + 1] = static_cast<std::uint8_t>(length >> 8);
        clip_record_at_[index] = static_cast<std::uint32_t>(record_start);
      }
      pieces_replayed_ += memo.replayed;
      pieces_clipped_ += memo.clipped;
      apart_at_[index] = memo.apart_now;
      apart_pairs_.found(index, pair_count, slot_a, slot_b, memo.apart_gap);
      pairs_apart_by_edge_axis_ +=
          memo.apart_now >= ClipMemo::kApartAtAxis && memo.apart_now < ClipMemo::kApartAtPlane;
    }
    // Every rank that holds a pair computes it; the owner of its first tet reports its energies.
    const double share = tets.is_owned(pair.a) ? 1.0 : 0.0;
    if (corners_)  // a pair without contact may stay so for a known travel (corner_contact.hpp)
      apart_pairs_.found(index, pair_count, slot_a, slot_b,
                         r.overlapping
                             ? 0.0
                             : corner_pair_apart_travel(geometry_a, corner_tets_[slot_a],
                                                        geometry_b, corner_tets_[slot_b]));
    if (!r.overlapping) {
      lost();
      continue;
    }
    overlapping_[index] = 1;
    may_hold_friction_[index] = 1;
    out.active_pairs += share > 0.0 ? 1 : 0;
    out.energy += share * r.energy;
    const LocalIndex* const node_a = tets.nodes.data() + 4 * static_cast<std::size_t>(pair.a);
    const LocalIndex* const node_b = tets.nodes.data() + 4 * static_cast<std::size_t>(pair.b);
    Vec3 va[4], vb[4];
    for (int c = 0; c < 4; ++c) va[c] = vb[c] = Vec3::Zero();
    const double xi = std::max(damping_ratio_[ma], damping_ratio_[mb]);
    if (mu > 0.0 || xi > 0.0)
      for (int c = 0; c < 4; ++c) {
        va[c] = vec3_at(nodes.v.data(), node_a[c]);
        vb[c] = vec3_at(nodes.v.data(), node_b[c]);
      }
    // A round-off sliver (overlap below 1e-12 of the smaller tet, e.g. coplanar faces touching
    // at t = 0) has no meaningful secant stiffness F²/(2U) (seen 1.6e23 N/m from F = 6e-41 N,
    // U = 1e-104 J): no dashpot on it.
    const double sliver =
        1e-12 * std::min(std::abs(tets.volume0[pair.a]), std::abs(tets.volume0[pair.b]));
    double f_n = 0.0;  // N: the dashpot's force on the contactor along r.normal
    const bool damped =
        xi > 0.0 && r.energy > 0.0 && r.normal_force > 0.0 && r.overlap_volume > sliver;
    if (damped) {
      // Normal dashpot c = 2ξ√(k m): k = F²/(2U) is the pair's secant stiffness (exact for U ∝ d²),
      // m the reduced mass of the two pieces (contact.dashpot: bodies) or of the two tets (tets);
      // a fixed partner has infinite mass.  The dashpot never pulls harder than the elastic push,
      // so it cannot make the contact sticky.
      const double k = r.normal_force * r.normal_force / (2.0 * r.energy);
      const double m_a = model.materials[ma].density * std::abs(tets.volume0[pair.a]);
      const double m_b = model.materials[mb].density * std::abs(tets.volume0[pair.b]);
      const bool a_fixed = piece_fixed(model, tets.piece[pair.a]),
                 b_fixed = piece_fixed(model, tets.piece[pair.b]);
      double coefficient = 0.0;  // N·s/m
      if (body_dashpot_) {       // dashpot_kernels.hpp: sized by the pieces, implicit on the pair
        const auto piece_mass = [&](LocalIndex t, double tet_mass) {
          return tets.dashpot_mass[t] > 0.0 ? tets.dashpot_mass[t] : tet_mass;
        };
        double inverse_a[4], inverse_b[4];
        for (int q = 0; q < 4; ++q) {
          inverse_a[q] = a_fixed ? 0.0 : 1.0 / nodes.mass[node_a[q]];
          inverse_b[q] = b_fixed ? 0.0 : 1.0 / nodes.mass[node_b[q]];
        }
        coefficient = dashpot_coefficient(
            xi, k, reduced_mass(piece_mass(pair.a, m_a), a_fixed, piece_mass(pair.b, m_b), b_fixed),
            centroid_point_mass(r, inverse_a, inverse_b), dt);
      } else {
        coefficient = dashpot_coefficient(xi, k, reduced_mass(m_a, a_fixed, m_b, b_fixed), 0.0, dt);
      }
      const double v_n = relative_velocity_at_centroid(r, va, vb).dot(r.normal);
      f_n = std::max(-coefficient * v_n, -r.normal_force);
    }
    FrictionResult f;
    if (mu > 0.0) {
      // Stick spring k_t = p·s (N/m) with s the pair's size: as stiff as the normal contact.
      // (set once per contact: the pair's reference volumes do not change)
      if (friction_of_pair_.empty()) friction_of_pair_.assign(pair_count, nullptr);
      PairFriction*& entry = friction_of_pair_[index];
      if (!entry) entry = &friction_[PairId{tets.gid[pair.a], tets.gid[pair.b]}];
      PairFriction& pair_friction = *entry;
      if (!(pair_friction.stiffness > 0.0))
        pair_friction.stiffness =
            penalty * std::cbrt(std::abs(tets.volume0[pair.a]) + std::abs(tets.volume0[pair.b]));
      const FrictionLaw law{mu, pair_friction.stiffness};
      pair_friction.owned = share > 0.0;
      FrictionHistory& history = pair_friction.history;
      // The spring joins two material points, anchored at the first real overlap's centroid (a
      // round-off sliver's centroid is noise) and following the centroid with a lag; it acts
      // midway between them (friction_kernels.hpp).
      if (r.overlap_volume > sliver) {
        if (!history.attached())
          history.attach(r);
        else
          history.follow(r, anchor_follow);
      }
      FrictionPoint point = centroid_point(r);
      if (history.attached()) spring_point(history, geometry_a, geometry_b, point);
      f = coulomb_friction(law, r, point, relative_velocity_at(point, va, vb), dt, history);
      if (f.slipping && history.attached()) slide_anchors(history, geometry_a, geometry_b, f.slip);
      out.friction_spring_energy += share * f.spring_energy;
    }
    // One pass over the pair's nodes: each node's force takes its contact, dashpot and friction
    // parts in that order, as three passes would add them (a pair's tets share no node: pairs
    // within one group are never candidates; a shared node would only sum in another order), the
    // dashpot's and friction's arrays their own.
    double* const force = nodes.f.data();
    double* const damping_force = damped ? writable(damping_force_, damping_written_) : nullptr;
    double* const friction_force =
        mu > 0.0 ? writable(friction_force_, friction_written_) : nullptr;
    const auto add_to_node = [&](LocalIndex node, const Vec3& contact, double centroid_weight,
                                 const Vec3& friction) {
      Vec3 total = vec3_at(force, node) + contact;
      if (damped) {
        const Vec3 damping = centroid_weight * f_n * r.normal;
        total += damping;
        vec3_at(damping_force, node) += damping;
      }
      if (mu > 0.0) {
        total += friction;
        vec3_at(friction_force, node) += friction;
      }
      vec3_at(force, node) = total;
    };
    for (int c = 0; c < 4; ++c)
      add_to_node(node_a[c], r.force_contactor[c], r.centroid_weights_contactor[c],
                  f.force_contactor[c]);
    for (int c = 0; c < 4; ++c)
      add_to_node(node_b[c], r.force_target[c], -r.centroid_weights_target[c], f.force_target[c]);
    if (share > 0.0)
      records_.push_back({r.centroid, r.normal_force * r.normal, f.tangential_force});
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

}  // namespace fdem
