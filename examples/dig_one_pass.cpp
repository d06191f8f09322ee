// dipper_dig_one_pass: one pass of the rope shovel through a bed of spheres and rocks, built and run through
// the library alone (no scenario file). The bed is blasted Aitik ore at a coarse size: 600 mm spheres with a
// third of the mass in rocks of 850 mm, 500 t between two side walls in front of the dipper. It settles for
// 2 s while the shovel holds its first pose; then the thesis' loading cycle digs it, swings 90 degrees and
// opens the door. The last line is the pass: the mass the dipper carried and the mean dig force (thesis eq. 11).
//
// usage: dipper_dig_one_pass [--threads N]
#include <dipper/dipper.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

using namespace dipper;

int main(int argc, char** argv)
{
    int threads = 2;
    for (int a = 1; a < argc; ++a) {
        const std::string arg = argv[a];
        if (arg == "--threads" && a + 1 < argc) {
            threads = std::atoi(argv[++a]);
        } else {
            std::fprintf(stderr, "usage: dipper_dig_one_pass [--threads N]\n");
            return 2;
        }
    }
    if (threads < 1) {
        std::fprintf(stderr, "dipper_dig_one_pass: --threads %d; expected 1 or more\n", threads);
        return 2;
    }
    try {
        // 1. the DEM world with its walls: the ground, a back wall, and two side walls 6.2 m apart that end
        // 7 m up, so that the dipper swings out over them (thesis Table 2 coefficients)
        dem::WorldSettings settings;
        settings.threads = threads;
        auto dem = std::make_unique<dem::World>(dem::MaterialTable::aitik_copper_ore(), settings);
        const dem::MaterialTable& m = dem->materials();
        dem->add_plane({0, 0, 0}, {0, 0, 1}, m.index_of("ground"), "ground");
        dem->add_plane({24.5, 0, 0}, {-1, 0, 0}, m.index_of("steel"), "back");
        dem->add_mesh(meshes::make_box_mesh({12.0, -3.3, 0.0}, {24.5, -3.1, 7.0}), m.index_of("steel"), "side_a");
        dem->add_mesh(meshes::make_box_mesh({12.0, 3.1, 0.0}, {24.5, 3.3, 7.0}), m.index_of("steel"), "side_b");

        // 2. the co-simulation around it: Bullet's walls for the rocks, then the rope shovel on the loading cycle,
        // its first dig 2 s in
        coupling::CoSimulationSettings cs;
        cs.rocks = true;
        coupling::CoSimulation sim(std::move(dem), cs);
        coupling::ShovelSettings shovel;
        shovel.dipper.element_size_m = 0.3;  // coarse surface elements: the spheres are 600 mm
        shovel.start_s = 2.0;
        sim.add_shovel(shovel);

        // 3. the bed, clear of the dipper where it stands, and the dipper's wear (force-work law, thesis eq. 2.8)
        coupling::MixedDistribution bed;
        bed.spheres = {0.3, 0.65};
        bed.rocks = {{0.85, 0.35}};
        const coupling::MixedMaterials materials{m.index_of("ore"), m.index_of("rock"), sim.rigid().material_index("rock"),
                                                 m.material(m.index_of("ore")).density_kg_per_m3};
        const coupling::MixedFillReport filled =
            coupling::fill_mixed(sim.coupled(), {13.0, -3.0, 0.0}, {24.5, 3.0, 11.0}, bed, materials, 500000.0, 7, 20000,
                                 [&sim](const Vec3& c, double r) { return sim.clear_of_machine(c, r); });
        sim.add_wear("dipper", wear::WearLaw::from_name("force_work", 1e-12, "dig_one_pass"));
        std::printf("bed: %zu spheres, %zu rocks, %.0f t; DEM step %.3g s, %d threads\n", filled.spheres,
                    filled.rocks_per_class.empty() ? std::size_t{0} : filled.rocks_per_class[0],
                    (filled.sphere_mass_kg + filled.rock_mass_kg) / 1000.0, sim.dem().step_s(), threads);

        // 4. dig until the door opens (the first pass is recorded then), reporting each simulated second
        constexpr double kGiveUp_s = 40.0;  // the cycle opens the door 27 s in (2 s settling, 25 s of pass)
        double next_report_s = 1.0;
        while (sim.passes().empty() && sim.time_s() < kGiveUp_s) {
            sim.step();
            if (sim.time_s() >= next_report_s) {
                const coupling::BucketContents b = sim.bucket();
                std::printf("t = %4.1f s  in the dipper %5.1f t  dig force %5.2f MN\n", sim.time_s(), b.mass_kg / 1000.0,
                            sim.reading().dig_force_filtered_N / 1e6);
                std::fflush(stdout);
                next_report_s += 1.0;
            }
        }
        if (sim.passes().empty()) {
            std::fprintf(stderr, "dipper_dig_one_pass: no pass by t = %.0f s\n", kGiveUp_s);
            return 1;
        }
        const coupling::PassRecord& p = sim.passes()[0];
        std::printf("dipper wear: %.3g mm3 over %.1f t\n", sim.wear()[0].surface->total_volume_m3() * 1e9, sim.tonnage_t());
        std::printf("pass 1: %.1f t, mean dig force %.2f MN\n", p.mass_kg / 1000.0, p.mean_dig_force_N / 1e6);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "dipper_dig_one_pass: %s\n", e.what());
        return 1;
    }
    return 0;
}
