// Bulk density of the mixed material (thesis Paper A 3.1): a box of known volume filled to the top and
// weighed, and the particle density scaled so that the bulk density hits a target.
#pragma once

#include "coupling/mixed_bed.h"

#include <cstdint>

namespace dipper::coupling {

/// The weighing box and how it is filled. Defaults: the thesis' 28 m3 (4 m x 3.5 m x 2 m), Table 1 material,
/// filled loosely with 1.25 times the box's target mass in a taller box, settled, struck off at the top.
struct BulkDensityBox {
    double length_m = 4.0, width_m = 3.5, height_m = 2.0;
    double overfill = 1.25;         ///< solid poured = overfill x volume x target bulk / initial particle density
    double settle_s = 2.5;          ///< time to settle after the loose fill
    int substeps = kDefaultSubsteps;  ///< coupling sub-steps (docs/coupling.md)
    int threads = 1;
    std::uint64_t seed = 1;
    MixedDistribution distribution = MixedDistribution::thesis_table1();

    double volume_m3() const { return length_m * width_m * height_m; }
    void validate(const std::string& where) const;
};

struct BulkDensityResult {
    double particle_density_kg_per_m3 = 0.0;
    double mass_in_box_kg = 0.0;   ///< the parts of spheres and rocks below the box's top (struck off exactly)
    double bulk_density_kg_per_m3 = 0.0;
    std::size_t spheres_in_box = 0, rocks_in_box = 0;
    double translational_energy_J = 0.0;  ///< what still moves at the end of settling (spheres and rocks)
};

/// Fills the box with `solid_volume_m3` of material of the given particle density (Aitik ore, Table 2),
/// settles it and weighs what lies below the top: spheres and rocks cut by the top plane count with the
/// part of their volume below it (spherical caps and clipped hulls, exact).
BulkDensityResult measure_bulk_density(const BulkDensityBox& box, double particle_density_kg_per_m3, double solid_volume_m3);

struct BulkDensityCalibration {
    BulkDensityResult first;      ///< the weighing at the initial particle density
    BulkDensityResult confirmed;  ///< the last weighing, at scaled_particle_density_kg_per_m3
    double scaled_particle_density_kg_per_m3 = 0.0;
    int scalings = 0;             ///< weighings after the first
    bool converged = false;       ///< the confirmed bulk density lies within the tolerance of the target
};

/// The thesis' calibration: weigh with `initial` particle density, scale it by target / measured bulk
/// density, and weigh again to confirm. All weighings pour the same solid volume with the same seed, so
/// the bodies are the same and only their density differs; the heavier or lighter bed settles a little
/// differently, so when the confirmation misses the target by more than `tolerance` (a fraction), the
/// density is scaled again by target / confirmed, up to `max_scalings` weighings after the first.
BulkDensityCalibration calibrate_bulk_density(const BulkDensityBox& box, double initial_particle_density_kg_per_m3,
                                              double target_bulk_density_kg_per_m3, double tolerance = 0.02,
                                              int max_scalings = 3);

}  // namespace dipper::coupling
