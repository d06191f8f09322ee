// Compiled with -fno-trapping-math and -fno-math-errno (see CMakeLists.txt) so that the loop below, with
// its selects, square roots and divisions, vectorises. On x86-64 it is built twice, for AVX2 and for the
// baseline, and the loader picks the one the processor runs; no FMA, so both give the same bits.
#include "dem/pair_batch.h"

namespace dipper::dem {

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("avx2", "default")))
#endif
double evaluate_pair_batch(PairBatch& b, double dt_s)
{
    double max_ratio = 0.0;
#pragma omp simd reduction(max : max_ratio)
    for (int c = 0; c < b.count; ++c) {
        const Vec3 d{b.dx[c], b.dy[c], b.dz[c]};
        const double dist = std::sqrt(b.distance2[c]);
        const bool apart = dist > 0.0;
        const Vec3 n = select(apart, d * (1.0 / (apart ? dist : 1.0)), Vec3{0.0, 0.0, 1.0});
        const double ri = b.ri[c], rj = b.rj[c];
        const double overlap = (ri + rj) - dist;
        const double ratio = overlap / (ri < rj ? ri : rj);
        max_ratio = ratio > max_ratio ? ratio : max_ratio;

        const double deflection_i = b.share_i[c] * overlap;
        const double a_i = ri - deflection_i, a_j = rj - (overlap - deflection_i);
        const Vec3 wi{b.wix[c], b.wiy[c], b.wiz[c]}, wj{b.wjx[c], b.wjy[c], b.wjz[c]};
        const Vec3 velocity = Vec3{b.dvx[c], b.dvy[c], b.dvz[c]} - cross(wi * a_i + wj * a_j, n);

        ContactConstants k;
        k.normal_stiffness_N_per_m = b.kn[c];
        k.normal_damping_N_s_per_m = b.cn[c];
        k.tangential_stiffness_N_per_m = b.kt[c];
        k.tangential_damping_N_s_per_m = b.ct[c];
        k.rolling_stiffness_N_m_per_rad = b.kr[c];
        k.rolling_limit_m = b.roll_limit[c];
        k.friction = b.friction[c];
        ContactHistory h{{b.sx[c], b.sy[c], b.sz[c]}, {b.mx[c], b.my[c], b.mz[c]}};
        const ContactForces f = linear_spring_dashpot(overlap, n, velocity, wi - wj, k, h, dt_s);
        b.sx[c] = h.tangential_spring_m.x; b.sy[c] = h.tangential_spring_m.y; b.sz[c] = h.tangential_spring_m.z;
        b.mx[c] = h.rolling_torque_N_m.x; b.my[c] = h.rolling_torque_N_m.y; b.mz[c] = h.rolling_torque_N_m.z;

        const Vec3 force = n * f.normal_force_N + f.tangential_force_N;
        const Vec3 n_x_ft = cross(n, f.tangential_force_N);  // only Ft has a moment about the centres
        const Vec3 ti = f.rolling_torque_N_m - n_x_ft * a_i;
        const Vec3 tj = -(f.rolling_torque_N_m + n_x_ft * a_j);
        b.fx[c] = force.x; b.fy[c] = force.y; b.fz[c] = force.z;
        b.fn[c] = f.normal_force_N;
        b.tix[c] = ti.x; b.tiy[c] = ti.y; b.tiz[c] = ti.z;
        b.tjx[c] = tj.x; b.tjy[c] = tj.y; b.tjz[c] = tj.z;
    }
    return max_ratio;
}

}  // namespace dipper::dem
