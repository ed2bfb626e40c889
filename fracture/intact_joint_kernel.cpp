#include "fracture/intact_joint_kernel.hpp"

namespace fdem {

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
// flatten: the kernel is inlined into each clone, so the AVX2 clone is AVX2 throughout.
__attribute__((target_clones("avx2", "default"), flatten))
#endif
void intact_joint_steps_for_this_cpu(IntactJointBatch& batch) {
  intact_joint_steps(batch);
}

}  // namespace fdem
