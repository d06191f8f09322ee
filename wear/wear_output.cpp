#include "wear/wear_output.h"

#include "core/errors.h"
#include "meshes/vtk_surface.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dipper::wear {

void write_wear_vtp(const WearSurface& s, const std::string& path, double tonnage_t, int smoothing_iterations,
                    const Mat3& rotation, const Vec3& translation_m, const std::vector<std::uint32_t>& triangle_plate)
{
    if (!(tonnage_t >= 0.0))
        throw InputError(concat("wear output '", path, "': tonnage is ", tonnage_t, " t; expected >= 0"));
    std::vector<Vec3> x = s.mesh().vertices_m();
    for (Vec3& v : x) v = rotation * v + translation_m;

    std::vector<double> cell_depth_mm = s.triangle_depth_m();
    for (double& d : cell_depth_mm) d *= 1000.0;
    std::vector<double> node_depth_mm = s.node_depth_m(smoothing_iterations);
    for (double& d : node_depth_mm) d *= 1000.0;
    const auto as_double = [](const std::vector<std::uint64_t>& v) { return std::vector<double>(v.begin(), v.end()); };

    std::vector<meshes::ScalarField> cells{{"depth_mm", cell_depth_mm},
                                           {"wear_volume_m3", s.triangle_volume_m3()},
                                           {"mean_normal_force_N", s.mean_normal_force_N()},
                                           {"mean_tangential_force_N", s.mean_tangential_force_N()},
                                           {"contact_steps", as_double(s.contact_steps())},
                                           {"impacts", as_double(s.impacts())}};
    std::vector<meshes::ScalarField> nodes{{"depth_mm", node_depth_mm}};
    if (tonnage_t > 0.0) {
        std::vector<double> cell_rate = cell_depth_mm, node_rate = node_depth_mm;
        for (double& r : cell_rate) r /= tonnage_t;
        for (double& r : node_rate) r /= tonnage_t;
        cells.emplace_back("rate_mm_per_t", std::move(cell_rate));
        nodes.emplace_back("rate_mm_per_t", std::move(node_rate));
    }
    if (!triangle_plate.empty()) {
        if (triangle_plate.size() != s.mesh().triangles().size())
            throw InputError(concat("wear output '", path, "': ", triangle_plate.size(), " plate numbers for ",
                                    s.mesh().triangles().size(), " triangles"));
        cells.emplace_back("plate", std::vector<double>(triangle_plate.begin(), triangle_plate.end()));
    }
    meshes::write_surface_vtp(path, x, s.mesh().triangles(), nodes, cells);
}

}  // namespace dipper::wear
