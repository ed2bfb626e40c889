// The contact stages of the step: detection (NBS, re-run only when a node has moved more than
// buffer/2 since the last detection) and contact forces (potential tet–tet contact + friction)
// over the candidate pairs.  Tets of one discrete element (piece) never contact each other: the
// mesh carries their compression.
#pragma once

#include <limits>
#include <memory>
#include <unordered_map>
#include <vector>

#include "contact/apart_pairs.hpp"
#include "contact/broad_phase.hpp"
#include "contact/clip_replay.hpp"
#include "contact/clip_topologies.hpp"
#include "contact/corner_contact.hpp"
#include "contact/friction_kernels.hpp"
#include "contact/nbs.hpp"
#include "core/model.hpp"
#include "core/travelling_state.hpp"

namespace fdem {

// Tet t's corners at the model's current positions (m).
inline TetCorners tet_corners(const Model& model, LocalIndex t) {
  TetCorners corners;
  for (int c = 0; c < 4; ++c)
    corners.x[c] = vec3_at(model.nodes.x.data(), model.tets.nodes[4 * t + c]);
  return corners;
}

struct ContactSettings {
  double buffer = -1.0;  // m; < 0: automatic (0.25 × median tet box size)
  // Leave enclosed tets out of contact while their body's joints hold (scene key
  // contact.skip_enclosed; false keeps them in, the previous algorithm, for benchmarks).
  bool skip_enclosed = true;
  // Narrow the detected pairs by the tets' exact distance as well as by their face planes (scene
  // key contact.narrowing: exact; face_planes is the previous algorithm, for benchmarks).
  bool exact_narrowing = true;
  // Time (s) with which a stick spring's anchors follow the overlap centroid (scene key
  // contact.friction_anchor_lag; friction_kernels.hpp, docs/verification.md).
  double friction_anchor_lag = 0.05;
  // Size the normal dashpot by the masses of the two pieces in contact (scene key
  // contact.dashpot: bodies), or by the two tets' (tets: the previous formulation, for
  // comparison); docs/verification.md, "Free rocking".
  bool body_dashpot = true;
  // Pairs and pieces whose nodal forces are proven below this fraction of p·ℓ² and below 1/1000
  // of a face pressed as deep are left out (scene key contact.sliver_tolerance;
  // pair_force_bound.hpp); at the default 1e-6 the second condition decides.  0 integrates every
  // pair that the face planes pass (the previous algorithm, for benchmarks).
  double sliver_tolerance = 1e-6;
  // Replay each lasting pair's piece clips from the step before where they cut the same vertices
  // (scene key contact.clip_replay; clip_replay.hpp): the same results bit for bit, without the
  // clipper's graph work.  false clips every piece afresh (the previous algorithm, for benchmarks).
  bool clip_replay = true;
  // Corner contact (scene key contact.formulation: corners; corner_contact.hpp) in place of
  // potential contact: a hinge's thrust stays at its edge.  Needs TetArrays::contact_faces.
  bool corners = false;
  // The least ratio of the contact dashpot, whatever the materials say (kCornerDampingRatio for
  // corner contact under quasi-static local damping, else 0).
  double least_damping_ratio = 0.0;
};

// Friction history of one pair, keyed by the two tets' global ids (a < b): what travels with
// the pair when the model is redistributed or checkpointed.
struct FrictionEntry {
  GlobalId a = 0, b = 0;
  Vec3 spring = Vec3::Zero();  // stick spring (m)
  double stiffness = 0.0;      // N/m
  // The spring's anchors: barycentric weights in tet a and in tet b (FrictionHistory).
  double anchor_a[4] = {0.0, 0.0, 0.0, 0.0};
  double anchor_b[4] = {0.0, 0.0, 0.0, 0.0};
};

// Friction entries as the pair records that travel with their first tet (TravellingState), and
// back: spring (m) in values 0–2, stiffness (N/m) in value 3, anchors in values 4–7 (tet a) and
// 8–11 (tet b).
std::vector<PairRecord> friction_records(const std::vector<FrictionEntry>& entries);
std::vector<FrictionEntry> friction_entries(const std::vector<PairRecord>& records);

// Energy taken from the bodies by friction and by the contact dashpots (J): minus the work of
// those forces on the owned nodes, with the integrator's trapezoid rule.  Step n gives
// −F_n·v_n−½·dt/2 ("before", in add_forces) and −F_n·v_n+½·dt/2 ("after", in work_after once the
// step is integrated); central difference's ½m·v_n−½·v_n+½ changes by exactly these halves.
struct ContactWork {
  double friction = 0.0;
  double damping = 0.0;
};

struct ContactForceSummary {
  double energy = 0.0;                  // Σ U of overlapping pairs (J)
  ContactWork work_before;              // J, the "before" halves of this step
  double friction_spring_energy = 0.0;  // J stored in stick springs (part of the contact energy)
  std::int64_t candidate_pairs = 0;     // may exceed the local tet count many times: 64-bit
  std::int64_t active_pairs = 0;        // overlapping pairs
};

// One active contact for output: where it acts and the force on the contactor.
struct ContactRecord {
  Vec3 point;
  Vec3 normal_force;
  Vec3 tangential_force;
};

class ContactStage {
 public:
  ContactStage(const Model& model, ContactSettings settings);

