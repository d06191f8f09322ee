// Runs a small DEM flow onto an inclined plate, then writes the wear outputs into the folder given on the
// command line (ParaView surface, point and section CSVs, and a summary), for the test that
// reads them back with independent readers (tests/data/read_wear_output.py).
#include "core/files.h"
#include "dem/insertion.h"
#include "dem/world.h"
#include "meshes/triangle_mesh.h"
#include "wear/calibration.h"
#include "wear/wear_output.h"

#include <cmath>
#include <filesystem>
#include <iostream>

int main(int argc, char** argv)
{
    using namespace dipper;
    if (argc != 2) {
        std::cerr << "usage: dipper_write_wear_sample OUTPUT_DIR\n";
        return 2;
    }
    const std::string dir = argv[1];
    std::filesystem::create_directories(dir);

    // a 2 x 1 m plate at 75 mm elements, tilted 20 deg about y, and ore dropped onto its upper end
    dem::World w(dem::MaterialTable::aitik_copper_ore(), dem::WorldSettings{});
    const double tilt = 20.0 * M_PI / 180.0;
    const meshes::TriangleMesh plate = meshes::make_plate_mesh(2.0, 1.0, 27, 13);
    const int wall = w.add_mesh(plate, w.materials().index_of("bucket"), "plate");
    w.set_mesh_pose(wall, rotation_about_axis({0.0, 1.0, 0.0}, tilt), {}, {}, {}, {});
    const auto fill = dem::fill_lattice(w, {0.05, 0.05, 0.2}, {0.6, 0.95, 0.7}, 0.045, 0.1,
                                        w.materials().index_of("ore"), 0.003, 3);
    wear::WearSurface surface("plate", plate, wear::WearLaw::from_name("force_work", 1e-12, "sample"), wall);
    w.set_contact_consumer([&](const std::vector<ContactRecord>& c, double, double dt) { surface.accumulate(c, dt); }, {wall});
    while (w.time_s() < 1.0) w.step();

    double mass_kg = 0.0;
    for (const double m : w.particles().mass_kg) mass_kg += m;
    const double tonnage_t = mass_kg / 1000.0;
    wear::write_wear_vtp(surface, dir + "/plate_wear.vtp", tonnage_t, 1, rotation_about_axis({0.0, 1.0, 0.0}, tilt));

    // a section along the plate's middle, and points compared with themselves (measured = simulated x 1.5)
    const wear::RateMap map(surface, tonnage_t, 1);
    const std::vector<Vec3> section{{0.05, 0.5, 0.0}, {1.95, 0.5, 0.0}};
    std::vector<wear::MeasuredPoint> points;
    for (int k = 0; k < 6; ++k) {
        wear::MeasuredPoint p;
        p.id = "S" + std::to_string(k);
        p.position_m = {0.15 + 0.3 * k, 0.5, 0.0};
        p.tonnage_t = 100.0;
        p.depth_mm = 1.5 * map.at(p.position_m, 1e-6, p.id) * p.tonnage_t;
        points.push_back(p);
    }
    const auto comparisons = wear::compare_points(map, points, {}, 0.01);
    wear::write_points_csv(dir + "/points.csv", comparisons);
    wear::write_section_csv(dir + "/section_middle.csv", wear::sample_section(map, section, 0.05, 0.01, "middle"),
                            wear::points_on_section(section, comparisons, 0.05));

    std::ofstream summary = open_for_writing(dir + "/summary.txt");
    summary.precision(17);
    summary << "particles " << fill.placed << "\ntonnage_t " << tonnage_t << "\ntotal_volume_m3 " << surface.total_volume_m3()
            << "\n";
    finish_writing(summary, dir + "/summary.txt");
    std::cout << "wear sample: " << fill.placed << " particles, " << tonnage_t << " t, wear volume "
              << surface.total_volume_m3() << " m^3, surface " << dir << "/plate_wear.vtp\n";
    return 0;
}
