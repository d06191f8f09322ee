// All sphere state, one contiguous array per field (structure of arrays).
#pragma once

#include "core/vec3.h"
#include "core/state_io.h"
#include "dem/material.h"

#include <cstdint>
#include <string>
#include <vector>

namespace dipper::dem {

/// What a new particle is made of and where it starts.
struct ParticleSpawn {
    Vec3 position_m;
    Vec3 velocity_m_per_s;
    Vec3 angular_velocity_rad_per_s;
    double radius_m = 0.0;
    MaterialIndex material = 0;
};

/// The fastest a new particle's centre or rim may move, m/s: 100 times a blast's fragments (about 100 m/s).
constexpr double kMaxSpeed_m_per_s = 1e4;

/// Sphere state. Arrays are indexed by a dense index that the neighbour search may permute (particles
/// are sorted by cell for memory locality); `id` is the particle's stable number for output and for
/// code outside the module.
class ParticleStore {
public:
    std::size_t size() const { return position_m.size(); }
    void reserve(std::size_t n);

    /// Appends a validated particle (finite, at most kMaxSpeed_m_per_s); mass and inertia come from the
    /// material's density. Returns the stable id. `where` names the source for error messages.
    std::uint32_t add(const ParticleSpawn& spawn, const MaterialTable& materials, const std::string& where);

    /// Reorders every array so that new index k holds what old index order[k] held.
    void permute(const std::vector<std::uint32_t>& order);

    /// Every array and the next id, for checkpoints; read_state replaces the whole store.
    void write_state(StateWriter& out) const;
    void read_state(StateReader& in, const MaterialTable& materials);

    // hot: read or written every step
    std::vector<Vec3> position_m, velocity_m_per_s, angular_velocity_rad_per_s;
    std::vector<Vec3> force_N, torque_N_m;
    // per-particle constants, cached inverses included
    std::vector<double> radius_m, mass_kg, inverse_mass_per_kg, inverse_inertia_per_kg_m2;
    std::vector<MaterialIndex> material;
    std::vector<std::uint32_t> id;
    /// 1 while the particle is frozen (World::set_frozen): held where it is, at rest, out of the integration and of
    /// the contacts with other frozen bodies.
    std::vector<std::uint8_t> frozen;

private:
    /// The checkpoint's fields, listed once for writing and reading (core/state_io.h).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& s);
    std::uint32_t next_id_ = 0;
};

/// Mass of a solid sphere, kg.
double sphere_mass_kg(double radius_m, double density_kg_per_m3);

}  // namespace dipper::dem