  // Largest box extent (m) of each owned tet at the current positions, and the automatic buffer
  // made from their median (0.25 × median): distributed runs take the median over all ranks.
  static std::vector<double> tet_sizes(const Model& model);
  static double auto_buffer(double median_tet_size) { return 0.25 * median_tet_size; }

  // Whether a scene needs contact at all: at least two pieces that are not both fixed.
  static bool needed(const Model& model);

  // Re-detects candidate pairs when the buffer is used up (or on the first call).  Returns true
  // if detection ran.
  bool detect_if_needed(const Model& model);
  // Whether this rank's nodes call for detection (a node moved more than buffer/2, a bond was
  // released, or none ran yet); a parallel run detects when any rank says so.
  bool detection_due(const Model& model) const;
  // Detection at the current positions.
  void detect(const Model& model);

  // Parallel runs (docs/parallel.md): after the model was redistributed, take over the state
  // that travelled with it — positions at the last detection (3 per local node), each local
  // tet's joint state, the friction history of the pairs held here — and rebuild the bonds from
  // the model's intact joints.  `detected`: whether a detection happened yet.  Then the candidate
  // pairs of the last detection: `candidates` (by gid, as candidate_gids() gave them on the ranks
  // that owned their tet a) keeps those this rank computes — both tets held, one active; without
  // them, the last detection is repeated at the positions it saw.  Both give the same list.
  void rebind(const Model& model, std::vector<double> x_at_detection,
              std::vector<std::uint8_t> tet_joint_state, const std::vector<FrictionEntry>& friction,
              bool detected, const std::vector<GidPair>* candidates = nullptr);
  // The candidate pairs of the last detection by global ids, sorted: what travels with the tets
  // when the model is redistributed between detections.
  std::vector<GidPair> candidate_gids(const Model& model) const;
  std::vector<FrictionEntry> friction_entries() const;
  // How many broad-phase passes ran (detections, and their repeats after a migration or a
  // release of bonds): a measure of what travelling candidates save.
  long broad_phase_passes() const { return broad_phase_passes_; }
  // Parallel runs, once the travelling state was taken: frees what rebind() rebuilds (candidate
  // pairs, their records and friction map, the detector's grids) so that it does not add to
  // the migration's buffers at the peak of the step loop.
  void release_until_rebind();
  // Positions (m, xyz) of every local node at the last detection, for checkpoints and
  // migration: the nodes of the tets that may pair as the detection saw them, the others (nodes
  // of enclosed tets only, which no detection looks at before their body cracks) where they are.
  std::vector<double> positions_at_detection(const Model& model) const;
  // Largest travel (m) since the last detection of an owned node of the tets that may pair
  // (+infinity for NaN); 0 before the first detection.
  double travel_since_detection(const Model& model) const;
  // After each integrated step (model.nodes.x at x_n+1): does the next step have to detect
  // (detection_needed on travel_since_detection)?  `step_travel` is the step's largest node
  // travel and `largest_coordinate` the largest |x| component after it (m).  The steps' travels
  // summed with their rounding bound the travel since the detection from above; while that bound
  // is below the threshold the answer is no without a pass over the nodes.
  bool detection_due_after_step(const Model& model, double step_travel, double largest_coordinate);
  std::vector<std::uint8_t> tet_joint_states() const;
  bool detected() const { return detected_; }
  // Adds contact forces to model.nodes.f (pairs in ascending (gid, gid) order).
  ContactForceSummary add_forces(Model& model, double dt);
  // The "after" halves of the friction and dashpot work of the last add_forces, once the step is
  // integrated (model.nodes.v holds v_n+½ of the owned nodes).
  ContactWork work_after(const Model& model, double dt) const;

