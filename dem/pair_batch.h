// Sphere-sphere contacts evaluated in batches: the pair loop gathers the touching pairs' geometry,
// velocities, constants and history into structure-of-arrays form, one loop runs the contact law over
// them as SIMD code, and the pair loop scatters the forces. The results are bit for bit those of the
// scalar law (linear_spring_dashpot) with the same geometry, whichever instruction set runs.
#pragma once

#include "dem/contact_law.h"

#include <cstdint>

namespace dipper::dem {

/// Up to kCapacity touching sphere pairs (i, j), this body = i. Inputs are filled by the caller; the
/// history is read and written in place; outputs are the force on i and the torques on i and j.
struct PairBatch {
    static constexpr int kCapacity = 64;
    int count = 0;
    // which pair and particles each lane belongs to (not read by the evaluation)
    std::uint32_t pair[kCapacity], i[kCapacity], j[kCapacity];
    // geometry: d = x_i - x_j, |d|^2, radii, the share of the overlap taken by i's deflection
    alignas(64) double dx[kCapacity], dy[kCapacity], dz[kCapacity], distance2[kCapacity];
    alignas(64) double ri[kCapacity], rj[kCapacity], share_i[kCapacity];
    // motion: v_i - v_j and both spins
    alignas(64) double dvx[kCapacity], dvy[kCapacity], dvz[kCapacity];
    alignas(64) double wix[kCapacity], wiy[kCapacity], wiz[kCapacity], wjx[kCapacity], wjy[kCapacity], wjz[kCapacity];
    // the pair's constants (ContactConstants, one array per field)
    alignas(64) double kn[kCapacity], cn[kCapacity], kt[kCapacity], ct[kCapacity], kr[kCapacity], roll_limit[kCapacity],
        friction[kCapacity];
    // history: tangential spring and rolling torque
    alignas(64) double sx[kCapacity], sy[kCapacity], sz[kCapacity], mx[kCapacity], my[kCapacity], mz[kCapacity];
    // outputs: force on i (j gets the opposite), its normal part, torques on i and on j
    alignas(64) double fx[kCapacity], fy[kCapacity], fz[kCapacity], fn[kCapacity];
    alignas(64) double tix[kCapacity], tiy[kCapacity], tiz[kCapacity], tjx[kCapacity], tjy[kCapacity], tjz[kCapacity];

    /// Appends the constants of one lane.
    void set_constants(int lane, const ContactConstants& k)
    {
        kn[lane] = k.normal_stiffness_N_per_m;
        cn[lane] = k.normal_damping_N_s_per_m;
        kt[lane] = k.tangential_stiffness_N_per_m;
        ct[lane] = k.tangential_damping_N_s_per_m;
        kr[lane] = k.rolling_stiffness_N_m_per_rad;
        roll_limit[lane] = k.rolling_limit_m;
        friction[lane] = k.friction;
    }
};

/// Evaluates lanes [0, b.count): normal n = d / |d| ((0, 0, 1) for coincident centres), overlap
/// r_i + r_j - |d|, lever arms a_i = r_i - share_i overlap and a_j = r_j - (overlap - share_i overlap)
/// along -n and +n, contact-point velocity (v_i - v_j) - (a_i w_i + a_j w_j) x n, the law of
/// linear_spring_dashpot, force F = n Fn + Ft on i, torques Mr - a_i n x Ft on i and -(Mr + a_j n x Ft) on j.
/// Returns the largest overlap / min(r_i, r_j) of the batch (0 for none).
double evaluate_pair_batch(PairBatch& b, double dt_s);

}  // namespace dipper::dem
