// What to tell a user whose joint laws cannot work: the condition that failed, and the penalty,
// fracture energy or element size that would make every law of the block work, with the scene
// file, the key and the valid range.
#pragma once

#include <string>
#include <vector>

#include "core/model.hpp"
#include "fracture/cohesive_law.hpp"

namespace fdem {

// The parameters of the CohesiveLaw of a resolved law.
CohesiveParameters cohesive_parameters(const JointLawSpec& spec);

// The message for law `failed` of `laws`, which CohesiveLaw refused with `what`.  When the
// penalty is too soft for the block's energies at its element sizes and strengths (pre-peak
// energy above G_I, or shear snap-back), it names the block's file and key, the condition, and
// the penalty (with its valid range), the energies and the element size that would work for
// every law of the block; otherwise it is `what` with the law's origin.
std::string joint_law_message(const std::vector<JointLawSpec>& laws, std::size_t failed,
                              const SofteningCurve& curve, const std::string& what);

}  // namespace fdem
