// Small builders shared by the DEM tests.
#pragma once

#include "dem/world.h"

#include <cmath>
#include <cstring>
#include <vector>

namespace dipper::test {

/// A material table with one particle material "p" and one surface "wall", and their pair and the
/// particle-particle pair set to `pair`.
inline dem::MaterialTable two_material_table(const dem::PairCoefficients& pair, double density = 2500.0,
                                             double youngs_modulus_Pa = 1e9, double poisson_ratio = 0.25)
{
    dem::MaterialTable t;
    t.add({"p", density, youngs_modulus_Pa, poisson_ratio, false});
    t.add({"wall", 0.0, 0.0, 0.0, true});
    t.set_pair("p", "p", pair);
    t.set_pair("p", "wall", pair);
    return t;
}

inline dem::PairCoefficients coefficients(double friction, double rolling, double damping_n, double damping_t,
                                          double c_norm = 1.0, double c_tan = 0.27)
{
    return {c_norm, c_tan, friction, rolling, damping_n, damping_t};
}

/// Exact response of the clamped linear spring-dashpot to an impact at speed v0 (unit v0 here):
/// m x'' + c x' + K x = 0 while K x + c x' > 0, then force-free until the overlap closes.
/// With theta = omega_d t, the force K x + c x' = m v0 omega0 e^{-zeta omega0 t} [omega0 (1 - 2 zeta^2)
/// sin(theta) / omega_d + 2 zeta cos(theta)] first vanishes at theta* = pi - atan2(2 zeta omega_d,
/// omega0 (1 - 2 zeta^2)). Restitution is -x'(t*) / v0; the contact lasts t* + x(t*) / |x'(t*)|.
struct ClampedImpact {
    double restitution, duration_s;
};
inline ClampedImpact clamped_impact(double zeta, double omega0)
{
    const double omega_d = omega0 * std::sqrt(1.0 - zeta * zeta);
    const double theta = M_PI - std::atan2(2.0 * zeta * omega_d, omega0 * (1.0 - 2.0 * zeta * zeta));
    const double t = theta / omega_d;
    const double decay = std::exp(-zeta * omega0 * t);
    const double x = decay * std::sin(theta) / omega_d;                                    // per unit v0
    const double v = decay * (std::cos(theta) - zeta * omega0 / omega_d * std::sin(theta));  // < 0
    return {-v, t + x / -v};
}

/// Bitwise hash of positions and velocities, in id order.
inline std::uint64_t state_hash(const dem::World& w)
{
    const auto& p = w.particles();
    std::vector<std::size_t> by_id(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) by_id[p.id[i]] = i;
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&](double d) {
        std::uint64_t b;
        std::memcpy(&b, &d, sizeof b);
        h = (h ^ b) * 1099511628211ull;
    };
    for (std::size_t k : by_id) {
        const auto& x = p.position_m[k];
        const auto& v = p.velocity_m_per_s[k];
        mix(x.x); mix(x.y); mix(x.z); mix(v.x); mix(v.y); mix(v.z);
    }
    return h;
}

/// Index of the particle with a stable id.
inline std::size_t index_of_id(const dem::World& w, std::uint32_t id)
{
    for (std::size_t i = 0; i < w.particles().size(); ++i)
        if (w.particles().id[i] == id) return i;
    return static_cast<std::size_t>(-1);
}

}  // namespace dipper::test
