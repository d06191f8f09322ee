// The contact law of dipper's spheres: linear spring-dashpot normal force, tangential spring with
// history and Coulomb limit, viscous damping as a fraction of critical, and elastic-plastic rolling
// resistance. Thesis Paper A eqs. 3-8; Cundall & Strack (1979); rolling spring of Ai, Chen, Rotter &
// Ooi (2011, model type C without its viscous part). One pure function serves sphere-sphere and
// sphere-wall contacts: a wall is the limit r2 -> inf, m2 -> inf of a sphere.
#pragma once

#include "core/vec3.h"
#include "dem/material.h"

#include <algorithm>
#include <cmath>

namespace dipper::dem {

/// Geometry and motion of one contact, computed by the caller. "This" body is the particle the force
/// acts on; "other" is the second sphere or the wall.
struct ContactState {
    double overlap_m = 0.0;             ///< > 0 while touching
    Vec3 normal;                        ///< unit, from the other body towards this one
    Vec3 relative_velocity_m_per_s;     ///< contact-point velocity of this minus other
    Vec3 relative_angular_velocity_rad_per_s;  ///< omega_this - omega_other
    double effective_radius_m = 0.0;    ///< r1 r2 / (r1 + r2); r1 against a wall
    double effective_mass_kg = 0.0;     ///< m1 m2 / (m1 + m2); m1 against a wall
    double normal_stiffness_N_per_m = 0.0;  ///< Kn of eq. 4 (C_norm included)
};

/// Carried from step to step for each touching pair (and reset when the pair separates).
struct ContactHistory {
    Vec3 tangential_spring_m;   ///< accumulated tangential displacement, in the current tangent plane
    Vec3 rolling_torque_N_m;    ///< rolling-spring torque on "this", in the current tangent plane
};

/// What the law returns for "this" body; the other body receives the opposite force and rolling torque.
struct ContactForces {
    double normal_force_N = 0.0;        ///< >= 0: the normal force is never attractive
    Vec3 tangential_force_N;
    Vec3 rolling_torque_N_m;
};

/// Normal stiffness of eq. 4: Kn = k1 r1 k2 r2 / (k1 r1 + k2 r2) C_norm, k the bulk modulus of eq. 5.
inline double pair_normal_stiffness(double k1_Pa, double r1_m, double k2_Pa, double r2_m, double c_norm)
{
    const double a = k1_Pa * r1_m, b = k2_Pa * r2_m;
    return a * b / (a + b) * c_norm;
}
/// The wall limit of eq. 4 (r2 -> inf): Kn = k1 r1 C.
inline double wall_normal_stiffness(double k1_Pa, double r1_m, double c_norm) { return k1_Pa * r1_m * c_norm; }

/// Rolling-spring stiffness k_r = 2.25 Kn mu_roll^2 R*^2 (Ai et al. 2011, eq. 18), N m / rad.
inline double rolling_stiffness(double kn_N_per_m, double rolling_friction, double effective_radius_m)
{
    return 2.25 * kn_N_per_m * rolling_friction * rolling_friction * effective_radius_m * effective_radius_m;
}

/// The factor that keeps a history vector's length when it is projected into the tangent plane:
/// (1 - q)^(-1/2), q = along^2 / |v|^2, along = v . n. A contact normal turns by a tiny angle in one step,
/// so q is tiny and the series 1 + q/2 + 3q^2/8 is exact to round-off for q < 1e-5 (error 5q^3/16);
/// larger turns take the closed form, and a vector along the normal (q >= 1) leaves nothing.
/// Written with selects, not branches, so that a loop over contacts becomes SIMD code (see pair_batch.h).
inline double tangent_plane_scale(double along, double length_squared)
{
    const double q = along * along / (length_squared > 0.0 ? length_squared : 1.0);
    const double closed_form = 1.0 / std::sqrt(q < 1.0 ? 1.0 - q : 1.0);
    return q < 1e-5 ? 1.0 + q * (0.5 + 0.375 * q) : (q >= 1.0 ? 0.0 : closed_form);
}

/// Re-expresses a history vector in the current tangent plane (normal n), keeping its length, so that a
/// rotating contact carries its spring along instead of growing a normal component.
inline Vec3 rotate_into_tangent_plane(const Vec3& v, const Vec3& n)
{
    const double along = dot(v, n);
    return (v - n * along) * tangent_plane_scale(along, norm_squared(v));
}

/// a where `pick` holds, else b, component by component (a select, not a branch)
inline Vec3 select(bool pick, const Vec3& a, const Vec3& b)
{
    return {pick ? a.x : b.x, pick ? a.y : b.y, pick ? a.z : b.z};
}

/// Everything about a contact that does not change while the two bodies keep their sizes and materials:
/// stiffnesses and damping coefficients of eqs. 3-8. Computed once per distinct pair of particle kinds.
struct ContactConstants {
    double normal_stiffness_N_per_m = 0.0;        ///< Kn (eq. 4)
    double normal_damping_N_s_per_m = 0.0;        ///< c_n = D_n 2 sqrt(m* Kn) (eq. 6)
    double tangential_stiffness_N_per_m = 0.0;    ///< Kt = C_tan Kn
    double tangential_damping_N_s_per_m = 0.0;    ///< c_t = D_t 2 sqrt(m* Kt)
    double rolling_stiffness_N_m_per_rad = 0.0;   ///< k_r = 2.25 Kn mu_roll^2 R*^2
    double rolling_limit_m = 0.0;                 ///< mu_roll R*: |Mr| <= this x Fn (eq. 8)
    double friction = 0.0;                        ///< mu (eq. 7)
};

inline ContactConstants contact_constants(double kn_N_per_m, double effective_mass_kg, double effective_radius_m,
                                          const PairCoefficients& p)
{
    ContactConstants k;
    const double critical = 2.0 * std::sqrt(effective_mass_kg * kn_N_per_m);
    k.normal_stiffness_N_per_m = kn_N_per_m;
    k.normal_damping_N_s_per_m = p.normal_damping_ratio * critical;
    k.tangential_stiffness_N_per_m = p.tangential_stiffness_scale * kn_N_per_m;
    k.tangential_damping_N_s_per_m = p.tangential_damping_ratio * critical * std::sqrt(p.tangential_stiffness_scale);
    k.rolling_stiffness_N_m_per_rad = rolling_stiffness(kn_N_per_m, p.rolling_friction, effective_radius_m);
    k.rolling_limit_m = p.rolling_friction * effective_radius_m;
    k.friction = p.friction;
    return k;
}

/// The coefficients the pair law takes under a form of rolling resistance: all of them for the relative spring;
/// without rolling friction when it acts on each sphere's own spin instead (RollingResistance::own_spin,
/// applied where a sphere's torques are summed, World::gather_forces_and_kick).
inline PairCoefficients law_coefficients(const PairCoefficients& p, RollingResistance form)
{
    PairCoefficients c = p;
    if (form == RollingResistance::own_spin) c.rolling_friction = 0.0;
    return c;
}

/// The torque with which a sphere's contacts resist its own spin (RollingResistance::own_spin): of magnitude
/// `resistance` (the sum of mu_roll r Fn over its contacts, eq. 8) against the spin omega + step_per_inertia
/// other_torque that the step would otherwise leave it with, and no larger than what brings that spin to rest
/// (step_per_inertia = dt / I, the step's change of spin per unit torque): it never turns a spin round, so a
/// sphere at rest stays at rest instead of chattering.
inline Vec3 spin_resisting_torque(const Vec3& omega, const Vec3& other_torque, double resistance, double step_per_inertia)
{
    const Vec3 predicted = omega + other_torque * step_per_inertia;
    const double spin = norm(predicted);
    if (!(spin > 0.0) || !(resistance > 0.0)) return {};
    const double magnitude = std::min(resistance, spin / step_per_inertia);
    return predicted * (-magnitude / spin);
}

/// The linear spring-dashpot law with Coulomb friction and rolling resistance.
///
/// Normal (eq. 3, 6): Fn = max(0, Kn delta - c_n v_n), c_n = D_n 2 sqrt(m* Kn). The clamp at zero means
/// a separating pair loses contact force when the damping term cancels the spring, before the overlap
/// closes; restitution is then higher than exp(-pi D / sqrt(1 - D^2)) (see docs/contact_model.md).
/// Tangential: xi += v_t dt; Ft = -Kt xi - c_t v_t, Kt = C_tan Kn, c_t = D_t 2 sqrt(m* Kt); if
/// |Ft| > mu Fn the force is scaled to mu Fn and the spring reset to xi = -(Ft + c_t v_t) / Kt, so that
/// sliding dissipates and never stores more than the Coulomb limit (eq. 7).
/// Rolling (eq. 8): Mr -= k_r omega_roll dt, |Mr| <= mu_roll R* Fn; omega_roll is the relative angular
/// velocity in the tangent plane (twisting is not resisted).
/// Both springs are carried into the current tangent plane each step (rotate_into_tangent_plane).
/// Written without branches (both sides of each limit are computed, then selected), so that the loop over
/// a batch of contacts in pair_batch.cpp runs as SIMD code and gives the same bits as this scalar form.
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline ContactForces linear_spring_dashpot(double overlap_m, const Vec3& n, const Vec3& relative_velocity_m_per_s,
                                           const Vec3& relative_angular_velocity_rad_per_s, const ContactConstants& k,
                                           ContactHistory& h, double dt_s)
{
    ContactForces out;

    // normal: spring and dashpot, never attractive
    const double vn = dot(relative_velocity_m_per_s, n);
    const double fn = k.normal_stiffness_N_per_m * overlap_m - k.normal_damping_N_s_per_m * vn;
    out.normal_force_N = fn > 0.0 ? fn : 0.0;

    // tangential: history spring in the current tangent plane, dashpot, Coulomb limit
    const Vec3 vt = relative_velocity_m_per_s - n * vn;
    const double kt = k.tangential_stiffness_N_per_m, ct = k.tangential_damping_N_s_per_m;
    const Vec3 spring = rotate_into_tangent_plane(h.tangential_spring_m, n) + vt * dt_s;
    const Vec3 ft = spring * (-kt) - vt * ct;
    const double ft2 = norm_squared(ft);
    const double limit = k.friction * out.normal_force_N;
    const bool sliding = ft2 > limit * limit;  // then ft2 > 0
    const Vec3 at_limit = ft * (limit / std::sqrt(ft2 > 0.0 ? ft2 : 1.0));
    out.tangential_force_N = select(sliding, at_limit, ft);
    h.tangential_spring_m = select(sliding, (at_limit + vt * ct) * (-1.0 / kt), spring);

    // rolling: elastic-plastic spring on the relative rolling rotation (k_r = 0 and mu_roll R* = 0 when
    // the pair has no rolling resistance: the torque stays zero)
    const Vec3& w = relative_angular_velocity_rad_per_s;
    const Vec3 w_roll = w - n * dot(w, n);
    const Vec3 mr = rotate_into_tangent_plane(h.rolling_torque_N_m, n) - w_roll * (k.rolling_stiffness_N_m_per_rad * dt_s);
    const double mr2 = norm_squared(mr);
    const double mr_limit = k.rolling_limit_m * out.normal_force_N;
    const Vec3 rolling = select(mr2 > mr_limit * mr_limit, mr * (mr_limit / std::sqrt(mr2 > 0.0 ? mr2 : 1.0)), mr);
    h.rolling_torque_N_m = rolling;
    out.rolling_torque_N_m = rolling;
    return out;
}

/// The same law from a complete ContactState (constants computed on the spot).
inline ContactForces linear_spring_dashpot(const ContactState& c, const PairCoefficients& p, ContactHistory& h, double dt_s)
{
    const ContactConstants k = contact_constants(c.normal_stiffness_N_per_m, c.effective_mass_kg, c.effective_radius_m, p);
    return linear_spring_dashpot(c.overlap_m, c.normal, c.relative_velocity_m_per_s, c.relative_angular_velocity_rad_per_s,
                                 k, h, dt_s);
}

}  // namespace dipper::dem
