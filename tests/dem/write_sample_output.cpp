// Writes a small DEM run's ParaView and CSV output into the folder given on the command line, for the
// test that reads it back with VTK's own reader (tests/data/read_vtk_output.py).
#include "dem/insertion.h"
#include "dem/output.h"
#include "meshes/triangle_mesh.h"

#include <fstream>
#include <iostream>

int main(int argc, char** argv)
{
    using namespace dipper;
    using namespace dipper::dem;
    if (argc != 2) {
        std::cerr << "usage: dipper_write_sample_output OUTPUT_DIR\n";
        return 2;
    }
    World w(MaterialTable::aitik_copper_ore(), WorldSettings{});
    w.add_mesh(meshes::make_plate_mesh(1.0, 1.0, 2, 2), w.materials().index_of("ground"), "floor");
    fill_lattice(w, {0, 0, 0.01}, {1.0, 1.0, 0.6}, 0.1, 0.25, w.materials().index_of("ore"));
    ParaViewSeries series(argv[1]);
    WorldCsv csv(std::string(argv[1]) + "/world.csv", w);
    for (int frame = 0; frame < 3; ++frame) {
        w.run_steps(100);
        series.write(w);
        csv.write_row(w);
    }
    // the compressed arrays' edge cases: a world without particles (empty arrays), and 4,000 particles whose
    // arrays span several 64 KiB blocks, with their positions as text to compare bit for bit
    World empty(MaterialTable::aitik_copper_ore(), WorldSettings{});
    write_particles_vtp(empty, std::string(argv[1]) + "/empty.vtp");
    World large(MaterialTable::aitik_copper_ore(), WorldSettings{});
    fill_lattice(large, {0, 0, 0}, {2.0, 2.0, 1.0}, 0.02, 0.05, large.materials().index_of("ore"), 0.003, 5);
    write_particles_vtp(large, std::string(argv[1]) + "/large.vtp");
    std::ofstream text(std::string(argv[1]) + "/large_positions.txt");
    text.precision(17);
    for (const Vec3& x : large.particles().position_m) text << x.x << ' ' << x.y << ' ' << x.z << '\n';
    std::cout << "wrote 3 frames of " << w.particles().size() << " particles to " << argv[1] << "\n";
    return 0;
}
