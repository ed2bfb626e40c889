#include "fracture/joint_stage.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "core/error.hpp"
#include "fracture/joint_law_advice.hpp"

namespace fdem {

JointStage::JointStage(const Model& model) {
  laws_.reserve(model.joint_laws.size());
  // Laws of one block share its softening curve (a strength distribution gives a block hundreds
  // of laws; a curve costs 20 001 samples of z to build).
  std::vector<SofteningCurve> curves;
  for (std::size_t i = 0; i < model.joint_laws.size(); ++i) {
    const JointLawSpec& spec = model.joint_laws[i];
    const CohesiveParameters p = cohesive_parameters(spec);
    const auto same = [&](const SofteningCurve& c) {
      return c.a() == p.softening_a && c.b() == p.softening_b && c.c() == p.softening_c;
    };
    auto curve = std::find_if(curves.begin(), curves.end(), same);
    try {
      if (curve == curves.end())
        curve = curves.insert(curves.end(),
                              SofteningCurve(p.softening_a, p.softening_b, p.softening_c));
      laws_.emplace_back(p, *curve);
      intact_laws_.emplace_back(laws_.back());
    } catch (const InputError& e) {
      if (curve == curves.end()) throw InputError(spec.origin + ": " + e.what());
      throw InputError(joint_law_message(model.joint_laws, i, *curve, e.what()));
    }
  }
  const JointArrays& joints = model.joints;
  slot_.assign(static_cast<std::size_t>(joints.size()), -1);
  for (LocalIndex j = 0; j < joints.size(); ++j) {
    FDEM_VERIFY(joints.law[j] >= 0 && joints.law[j] < static_cast<int>(laws_.size()),
                "joint law index");
    if (joints.broken[j]) {
      JointHistory& h = live_[static_cast<std::size_t>(promote(j))];
      h.broken = true;
      h.mode = static_cast<FailureMode>(joints.mode[j]);  // failure time: from rebind's history
      for (auto& p : h.point) p.damage = 1.0;
      ++broken_;
    }
  }
}

std::int32_t JointStage::promote(LocalIndex j) {
  std::int32_t& slot = slot_[static_cast<std::size_t>(j)];
  if (slot >= 0) return slot;
  FDEM_VERIFY(live_.size() < static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()),
              "joint history slots");
  slot = static_cast<std::int32_t>(live_.size());
  live_.push_back(JointHistory{});
  return slot;
}

std::vector<JointHistory> JointStage::history() const {
  std::vector<JointHistory> out(slot_.size());
  for (std::size_t j = 0; j < slot_.size(); ++j)
    if (slot_[j] >= 0) out[j] = live_[static_cast<std::size_t>(slot_[j])];
  return out;
}

void JointStage::add_intact(Model& model, LocalIndex j, const IntactJointBatch& batch, int lane,
                            double share, JointStepSummary& out) {
  const LocalIndex* id = model.joints.nodes.data() + 6 * static_cast<std::size_t>(j);
  double* f = model.nodes.f.data();
  for (int i = 0; i < 6; ++i) {
    double* node_force = f + 3 * static_cast<std::size_t>(id[i]);
    for (int k = 0; k < 3; ++k) node_force[k] += batch.force[3 * i + k][lane];
  }
  out.stored_energy += share * batch.stored_energy[lane];  // nothing dissipated while pristine
}

