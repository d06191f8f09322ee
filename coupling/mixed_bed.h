// Mixed material: spheres and polyhedral rocks by the mass fractions of thesis Paper A Table 1, placed
// without overlap, and saved states of a bed that a later run loads.
#pragma once

#include "coupling/coupled_world.h"
#include "dem/insertion.h"

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace dipper::coupling {

/// One class of rocks: the diameter of the sphere of equal volume and the fraction of the total mass.
struct RockClass {
    double size_m = 0.0;
    double mass_fraction = 0.0;
};

/// Spheres of one radius and rock classes, by mass fraction (summing to 1 within 1e-6).
struct MixedDistribution {
    dem::SizeClass spheres{0.1, 0.37};
    std::vector<RockClass> rocks{{0.30, 0.10}, {0.40, 0.09}, {0.60, 0.19}, {0.85, 0.25}};
    double elongation_min = 1.0, elongation_max = 2.0;  ///< rock shapes (rigid::RockShape)
    int rock_point_count = 20;

    /// Thesis Paper A Table 1: 200 mm spheres 37 % of the mass; rocks 300, 400, 600, 850 mm with 10, 9,
    /// 19, 25 %. Elongation up to 2 (the thesis' aspect ratios).
    static MixedDistribution thesis_table1() { return {}; }
    void validate(const std::string& where) const;
};

/// Materials of the mixed material in the two worlds.
struct MixedMaterials {
    dem::MaterialIndex sphere = 0;  ///< DEM material of the spheres
    dem::MaterialIndex rock = 0;    ///< DEM material the spheres see on rocks
    int rigid_rock = 0;             ///< Bullet material of the rocks
    double density_kg_per_m3 = 3700.0;  ///< particle density of spheres and rocks alike (thesis: one density)
};

struct MixedFillReport {
    std::size_t spheres = 0;
    std::vector<std::size_t> rocks_per_class;
    double sphere_mass_kg = 0.0, rock_mass_kg = 0.0;
};

/// Which bodies fill_mixed and load_state place: keep(centre, radius) for a sphere (its centre and
/// radius) and for a rock (its centroid and the radius of the sphere about it that holds its hull).
using KeepFilter = std::function<bool(const Vec3& centre_m, double radius_m)>;

/// Places `total_mass_kg` of mixed material at seeded random positions inside the box [lo, hi], none
/// overlapping another or what the worlds already hold of it: rocks first, largest first, each turned at
/// random; then spheres in the gaps. Class c gets round(f_c M / m_c) bodies, m_c the mass of one body of
/// the class. The sphere material's density in the DEM table must equal materials.density_kg_per_m3.
/// A place that `keep` refuses (a machine part's steel there) is tried again elsewhere.
/// Throws InputError if a body finds no place in `attempts` tries (the box is too small for the mass).
MixedFillReport fill_mixed(CoupledWorld& world, const Vec3& lo_m, const Vec3& hi_m, const MixedDistribution& distribution,
                           const MixedMaterials& materials, double total_mass_kg, std::uint64_t seed, int attempts = 20000,
                           const KeepFilter& keep = {});

/// Writes the spheres (position, velocity, spin, radius, material) and the rocks made with add_rock (shape,
/// density, materials, pose, velocities) to a versioned text file, full precision. Only spheres whose
/// centre and rocks whose centroid lie at or below `cut_above_m` are written (a pile cut at a height).
void save_state(const CoupledWorld& world, const std::string& path,
                double cut_above_m = std::numeric_limits<double>::infinity());

/// What load_state placed, and what the filter left out.
struct LoadedState {
    std::size_t spheres = 0, rocks = 0;
    std::size_t spheres_left_out = 0, rocks_left_out = 0;
};

/// Adds the spheres and rocks of a saved state to the worlds (materials matched by name), those the filter
/// keeps (all without one). Errors name the file, the line and what was expected.
LoadedState load_state(CoupledWorld& world, const std::string& path, const KeepFilter& keep = {});

}  // namespace dipper::coupling
