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

const std::vector<ContactRecord>& World::last_contact_records() const
{
    if (!records_stale_) return records_;
    // the contacts of planes and open meshes in particle order, then those of convex bodies, in particle order
    std::vector<const WallContact*> contacts(wall_contacts_.size());
    for (std::size_t k = 0; k < wall_contacts_.size(); ++k) contacts[k] = &wall_contacts_[k];
    for (std::size_t k = 0; k < convex_.size(); ++k)
        if (convex_.touching(k)) contacts.push_back(&convex_.contact(k));
    records_.resize(contacts.size());
#pragma omp parallel for schedule(static) num_threads(threads_)
    for (std::size_t k = 0; k < contacts.size(); ++k) {
        const WallContact& c = *contacts[k];
        ContactRecord& r = records_[k];
        r.point_world = c.point;
        r.normal_world = c.normal;
        r.normal_force_N = c.forces.normal_force_N;
        r.tangential_force_N = c.forces.tangential_force_N;
        r.relative_displacement_m = c.relative_displacement_m;
        r.overlap_m = c.overlap_m;
        r.surface_id = c.wall;
        r.triangle_id = c.triangle;
        r.particle_index = static_cast<std::int32_t>(c.particle);
        r.particle_mass_kg = particles_.mass_kg[c.particle];
        r.first_step = c.first_step;
    }
    records_stale_ = false;
    return records_;
}

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