void JointStage::add_full_law(Model& model, LocalIndex j, double share, double time, double step,
                              JointStepSummary& out) {
  JointArrays& joints = model.joints;
  const LocalIndex* id = joints.nodes.data() + 6 * static_cast<std::size_t>(j);
  const bool was_pristine = slot_[static_cast<std::size_t>(j)] < 0;
  const std::int32_t slot = promote(j);
  Vec3 x[6];
  for (int i = 0; i < 6; ++i) x[i] = vec3_at(model.nodes.x.data(), id[i]);
  JointHistory& h = live_[static_cast<std::size_t>(slot)];
  if (was_pristine) {  // the previous step's opening and shear, for the energy terms
    Vec3 previous[6];
    for (int i = 0; i < 6; ++i) previous[i] = x[i] - step * vec3_at(model.nodes.v.data(), id[i]);
    IntactJointState state;
    intact_state_at(previous, laws_[joints.law[j]], state);
    for (int i = 0; i < 3; ++i) {
      h.point[i].previous_opening = state.previous_opening[i];
      h.point[i].previous_shear_sq = state.previous_shear_sq[i];
    }
  }
  const JointForce f = joint_force(x, joints.area0[j], laws_[joints.law[j]], h);
  for (int i = 0; i < 6; ++i) vec3_at(model.nodes.f.data(), id[i]) += f.force[i];
  out.stored_energy += share * f.stored_energy;
  out.fracture_dissipated += share * f.fracture_energy;
  out.friction_dissipated += share * f.friction_energy;
  if (!f.newly_broken) return;
  h.failure_time = time;
  joints.broken[j] = 1;
  joints.mode[j] = static_cast<std::uint8_t>(h.mode);
  newly_broken_.push_back(j);
}

// The whole loop built twice, AVX2 and the x86-64 baseline, chosen when the program loads: the
// lanes' gathers and scatters and the inlined intact step then use the CPU's full vector width
// (no FMA in either, so both give the same bits).
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
__attribute__((target_clones("avx2", "default"), flatten))
#endif
JointStepSummary
JointStage::add_forces(Model& model, double time, double step) {
  JointStepSummary out;
  newly_broken_.clear();
  JointArrays& joints = model.joints;
  NodeArrays& nodes = model.nodes;
  const LocalIndex n = joints.size();
  const TetArrays& tets = model.tets;
  // Joints go in chunks of `lanes`: the pristine ones of a chunk take their intact step together
  // (intact_joint_steps), then every joint of the chunk adds its forces in joint order, so each
  // node receives its contributions in the same order as one joint at a time.
  constexpr int lanes = intact_lanes;
  constexpr LocalIndex prefetch_ahead = 2 * lanes;
  enum class Kind : unsigned char { elsewhere, pristine, live };
  IntactJointBatch batch;
  Kind kind[lanes];
  double share[lanes];  // 1 where this rank reports the joint's energies (it owns tet A)
  const LocalIndex* id[lanes];
  double w[lanes];
  const IntactJointLaw* law[lanes];
  for (LocalIndex start = 0; start < n; start += lanes) {
    const int count = static_cast<int>(std::min<LocalIndex>(lanes, n - start));
    int first_pristine = -1;
    for (int l = 0; l < count; ++l) {
      const LocalIndex j = start + l;
      // Face B's nodes belong to the neighbouring tet, often far from face A's in memory: fetched
      // ahead, they are in cache when the joint is computed.
      if (j + prefetch_ahead < n)
        for (int i = 3; i < 6; i += 2) {
          const LocalIndex node =
              joints.nodes[6 * static_cast<std::size_t>(j + prefetch_ahead) + i];
          __builtin_prefetch(nodes.x.data() + 3 * static_cast<std::size_t>(node));
          __builtin_prefetch(nodes.f.data() + 3 * static_cast<std::size_t>(node), 1);
        }
      const LocalIndex tet_a = joints.tets[2 * j], tet_b = joints.tets[2 * j + 1];
      kind[l] = joints.broken[j] || (!tets.is_active(tet_a) && !tets.is_active(tet_b))
                    ? Kind::elsewhere  // broken, or computed by other ranks
                : slot_[static_cast<std::size_t>(j)] < 0 ? Kind::pristine
                                                         : Kind::live;
      share[l] = tets.is_owned(tet_a) ? 1.0 : 0.0;
      id[l] = joints.nodes.data() + 6 * static_cast<std::size_t>(j);
      if (kind[l] != Kind::pristine) continue;
      w[l] = joints.area0[j] / 3.0;
      law[l] = &intact_laws_[joints.law[j]];
      if (first_pristine < 0) first_pristine = l;
    }
    if (first_pristine >= 0) {
      const LocalIndex* lane_id[lanes];
      for (int l = 0; l < lanes; ++l) {  // a lane without a pristine joint computes a copy
        const int from = l < count && kind[l] == Kind::pristine ? l : first_pristine;
        lane_id[l] = id[from];
        w[l] = w[from];
        law[l] = law[from];
      }
      set_lanes(batch, nodes.x.data(), lane_id, w, law);
      intact_joint_steps(batch);
    }
    for (int l = 0; l < count; ++l) {
      if (kind[l] == Kind::pristine && batch.step[l] != IntactStep::leaves)
        add_intact(model, start + l, batch, l, share[l], out);
      else if (kind[l] != Kind::elsewhere)  // a full history, or a pristine joint now at strength
        add_full_law(model, start + l, share[l], time, step, out);
    }
  }
  // Count the ones this rank reports (tet A owned); the ranks that hold a joint without computing
  // it learn of it through mark_broken.
  const auto reported =
      std::count_if(newly_broken_.begin(), newly_broken_.end(),
                    [&](LocalIndex j) { return tets.is_owned(joints.tets[2 * j]); });
  broken_ += static_cast<LocalIndex>(reported);
  out.newly_broken = static_cast<LocalIndex>(reported);
  out.broken = broken_;
  return out;
}

