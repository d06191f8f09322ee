// Bulk density calibration (thesis Paper A 3.1): fill the 28 m3 box with the mixed material of Table 1,
// settle, weigh what lies inside, scale the particle density by target / measured, and weigh again (and
// scale again, up to three times, while the confirmation misses the target by more than 2 %).
// Usage: dipper_bulk_density [--target 1903] [--density 3700] [--settle-s 2.5] [--threads 1] [--scale 1]
//   --scale shrinks the box's sides (0.5: a 7 m3 box with the same height ratio, for a quick look).
#include "coupling/bulk_density.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace dipper;

int main(int argc, char** argv)
{
    double target = 1903.0, density = 3700.0, scale = 1.0;
    coupling::BulkDensityBox box;
    for (int k = 1; k + 1 < argc; k += 2) {
        const std::string key = argv[k];
        if (key == "--target") target = std::atof(argv[k + 1]);
        else if (key == "--density") density = std::atof(argv[k + 1]);
        else if (key == "--settle-s") box.settle_s = std::atof(argv[k + 1]);
        else if (key == "--threads") box.threads = std::atoi(argv[k + 1]);
        else if (key == "--scale") scale = std::atof(argv[k + 1]);
        else {
            std::fprintf(stderr, "dipper_bulk_density: unknown option '%s'; options: --target --density --settle-s --threads --scale\n", argv[k]);
            return 2;
        }
    }
    box.length_m *= scale;
    box.width_m *= scale;
    const auto t0 = std::chrono::steady_clock::now();
    try {
        const coupling::BulkDensityCalibration c = coupling::calibrate_bulk_density(box, density, target);
        auto show = [&](const char* what, const coupling::BulkDensityResult& r) {
            std::printf("%s: particle density %.1f kg/m3 -> %.0f kg in the %.1f m3 box (%zu spheres, %zu rocks): bulk density "
                        "%.1f kg/m3 (%+.2f %% of the target); still moving %.3g J\n",
                        what, r.particle_density_kg_per_m3, r.mass_in_box_kg, box.volume_m3(), r.spheres_in_box, r.rocks_in_box,
                        r.bulk_density_kg_per_m3, 100.0 * (r.bulk_density_kg_per_m3 / target - 1.0), r.translational_energy_J);
        };
        show("first weighing", c.first);
        std::printf("scaled particle density: %.1f kg/m3 after %d scaling(s) by target / measured\n",
                    c.scaled_particle_density_kg_per_m3, c.scalings);
        show("confirmation  ", c.confirmed);
        if (!c.converged) std::printf("the confirmation is not within 2 %% of the target after %d scalings\n", c.scalings);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "dipper_bulk_density: %s\n", e.what());
        return 1;
    }
    std::printf("wall time %.0f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    return 0;
}
