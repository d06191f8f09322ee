// dem::World: what the probes read of the spheres (contacts, energies, momenta, mass).
#include "dem/world.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace dipper::dem {

std::size_t World::pair_contact_count() const { return pairs_.contact_count(); }

std::vector<PairContactView> World::pair_contacts() const { return pairs_.contacts(particles_); }

double World::kinetic_energy_J() const
{
    double e = 0.0;
    for (std::size_t i = 0; i < particles_.size(); ++i)
        e += 0.5 * particles_.mass_kg[i] * norm_squared(particles_.velocity_m_per_s[i]) +
             0.5 / particles_.inverse_inertia_per_kg_m2[i] * norm_squared(particles_.angular_velocity_rad_per_s[i]);
    return e;
}

double World::gravitational_potential_energy_J() const
{
    double e = 0.0;
    for (std::size_t i = 0; i < particles_.size(); ++i)
        e -= particles_.mass_kg[i] * dot(settings_.gravity_m_per_s2, particles_.position_m[i]);
    return e;
}

Vec3 World::linear_momentum_kg_m_per_s() const
{
    Vec3 p{};
    for (std::size_t i = 0; i < particles_.size(); ++i) p += particles_.velocity_m_per_s[i] * particles_.mass_kg[i];
    return p;
}

Vec3 World::angular_momentum_kg_m2_per_s() const
{
    Vec3 l{};
    for (std::size_t i = 0; i < particles_.size(); ++i)
        l += cross(particles_.position_m[i], particles_.velocity_m_per_s[i] * particles_.mass_kg[i]) +
             particles_.angular_velocity_rad_per_s[i] * (1.0 / particles_.inverse_inertia_per_kg_m2[i]);
    return l;
}

double World::total_mass_kg() const
{
    double m = 0.0;
    for (double mi : particles_.mass_kg) m += mi;
    return m;
}

}  // namespace dipper::dem
