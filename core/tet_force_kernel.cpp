#include "core/tet_force_kernel.hpp"

namespace fdem {

namespace {

template <template <class> class Law>
inline void tet_lanes(TetLaneBatch& b) {
  tet_corner_forces(b.x, b.v, b.dm_inv, b.volume0, Law<Lanes>{b.lambda, b.mu}, b.viscosity,
                    b.any_viscous, b.out);
}

}  // namespace

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
// flatten: the kernel is inlined into each clone, so the AVX2 clone is AVX2 throughout.
#define FDEM_LANE_CLONES __attribute__((target_clones("avx2", "default"), flatten))
#else
#define FDEM_LANE_CLONES
#endif

FDEM_LANE_CLONES void neo_hookean_tet_lanes(TetLaneBatch& batch) {
  tet_lanes<NeoHookeanLaw>(batch);
}

FDEM_LANE_CLONES void st_venant_kirchhoff_tet_lanes(TetLaneBatch& batch) {
  tet_lanes<StVenantKirchhoffLaw>(batch);
}

}  // namespace fdem