void JointStage::rebind(const Model& model, std::vector<JointHistory> history) {
  FDEM_VERIFY(history.size() == static_cast<std::size_t>(model.joints.size()),
              "one history per local joint");
  slot_.assign(history.size(), -1);
  live_.clear();
  for (std::size_t j = 0; j < history.size(); ++j) {
    const JointHistory& h = history[j];
    bool zero = pristine(h) && !h.broken && h.mode == FailureMode::none;
    for (const auto& p : h.point)
      zero = zero && p.damage == 0.0 && p.plastic_slip[0] == 0.0 && p.plastic_slip[1] == 0.0;
    if (zero) continue;  // pristine: no state (its energy terms come from the positions)
    slot_[j] = static_cast<std::int32_t>(live_.size());
    live_.push_back(h);
  }
  live_.shrink_to_fit();
  newly_broken_.clear();
}

void JointStage::mark_broken(Model& model, LocalIndex j, double time, std::uint8_t mode) {
  JointArrays& joints = model.joints;
  if (joints.broken[j]) return;
  JointHistory& h = live_[static_cast<std::size_t>(promote(j))];
  h.broken = true;
  h.mode = static_cast<FailureMode>(mode);
  h.failure_time = time;
  for (auto& p : h.point) p.damage = 1.0;
  joints.broken[j] = 1;
  joints.mode[j] = mode;
}

double JointStage::critical_time_step(const Model& model) const {
  const JointArrays& joints = model.joints;
  std::vector<double> stiffness(model.nodes.size(), 0.0);  // Σ 2k·A0/3 per node (N/m)
  for (LocalIndex j = 0; j < joints.size(); ++j) {
    const CohesiveLaw& law = laws_[joints.law[j]];
    const double k =
        2.0 * std::max(law.normal_stiffness(), law.tangential_stiffness()) * joints.area0[j] / 3.0;
    for (int i = 0; i < 6; ++i) stiffness[joints.nodes[6 * j + i]] += k;
  }
  double omega2 = 0.0;
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (stiffness[n] > 0.0) omega2 = std::max(omega2, stiffness[n] / model.nodes.mass[n]);
  return omega2 > 0.0 ? 2.0 / std::sqrt(omega2) : std::numeric_limits<double>::infinity();
}

static_assert(std::is_trivially_copyable_v<JointHistory>, "joint histories travel as bytes");

std::vector<std::uint8_t> joint_records(const std::vector<JointHistory>& history) {
  std::vector<std::uint8_t> records(history.size() * sizeof(JointHistory));
  if (!records.empty()) std::memcpy(records.data(), history.data(), records.size());
  return records;
}

std::vector<JointHistory> joint_histories(const std::vector<std::uint8_t>& records) {
  FDEM_VERIFY(records.size() % sizeof(JointHistory) == 0, "whole joint history records");
  std::vector<JointHistory> history(records.size() / sizeof(JointHistory));
  if (!history.empty()) std::memcpy(history.data(), records.data(), records.size());
  return history;
}

}  // namespace fdem