  // Tets bonded by an intact cohesive joint never pair (the joint carries their load).  Pairs
  // are model tet indices, at most 4 bonds per tet (one per face).
  void set_bonds(LocalIndex n_tets, const std::vector<std::pair<LocalIndex, LocalIndex>>& pairs);
  // Joints broke: the two tets of each (model tet indices; −1 for a tet not held here) become
  // contact partners, and cracked (pairs with the tets they met at a mesh node may form).  The
  // buffer rule would not notice pairs that are already inside the buffer, so the candidates are
  // found again at the positions of the last detection: the list only grows, by the pairs the
  // release allows, and the positions at detection, the detection count and the friction history
  // stay — no detection falls due (the freed pairs are as safe as any until the next one).
  void release_bonds(const Model& model,
                     const std::vector<std::pair<LocalIndex, LocalIndex>>& pairs);
  // Bonded tets flagged in `enclosed` (per model tet, TetArrays::enclosed; empty: none) become
  // enclosed; call after set_bonds.
  void enclose(const std::vector<std::uint8_t>& enclosed);
  // A joint of body `body` broke (anywhere, on any rank): its enclosed tets take part in contact
  // from the next detection on.
  void crack_body(std::int32_t body);
  bool body_cracked(std::int32_t body) const {
    return body_cracked_[static_cast<std::size_t>(body)] != 0;
  }
  // Enclosed tets left out of the last detection.
  std::int64_t left_out() const { return left_out_count_; }

  // Penalty (Pa) of each material as resolved (auto → 10 × Young's modulus).
  const std::vector<double>& material_penalty() const { return penalty_; }
  // Stable step (s) of the contact springs alone: a face pressed a depth d into a tet of altitude H
  // stores U ≈ 2pAd²(1/H_c + 1/H_t), a stiffness 8pA/H on a tet's node mass ρAH/12 at most, so
  // ω_c² ≤ 96p/(ρH²) with H the smallest altitude.  Combine with the elastic step by adding ω².
  double critical_time_step(const Model& model) const;
  double buffer() const { return buffer_; }
  long detections() const { return detections_; }
  // Pieces replayed from the step before and pieces clipped afresh, over the run (clip_replay).
  std::uint64_t pieces_replayed() const { return pieces_replayed_; }
  std::uint64_t pieces_clipped() const { return pieces_clipped_; }
  // Pairs apart at the step before that an edge-edge axis showed still apart (clip_replay.hpp).
  std::uint64_t pairs_apart_by_edge_axis() const { return pairs_apart_by_edge_axis_; }
  // Pair evaluations skipped over the run: apart by more than their tets had moved since.
  std::uint64_t pair_steps_kept_apart() const { return pair_steps_kept_apart_; }
  const std::vector<CandidatePair>& candidates() const { return pairs_; }
  // Per candidate pair: whether it overlapped at the last add_forces (it then costs the full
  // overlap integration, ~60× a tet's internal force; a separated pair is rejected early).
  const std::vector<std::uint8_t>& overlapping() const { return overlapping_; }
  const std::vector<ContactRecord>& records() const { return records_; }

 private:
  static bool piece_fixed(const Model& model, std::int32_t piece);
  // Boxes (boxes_) of every tet, or of `members` only (in their order).
  void compute_boxes(const Model& model, const double* x,
                     const std::vector<LocalIndex>* members = nullptr);
  ContactWork work_against(const Model& model, double dt) const;
  void run_detection(const Model& model, const double* x);
  bool keeps(const Model& model, const double* x, LocalIndex a, LocalIndex b) const;
  void add_pairs_of(const Model& model, const std::vector<LocalIndex>& changed);

