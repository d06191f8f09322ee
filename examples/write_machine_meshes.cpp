// Writes the generated machine parts as STL files: the dipper (baseline and the two wear-bar variants)
// with its door, the vibratory feeder's pan and bin, the truck body and the ground, at a chosen element
// size, and prints the dipper's struck volume and rake angle.
// Usage: dipper_write_machine_meshes OUTPUT_DIR [ELEMENT_SIZE_M]   (default 0.075)
#include "meshes/machine_geometry.h"
#include "meshes/mesh_io.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

int main(int argc, char** argv)
{
    using namespace dipper::meshes;
    if (argc < 2 || argc > 3) {
        std::fprintf(stderr, "usage: dipper_write_machine_meshes OUTPUT_DIR [ELEMENT_SIZE_M]\n");
        return 2;
    }
    const std::string dir = argv[1];
    const double size = argc == 3 ? std::atof(argv[2]) : 0.075;
    std::filesystem::create_directories(dir);
    const auto write = [&](const MachinePart& part) {
        const std::string path = dir + "/" + part.name + ".stl";
        write_stl(part.surface, path, part.name);
        std::printf("  %-16s %7zu triangles  %s\n", part.name.c_str(), part.surface.triangle_count(), path.c_str());
    };
    for (const WearBars bars : {WearBars::None, WearBars::Transverse, WearBars::Diagonal}) {
        DipperParameters p;
        p.element_size_m = size;
        p.wear_bars = bars;
        const Dipper d = make_dipper(p);
        write(d.body);
        if (bars == WearBars::None) {
            write(d.door);
            std::printf("dipper: struck volume %.3f m^3, rake angle %.2f deg\n", d.struck_volume_m3, d.measured_rake_angle_deg());
        }
    }
    FeederParameters f;
    f.element_size_m = size;
    const Feeder feeder = make_feeder(f);
    write(feeder.pan);
    write(feeder.bin);
    TruckBodyParameters t;
    t.element_size_m = std::max(size, 0.3);
    write(make_truck_body(t));
    write(make_ground(40.0, 40.0, 2.0));
    return 0;
}
