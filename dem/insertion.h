// Putting particles into a world: random non-overlapping fills of a box or of a mesh-bounded region by
// a size distribution given as mass fractions (thesis Paper A, Table 1 style), lattice fills, and
// pouring from a region over time.
#pragma once

#include "dem/world.h"
#include "meshes/triangle_mesh.h"

#include <cstdint>
#include <random>
#include <vector>

namespace dipper::dem {

/// One size class: sphere radius and the fraction of the total mass it carries.
struct SizeClass {
    double radius_m = 0.0;
    double mass_fraction = 0.0;
};

/// Sizes by mass fraction; the fractions must sum to 1 (within 1e-6).
struct SizeDistribution {
    std::vector<SizeClass> classes;
    void validate(const std::string& where) const;
    double max_radius_m() const;
};

/// Radii of the particles that make up `total_mass_kg` of a distribution at a density, largest first:
/// class c gets round(fraction_c * total / m_c) particles. More than kMaxFillParticles is an InputError
/// that gives the count (a typo in a mass or a radius would otherwise exhaust the memory).
std::vector<double> radii_for_mass(const SizeDistribution& distribution, double density_kg_per_m3, double total_mass_kg);
constexpr double kMaxFillParticles = 1e8;
/// How many particles radii_for_mass makes, before rounding (any size: nothing is allocated).
double particles_for_mass(const SizeDistribution& distribution, double density_kg_per_m3, double total_mass_kg);

/// Throws InputError naming `where` when `total_mass_kg` of solid at the density fills more than 74 % of the
/// box [lo, hi] (the densest packing of equal spheres): such a fill cannot be placed, and finding that out by
/// placing particles until one finds no room could take hours.
void require_mass_fits(double total_mass_kg, double density_kg_per_m3, const Vec3& lo, const Vec3& hi, const std::string& where);

/// Where particles may be placed: a whole sphere must fit.
class Region {
public:
    virtual ~Region() = default;
    virtual bool holds(const Vec3& centre_m, double radius_m) const = 0;
    virtual Vec3 bounds_min_m() const = 0;
    virtual Vec3 bounds_max_m() const = 0;
};

/// Axis-aligned box.
class BoxRegion final : public Region {
public:
    BoxRegion(const Vec3& min_corner_m, const Vec3& max_corner_m);
    bool holds(const Vec3& c, double r) const override;
    Vec3 bounds_min_m() const override { return lo_; }
    Vec3 bounds_max_m() const override { return hi_; }

private:
    Vec3 lo_, hi_;
};

/// Inside a closed triangle mesh (in world coordinates), at least one radius from its surface.
class MeshRegion final : public Region {
public:
    explicit MeshRegion(const meshes::TriangleMesh& closed_mesh) : mesh_(closed_mesh) {}
    bool holds(const Vec3& c, double r) const override { return mesh_.contains(c) && mesh_.distance_m(c) >= r; }
    Vec3 bounds_min_m() const override { return mesh_.bounds_min_m(); }
    Vec3 bounds_max_m() const override { return mesh_.bounds_max_m(); }

private:
    const meshes::TriangleMesh& mesh_;
};

/// What a fill did.
struct FillReport {
    std::size_t requested = 0, placed = 0;
    double placed_mass_kg = 0.0;
};

/// Places the particles of `total_mass_kg` at seeded random positions in the region, without overlapping
/// each other or the particles already in the world; largest first. Throws InputError if a particle
/// finds no free place in `attempts_per_particle` tries (the region is too small for that mass).
FillReport fill_random(World& world, const Region& region, const SizeDistribution& distribution, MaterialIndex material,
                       double total_mass_kg, std::uint64_t seed, int attempts_per_particle = 5000);

/// Places equal spheres on a simple cubic lattice of the given spacing (>= 2 r) inside [lo, hi], each
/// displaced by a seeded random offset of at most `jitter_m` per axis (kept non-overlapping).
FillReport fill_lattice(World& world, const Vec3& lo_m, const Vec3& hi_m, double radius_m, double spacing_m,
                        MaterialIndex material, double jitter_m = 0.0, std::uint64_t seed = 1);

/// Pours particles from a box region at a mass flow rate with an initial velocity until a total mass has
/// entered. Call update() as the run proceeds; particles that find no free place wait for the next call.
class Pourer {
public:
    Pourer(BoxRegion region, SizeDistribution distribution, MaterialIndex material, double mass_flow_kg_per_s,
           double total_mass_kg, const Vec3& initial_velocity_m_per_s, std::uint64_t seed, double start_s = 0.0);
    /// Inserts what is due by the world's current time; returns how many particles were added. Nothing
    /// enters before `start_s`; the flow counts from the first call at or after it.
    std::size_t update(World& world);
    bool done() const { return start_time_s_ >= 0.0 && next_ >= radii_.size(); }
    double poured_mass_kg() const { return poured_mass_kg_; }
    /// Progress and random state, for checkpoints (the region and sizes come from the same input again).
    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

private:
    template <class IO, class Self>
    static void state_fields(IO& io, Self& s, std::string& random);
    BoxRegion region_;
    MaterialIndex material_;
    double mass_flow_kg_per_s_;
    Vec3 initial_velocity_;
    SizeDistribution distribution_;
    double total_mass_kg_ = 0.0;
    std::vector<double> radii_;
    std::size_t next_ = 0;
    double not_before_s_ = 0.0;
    double poured_mass_kg_ = 0.0, start_time_s_ = -1.0;
    std::mt19937_64 random_;
};

}  // namespace dipper::dem
