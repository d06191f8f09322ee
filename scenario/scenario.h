// A scenario: one run described in a YAML file (docs/scenario.md lists every key). Parsing checks every
// key and value where it enters; building turns the description into a DEM world.
#pragma once

#include "core/vec3.h"
#include "coupling/co_simulation.h"
#include "coupling/mixed_bed.h"
#include "dem/insertion.h"
#include "dem/material.h"
#include "dem/pile.h"
#include "dem/walls.h"
#include "dem/world.h"

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace dipper::scenario {

struct PlaneSpec {
    std::string name, material;
    Vec3 point_m, normal;
    double removed_at_s = std::numeric_limits<double>::infinity();  ///< from then on no sphere touches it
    bool material_only = false;  ///< holds material only: the shovel's path may cross it (machine_crossings)
};

struct MeshSpec {
    std::string name, file, material;  ///< file: absolute, or relative to Scenario::base_dir
    std::string part;                  ///< a generated part instead of a file (truck_body, feeder_pan, feeder_bin)
    double element_size_m = 0.15;      ///< of a generated part
    double scale = 1.0;
    Vec3 rotate_deg;
    Vec3 translate_m;
    std::optional<dem::PrescribedMotion> motion;
    double removed_at_s = std::numeric_limits<double>::infinity();  ///< from then on no sphere touches it
    bool material_only = false;  ///< holds material only: the shovel's path may cross it (machine_crossings)
    std::string where;                 ///< file:line:col of the entry, for errors found when loading the mesh
};

/// Particles of a size distribution in a box: placed at t = 0 (a fill) or entering over time (a pour).
struct ParticleSource {
    std::string material = "ore";
    double mass_kg = 0.0;
    Vec3 min_m, max_m;
    dem::SizeDistribution sizes;
    std::string where;  ///< file:line:col of the entry's mass_kg, for errors found when placing
};

/// Particles placed at t = 0: spheres only, or spheres of one size with rock classes (a mixed fill).
struct FillSpec : ParticleSource {
    std::vector<coupling::RockClass> rocks;
    double rock_elongation_max = 2.0;
    int rock_points = 20;  ///< points drawn per rock before its hull (rigid::RockShape::point_count)
};

struct PourSpec : ParticleSource {
    double rate_kg_per_s = 0.0;
    Vec3 velocity_m_per_s;
    double start_s = 0.0;  ///< nothing enters before this time
};

using coupling::rigid_material_names;
/// Names for messages: "a, b, c".
inline std::string joined(const std::vector<std::string>& names)
{
    std::string s;
    for (std::size_t k = 0; k < names.size(); ++k) s += (k ? ", " : "") + names[k];
    return s;
}


struct RegionProbe {
    std::string name;
    Vec3 min_m, max_m;
};

/// The rope shovel of a scenario (rigid/rope_shovel.h).
struct ShovelSpec {
    Vec3 position_m;
    double heading_deg = 0.0;
    double rake_angle_deg = 61.8;
    std::string wear_bars = "baseline";  ///< baseline (no bars), transverse, diagonal
    double element_size_m = 0.15;
    std::string material = "bucket";
    std::string motion = "default_cycle";  ///< or a CSV file, absolute or relative to base_dir
    double start_s = 0.0;
    int passes = 0;  ///< > 0: the run ends 1 s after this pass's dump
    double dig_speed_factor = 1.0;
    double advance_per_pass_m = 0.0;  ///< the default cycle's propel after each dump
    double bulk_density_kg_per_m3 = 1903.0;
    std::string where;
};

/// A wear surface on a machine part.
/// A line across a wear surface along which the wear rate is written and compared with the measured
/// points near it (thesis Paper B Fig. 16).
struct WearSectionSpec {
    std::string name;
    std::vector<Vec3> points_m;  ///< polyline in the part's own frame, at least two points
    double spacing_m = 0.05;
    std::string where;
};

struct WearSpec {
    std::string part, law;
    double constant = 0.0;
    int smoothing_iterations = 2;
    double tonnage_t = 0.0;       ///< 0: the shovel's passes
    std::string measured_file;    ///< absolute path, or empty
    std::vector<WearSectionSpec> sections;
    std::string where;
};

struct ReposeProbe {
    dem::ReposeWindow window;
    std::string where;
};

struct OutputSpec {
    double vtk_interval_s = 0.1, csv_interval_s = 0.01, checkpoint_interval_s = 0.0, progress_interval_s = 10.0;
    std::string pile_file;      ///< file name in the output folder, or empty
    double pile_cut_above_m = 1e9;
    std::string vtk_where, csv_where, checkpoint_where;  ///< file:line:col of the intervals, for errors found later
};

/// A parsed, checked scenario.
struct Scenario {
    std::string source;    ///< the file it came from (for messages)
    std::string text;      ///< the file's text, kept so that a checkpoint carries its own scenario
    std::string base_dir;  ///< folder that relative file names are taken from
    std::string name;
    std::uint64_t seed = 1;
    int threads = 0;
    Vec3 gravity_m_per_s2{0.0, 0.0, -9.81};
    double duration_s = 0.0, step_s = 0.0;
    dem::MaterialTable materials;
    std::vector<coupling::RockPair> rock_pairs;  ///< applied in this order after the rigid preset
    std::vector<PlaneSpec> planes;
    std::vector<MeshSpec> meshes;
    std::string pile;  ///< a saved pile to start from (absolute path), or empty
    /// The part of the pile kept (pile_region): the spheres and rocks whose centre lies in the box; of those, the
    /// ones within hold_m of a face that cuts the pile (a face some body was left out beyond) are held fixed.
    struct PileRegion {
        Vec3 min_m, max_m;
        double hold_m = 0.5;
    };
    std::optional<PileRegion> pile_region;
    std::vector<FillSpec> fills;
    std::vector<PourSpec> pours;
    std::vector<RegionProbe> regions;
    std::optional<ReposeProbe> repose;
    OutputSpec output;
    coupling::CouplingSettings coupling;  ///< coupling.substeps, coupling.runaway_guard
    coupling::DynamicDomainSettings dynamic_domain;  ///< dynamic_domain: enabled where the section is given
    std::optional<ShovelSpec> shovel;
    std::vector<WearSpec> wear;

    /// True if the run goes through the co-simulation (coupling/co_simulation.h): it has rocks, the shovel, wear
    /// surfaces, or starts from or saves a pile.
    bool uses_coupling() const;
};

/// Reads and checks a scenario file. Errors are InputErrors of the form
/// "FILE:LINE:COL: key.path: got VALUE; expected ...", an unknown key listing the valid ones.
Scenario load_scenario(const std::string& path);
/// The same from text; `source` names it in messages and `base_dir` resolves relative file names.
Scenario parse_scenario(const std::string& text, const std::string& source, const std::string& base_dir);

/// The DEM world a scenario describes, with its walls; particles come from fills (build_particles) or a
/// checkpoint. Mesh files that cannot be read are InputErrors naming the scenario entry.
std::unique_ptr<dem::World> build_world(const Scenario& scenario);
/// Checks that every particle material of the fills and pours has coefficients with every other one and
/// with every wall's material; throws an InputError naming the pair and the scenario otherwise.
void check_pairs(const Scenario& scenario);
/// Places the particles of the fills without rocks (seeded by the scenario's seed and the fill's position
/// in the list), clear of the walls. Fills with rocks are placed by fill_rocks.
void build_particles(const Scenario& scenario, dem::World& world);
/// The pours, ready to run from t = 0 (each waits for its start_s).
std::vector<dem::Pourer> make_pourers(const Scenario& scenario, const dem::World& world);

/// How far a measured wear point or a wear section may lie from its part's surface, m.
inline constexpr double kMeasuredPointTolerance_m = 0.1;

/// The co-simulation of a scenario that uses_coupling(), around its DEM world (walls added, particles not
/// yet): Bullet's walls and rock pairs, and the shovel. Errors name the scenario entry.
std::unique_ptr<coupling::CoSimulation> build_co_simulation(const Scenario& scenario, std::unique_ptr<dem::World> dem);
/// Places the fills that have rocks (the others go through build_particles), clear of the machine.
void fill_rocks(const Scenario& scenario, coupling::CoSimulation& sim);
/// Adds the wear surfaces, in the scenario's order, after the fills; their measured points and sections must
/// lie on the part (kMeasuredPointTolerance_m).
void add_wear(const Scenario& scenario, coupling::CoSimulation& sim);
/// The tonnage wear surface k's rates divide by: its tonnage_t key, or the passes' tonnage.
double wear_tonnage_t(const Scenario& scenario, const coupling::CoSimulation& sim, std::size_t k);

}  // namespace dipper::scenario
