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

namespace {
void make_record(const WallContact& c, const ParticleStore& particles, ContactRecord& r)
{
    r.point_world = c.point;
    r.normal_world = c.normal;
    r.normal_force_N = c.forces.normal_force_N;
    r.tangential_force_N = c.forces.tangential_force_N;
    r.relative_displacement_m = c.relative_displacement_m;
    r.overlap_m = c.overlap_m;
    r.surface_id = c.wall;
    r.triangle_id = c.triangle;
    r.particle_index = static_cast<std::int32_t>(c.particle);
    r.particle_mass_kg = particles.mass_kg[c.particle];
    r.first_step = c.first_step;
}
}  // namespace

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
    for (std::size_t k = 0; k < contacts.size(); ++k) make_record(*contacts[k], particles_, records_[k]);
    records_stale_ = false;
    return records_;
}

void World::records_of(const WallFlags& walls, std::vector<ContactRecord>& out) const
{
    // as last_contact_records, those of the flagged walls alone; the convex bodies' pairs are read only if one is
    // flagged (a wear surface is a machine part, not a rock)
    const auto taken = [&](std::int32_t wall) {
        return static_cast<std::size_t>(wall) < walls.flag.size() && walls.flag[static_cast<std::size_t>(wall)];
    };
    out.clear();
    for (const WallContact& c : wall_contacts_)
        if (taken(c.wall)) make_record(c, particles_, out.emplace_back());
    if (!walls.any_convex) return;
    for (std::size_t k = 0; k < convex_.size(); ++k)
        if (convex_.touching(k) && taken(convex_.contact(k).wall)) make_record(convex_.contact(k), particles_, out.emplace_back());
}

World::WallFlags World::wall_flags(const std::vector<int>& walls, const char* caller) const
{
    WallFlags flags;
    flags.flag.assign(walls_.size(), 0);
    for (int w : walls) {
        if (w < 0 || static_cast<std::size_t>(w) >= walls_.size())
            throw InputError(concat(caller, ": no wall ", w, "; the world has walls 0 to ", static_cast<long>(walls_.size()) - 1));
        const WallRef& ref = walls_[static_cast<std::size_t>(w)];
        flags.flag[static_cast<std::size_t>(w)] = 1;
        flags.any_convex = flags.any_convex || (ref.is_mesh && meshes_[static_cast<std::size_t>(ref.index)].convex());
    }
    return flags;
}

std::vector<ContactRecord> World::contact_records(const std::vector<int>& walls) const
{
    std::vector<ContactRecord> out;
    records_of(wall_flags(walls, "contact_records"), out);
    return out;
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