  double buffer_ = 0.0;
  std::vector<double> penalty_;
  NbsDetector detector_;
  std::vector<double> boxes_;  // 6 per tet: lo xyz, hi xyz (m); between compute_boxes and detection
  // Positions at the last detection (m, xyz): of every local node while every_node_kept_, else
  // of kept_nodes_ (ascending), the nodes of the tets that may pair.  An intact jointed body's
  // enclosed tets hold most of its nodes, whose positions no detection needs (24 B per node).
  std::vector<double> x_at_detection_;
  std::vector<LocalIndex> kept_nodes_;
  bool every_node_kept_ = true;
  // Upper bound of every owned node's travel since the last detection (m): 0 at a detection,
  // then Σ (step travel + rounding); unknown (+inf) after a rebind until the next detection.
  double travel_bound_ = std::numeric_limits<double>::infinity();
  // Keeps the positions x of the nodes the last mark_left_out() lets pair (or all of them).
  void keep_positions(const Model& model, const double* x);
  std::vector<CandidatePair> pairs_;
  std::vector<std::uint8_t> overlapping_;
  // Per candidate pair: it may hold a friction history (it overlapped at the last add_forces, or
  // the list is new since): only those pay a map lookup when they do not overlap.
  std::vector<std::uint8_t> may_hold_friction_;
  std::vector<ContactRecord> records_;
  // The distinct tets of pairs_ (ascending), per pair the indices of its two tets in that list
  // (2 per pair), and their boxes and geometry, computed once per step for all their pairs (a
  // surface tet of a dense pile is in ~14 pairs; rejecting a pair then costs a box test, over
  // boxes kept apart so that they stay in cache).  The lists follow pairs_ (candidates_changed);
  // boxes and geometry are per step.
  std::vector<LocalIndex> pair_tets_;
  std::vector<std::int32_t> pair_slots_;
  std::vector<TetBox> tet_boxes_;
  std::vector<TetGeometry> tet_geometry_;
  // Corner contact (ContactSettings::corners): per tet of pair_tets_, what corner_contact reads
  // besides its geometry (static; made again when the list changes).
  bool corners_ = ContactSettings{}.corners;
  std::vector<CornerTet> corner_tets_;
  // Fills pair_tets_ and pair_slots_ for the current pairs_.
  void index_pair_tets();
  // tet_boxes_ and tet_geometry_ at the current positions (indexing the pairs' tets first when
  // pairs_ changed).
  void update_tet_geometry(const Model& model);
  // Per-pair state starts afresh after pairs_ changed.
  void candidates_changed();
  // Friction history per pair, keyed by the two tets' global ids; kept across re-detection.
  struct PairFriction {
    FrictionHistory history;
    double stiffness = 0.0;  // N/m, for the energy released when the pair ends
    bool owned = true;       // this rank owns tet a: it reports the pair's energies
  };
  // Key of a pair: both tets' global ids in full (64-bit each, any model size).
  struct PairId {
    GlobalId a, b;
    bool operator==(const PairId& other) const { return a == other.a && b == other.b; }
  };
  struct PairIdHash {
    std::size_t operator()(const PairId& p) const {
      std::uint64_t h = static_cast<std::uint64_t>(p.a) * 0x9E3779B97F4A7C15ULL ^
                        static_cast<std::uint64_t>(p.b) * 0xC2B2AE3D27D4EB4FULL;
      h ^= h >> 29;
      return static_cast<std::size_t>(h * 0xbf58476d1ce4e5b9ULL);
    }
  };
  std::unordered_map<PairId, PairFriction, PairIdHash> friction_;
  // Per candidate pair: its entry in friction_ once looked up (null: not yet, or none), so that a
  // lasting contact pays one hash lookup, not one per step.  Entries of an unordered_map stay
  // put; every erase clears the pointer to it (the pair's own, or all with candidates_changed).
  std::vector<PairFriction*> friction_of_pair_;
  std::vector<double> friction_coefficient_, damping_ratio_;
  // Friction and dashpot forces of the last add_forces per local node (N, xyz), for their work;
  // empty until a step writes such a force.
  std::vector<double> friction_force_, damping_force_;
  bool friction_written_ = false, damping_written_ = false;  // by the last add_forces
  std::vector<LocalIndex> bonds_;  // 4 per tet: partner bonded by an intact joint, or −1
  using JointState = TetJointState;
  std::vector<JointState> joint_state_;
  // The settings' own defaults (the constructor sets every one from its ContactSettings).
  bool skip_enclosed_ = ContactSettings{}.skip_enclosed;
  bool exact_narrowing_ = ContactSettings{}.exact_narrowing;
  double friction_anchor_lag_ = ContactSettings{}.friction_anchor_lag;  // s
  bool body_dashpot_ = ContactSettings{}.body_dashpot;
  double sliver_tolerance_ = ContactSettings{}.sliver_tolerance;  // (-)
  bool clip_replay_ = ContactSettings{}.clip_replay;
  // The pieces' clips of the last add_forces (clip_replay.hpp), for the next one to replay: each
  // pair's record in clip_records_[clip_parity_] at clip_record_at_[pair] (kNoClipRecord: none),
  // the pair's length in its first two bytes.  The offsets exist from the first pair whose boxes
  // meet, and go with the candidate list.
  static constexpr std::uint32_t kNoClipRecord = 0xFFFFFFFFu;
  RecordBytes clip_records_[2];
  std::vector<std::uint32_t> clip_record_at_;
  // Every clip met on this rank, shared by all pairs: where a pair's record of the step before
  // no longer fits its piece.
  piece_clip::ClipTopologies clip_topologies_;
  // Per candidate pair, how it came out apart at the step before (ClipMemo::apart_before); with
  // clip_record_at_.
  std::vector<std::uint8_t> apart_at_;
  // Pairs found apart by a gap their tets have not yet travelled (with clip_replay), skipped.
  ApartPairs apart_pairs_;
  int clip_parity_ = 0;
  std::uint64_t pieces_replayed_ = 0, pieces_clipped_ = 0, pairs_apart_by_edge_axis_ = 0,
                pair_steps_kept_apart_ = 0;
  std::vector<std::uint8_t> body_cracked_;  // per body: one of its joints broke
  std::vector<std::uint8_t> left_out_;      // per tet, at the last detection
  std::int64_t left_out_count_ = 0;
  long detections_ = 0;
  long broad_phase_passes_ = 0;
  // left_out_ for the current joint states and cracked bodies (enclosed tets of intact bodies).
  void mark_left_out(const Model& model);
  bool detected_ = false;
};

}  // namespace fdem
