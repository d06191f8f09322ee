#include "coupling/bulk_density.h"

#include "core/errors.h"
#include "meshes/mesh_builder.h"

#include <algorithm>
#include <cmath>

namespace dipper::coupling {

void BulkDensityBox::validate(const std::string& where) const
{
    require_positive(length_m, "length_m", where);
    require_positive(width_m, "width_m", where);
    require_positive(height_m, "height_m", where);
    require_in_range(overfill, 1.0, 3.0, "overfill", where);
    require_positive(settle_s, "settle_s", where);
    if (substeps < 1) throw InputError(concat(where, ": substeps = ", substeps, "; expected >= 1"));
    distribution.validate(where);
}

namespace {

/// Volume of a sphere below the plane z = h (a spherical cap, or all or nothing).
double sphere_volume_below(double z, double r, double h)
{
    const double depth = std::clamp(h - (z - r), 0.0, 2.0 * r);  // height of the part below the plane
    return M_PI * depth * depth * (3.0 * r - depth) / 3.0;
}

/// Volume of a placed convex rock below the plane z = h: the hull of its vertices below and of its edges'
/// crossings of the plane.
double rock_volume_below(const rigid::ConvexPolyhedron& shape, const rigid::BodyState& s, double h)
{
    std::vector<Vec3> world;
    for (const Vec3& v : shape.vertices_m()) world.push_back(s.rotation * v + s.position_m);
    std::vector<Vec3> below;
    for (const Vec3& w : world)
        if (w.z <= h) below.push_back(w);
    if (below.size() == world.size()) return shape.volume_m3();
    if (below.empty()) return 0.0;
    for (const auto& t : shape.triangles())
        for (int e = 0; e < 3; ++e) {
            const Vec3 a = world[t[static_cast<std::size_t>(e)]], b = world[t[static_cast<std::size_t>((e + 1) % 3)]];
            if ((a.z < h) != (b.z < h)) below.push_back(a + (b - a) * ((h - a.z) / (b.z - a.z)));
        }
    try {
        return rigid::ConvexPolyhedron::hull_of(below, "rock part below the box top").volume_m3();
    } catch (const InputError&) {
        return 0.0;  // a sliver with (nearly) no volume
    }
}

}  // namespace

BulkDensityResult measure_bulk_density(const BulkDensityBox& box, double particle_density, double solid_volume_m3)
{
    const std::string where = "bulk density box";
    box.validate(where);
    require_positive(particle_density, "particle_density_kg_per_m3", where);
    require_positive(solid_volume_m3, "solid_volume_m3", where);

    dem::WorldSettings ds;
    ds.threads = box.threads;
    dem::World dem(dem::MaterialTable::aitik_copper_ore(particle_density), ds);
    rigid::RigidSettings rs;
    rs.threads = dem.threads();
    rigid::RigidWorld rigid(rs);
    rigid::add_aitik_copper_ore_materials(rigid);
    CoupledWorld world(dem, rigid, CouplingSettings{box.substeps});

    // the loose fill needs room above the box: a container as tall as the fill, struck off at height_m later
    const double poured = solid_volume_m3 * particle_density;
    const double fill_height = solid_volume_m3 / 0.3 / (box.length_m * box.width_m);  // loose: 30 % solid
    const double wall_height = std::max(box.height_m, fill_height) + 0.5;
    const meshes::TriangleMesh container = meshes::make_open_box_mesh(box.length_m, box.width_m, wall_height, 0.5);
    // rocks: Bullet's open box; spheres: the ground as floor and frictionless steel sides (Table 2's
    // "DE-remaining"), so that the floor carries the weight and the sides hold no material up
    rigid.add_static_mesh(container, rigid.material_index("ground"), "box");
    const auto& m = dem.materials();
    dem.add_plane({0, 0, 0}, {0, 0, 1}, m.index_of("ground"), "floor");
    dem.add_plane({0, 0, 0}, {1, 0, 0}, m.index_of("steel"), "x0");
    dem.add_plane({box.length_m, 0, 0}, {-1, 0, 0}, m.index_of("steel"), "x1");
    dem.add_plane({0, 0, 0}, {0, 1, 0}, m.index_of("steel"), "y0");
    dem.add_plane({0, box.width_m, 0}, {0, -1, 0}, m.index_of("steel"), "y1");
    const MixedMaterials materials{dem.materials().index_of("ore"), dem.materials().index_of("rock"), rigid.material_index("rock"),
                                   particle_density};
    fill_mixed(world, {0, 0, 0}, {box.length_m, box.width_m, fill_height}, box.distribution, materials, poured, box.seed);

    while (world.time_s() < box.settle_s) world.step();

    BulkDensityResult r;
    r.particle_density_kg_per_m3 = particle_density;
    const auto& p = dem.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
        r.translational_energy_J += 0.5 * p.mass_kg[i] * norm_squared(p.velocity_m_per_s[i]);
        const double v = sphere_volume_below(p.position_m[i].z, p.radius_m[i], box.height_m);
        r.mass_in_box_kg += v * particle_density;
        if (v > 0.0) ++r.spheres_in_box;
    }
    for (const RockRecord& rock : world.rocks()) {
        const rigid::BodyState s = rigid.state(rock.body);
        r.translational_energy_J += 0.5 * rigid.mass_kg(rock.body) * norm_squared(s.velocity_m_per_s);
        const double v = rock_volume_below(rock.shape, s, box.height_m);
        r.mass_in_box_kg += v * rock.density_kg_per_m3;
        if (v > 0.0) ++r.rocks_in_box;
    }
    r.bulk_density_kg_per_m3 = r.mass_in_box_kg / box.volume_m3();
    return r;
}

BulkDensityCalibration calibrate_bulk_density(const BulkDensityBox& box, double initial, double target, double tolerance,
                                              int max_scalings)
{
    require_positive(initial, "initial particle density", "bulk density calibration");
    require_positive(target, "target bulk density", "bulk density calibration");
    require_positive(tolerance, "tolerance", "bulk density calibration");
    if (max_scalings < 1)
        throw InputError(concat("bulk density calibration: max_scalings is ", max_scalings, "; expected 1 or more"));
    BulkDensityCalibration c;
    const double solid = box.overfill * box.volume_m3() * target / initial;
    c.first = measure_bulk_density(box, initial, solid);
    BulkDensityResult last = c.first;
    double density = initial;
    while (c.scalings < max_scalings) {
        if (!(last.bulk_density_kg_per_m3 > 0.0))
            throw SimulationError(concat("bulk density calibration: the box holds no material after settling (particle density ",
                                         density, " kg/m3); check the box and the fill"));
        density *= target / last.bulk_density_kg_per_m3;
        last = measure_bulk_density(box, density, solid);
        ++c.scalings;
        if (std::abs(last.bulk_density_kg_per_m3 / target - 1.0) <= tolerance) break;
    }
    c.scaled_particle_density_kg_per_m3 = density;
    c.confirmed = last;
    c.converged = std::abs(last.bulk_density_kg_per_m3 / target - 1.0) <= tolerance;
    return c;
}

}  // namespace dipper::coupling
