#include "scenario/scenario.h"

#include "core/errors.h"
#include "meshes/machine_geometry.h"
#include "meshes/mesh_io.h"
#include "scenario/detail/map_reader.h"
#include "scenario/detail/text_checks.h"
#include "scenario/keys.h"
#include "wear/calibration.h"
#include "wear/laws.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace dipper::scenario {

using detail::MapReader;

namespace {

/// A file named in the scenario: absolute, or relative to the scenario file's folder.
std::string resolved(const std::string& base_dir, const std::string& file)
{
    const std::filesystem::path p(file);
    return (p.is_absolute() ? p : std::filesystem::path(base_dir) / p).string();
}

dem::SizeDistribution read_sizes(const MapReader& r, bool fractions_sum_to_one = true)
{
    dem::SizeDistribution d;
    for (const MapReader& s : r.maps("sizes")) {
        const double radius = s.number("radius_m"), fraction = s.number("mass_fraction");
        require_positive(radius, "radius_m", s.where("radius_m"));
        require_in_range(fraction, 0.0, 1.0, "mass_fraction", s.where("mass_fraction"));
        d.classes.push_back({radius, fraction});
    }
    if (d.classes.empty()) r.fail("sizes", "an empty list", "at least one size class");
    if (fractions_sum_to_one) d.validate(r.where("sizes"));
    return d;
}

void read_box(const MapReader& r, Vec3& lo, Vec3& hi, const char* lo_key, const char* hi_key)
{
    lo = r.vector3(lo_key);
    hi = r.vector3(hi_key);
    for (int a = 0; a < 3; ++a)
        if (!(hi[a] > lo[a]))
            r.fail(hi_key, concat("[", hi.x, ", ", hi.y, ", ", hi.z, "]"),
                   concat("each coordinate above ", lo_key, " [", lo.x, ", ", lo.y, ", ", lo.z, "]"));
}

/// A wall's removed_at_s: when it stops touching spheres; infinite when the key is absent.
double removal_time(const MapReader& r)
{
    if (!r.has("removed_at_s")) return std::numeric_limits<double>::infinity();
    const double t = r.number("removed_at_s");
    require_non_negative(t, "removed_at_s", r.where("removed_at_s"));
    return t;
}

void read_materials(const MapReader& top, Scenario& s)
{
    const MapReader m = top.map("materials");
    const std::string preset = m.text("preset");
    const double density = m.number("particle_density_kg_per_m3");
    require_positive(density, "particle_density_kg_per_m3", m.where("particle_density_kg_per_m3"));
    if (preset == "aitik_copper_ore") s.materials = dem::MaterialTable::aitik_copper_ore(density);
    else if (preset == "none") s.materials = dem::MaterialTable{};
    else m.fail("preset", concat("\"", preset, "\""), "aitik_copper_ore or none");
    const std::string rolling = m.text("rolling_resistance");
    if (rolling == "relative_spring") s.materials.set_rolling_resistance(dem::RollingResistance::relative_spring);
    else if (rolling == "own_spin") s.materials.set_rolling_resistance(dem::RollingResistance::own_spin);
    else m.fail("rolling_resistance", concat("\"", rolling, "\""), "relative_spring or own_spin");

    for (const MapReader& a : m.maps("add")) {
        dem::Material mat;
        mat.name = a.text("name");
        mat.is_surface = a.boolean("surface");
        mat.density_kg_per_m3 = a.number("density_kg_per_m3");
        mat.youngs_modulus_Pa = a.number("youngs_modulus_Pa");
        mat.poisson_ratio = a.number("poisson_ratio");
        for (std::size_t k = 0; k < s.materials.size(); ++k)
            if (s.materials.material(static_cast<dem::MaterialIndex>(k)).name == mat.name)
                a.fail("name", concat("\"", mat.name, "\""), "a name not already in the table");
        dem::validate(mat, a.where("name"));
        s.materials.add(mat);
    }
    for (const MapReader& p : m.maps("pairs")) {
        const std::vector<std::string> names = p.texts("materials");
        if (names.size() != 2) p.fail("materials", concat(names.size(), " names"), "two material names [a, b]");
        dem::MaterialIndex ia = 0, ib = 0;
        try {
            ia = s.materials.index_of(names[0]);
            ib = s.materials.index_of(names[1]);
        } catch (const InputError& e) {
            throw InputError(concat(p.where("materials"), ": ", e.what()));
        }
        dem::PairCoefficients c = s.materials.has_pair(ia, ib) ? s.materials.pair(ia, ib) : dem::PairCoefficients{};
        const auto set = [&](const char* key, double& field) {
            if (p.has(key) || !s.materials.has_pair(ia, ib)) field = p.number(key);
        };
        set("normal_stiffness_scale", c.normal_stiffness_scale);
        set("tangential_stiffness_scale", c.tangential_stiffness_scale);
        set("friction", c.friction);
        set("rolling_friction", c.rolling_friction);
        set("normal_damping_ratio", c.normal_damping_ratio);
        set("tangential_damping_ratio", c.tangential_damping_ratio);
        s.materials.set_pair(ia, ib, c, p.where("materials"));
    }
    for (const MapReader& p : m.maps("rock_pairs")) {
        const std::vector<std::string> names = p.texts("materials");
        const auto rigid = [](const std::string& n) {
            const auto& known = rigid_material_names();
            return std::find(known.begin(), known.end(), n) != known.end();
        };
        if (names.size() != 2 || !rigid(names[0]) || !rigid(names[1]) || (names[0] != "rock" && names[1] != "rock"))
            p.fail("materials", concat("[", joined(names), "]"),
                   concat("[rock, X] with X one of the rigid materials ", joined(rigid_material_names())));
        coupling::RockPair pair{names[0], names[1], p.number("friction"), p.number("restitution")};
        require_in_range(pair.friction, 0.0, 2.0, "friction", p.where("friction"));
        require_in_range(pair.restitution, 0.0, 1.0, "restitution", p.where("restitution"));
        s.rock_pairs.push_back(pair);
    }
}

std::string material_known(const Scenario& s, const MapReader& r, const std::string& key, bool surface)
{
    const std::string name = r.text(key);
    for (std::size_t k = 0; k < s.materials.size(); ++k) {
        const dem::Material& m = s.materials.material(static_cast<dem::MaterialIndex>(k));
        if (m.name != name) continue;
        if (m.is_surface != surface)
            r.fail(key, concat("\"", name, "\""), surface ? "a surface material (a wall)" : "a particle material (not a surface)");
        return name;
    }
    std::vector<std::string> names;
    for (std::size_t k = 0; k < s.materials.size(); ++k) {
        const dem::Material& m = s.materials.material(static_cast<dem::MaterialIndex>(k));
        if (m.is_surface == surface) names.push_back(m.name);
    }
    r.fail(key, concat("\"", name, "\""), concat("one of the ", surface ? "surface" : "particle", " materials: ", joined(names)));
}

/// A fill or pour of spheres alone makes at most dem::kMaxFillParticles (a mix with rocks is checked as it is made).
void require_particle_count(const Scenario& s, const MapReader& r, const ParticleSource& source)
{
    const double density = s.materials.material(s.materials.index_of(source.material)).density_kg_per_m3;
    const double count = dem::particles_for_mass(source.sizes, density, source.mass_kg);
    if (!(count <= dem::kMaxFillParticles))
        r.fail("mass_kg", concat(source.mass_kg),
               concat("a mass of at most ", dem::kMaxFillParticles, " particles (this is ", count, " of these sizes at ",
                      density, " kg/m3)"));
    if (count < 0.5)
        r.fail("mass_kg", concat(source.mass_kg),
               concat("a mass of at least one particle (this is ", count, " of these sizes at ", density, " kg/m3)"));
}

/// The keys fills and pours share: material, mass, box and sizes.
ParticleSource read_source(const Scenario& s, const MapReader& r, bool fractions_sum_to_one = true)
{
    ParticleSource source;
    source.where = r.where("mass_kg");
    source.material = material_known(s, r, "material", false);
    source.mass_kg = r.number("mass_kg");
    require_positive(source.mass_kg, "mass_kg", r.where("mass_kg"));
    read_box(r.map("box"), source.min_m, source.max_m, "min_m", "max_m");
    source.sizes = read_sizes(r, fractions_sum_to_one);
    // a box no wider than a sphere's diameter has no place for its centre (a pour placed nothing, and a
    // run with no sphere at t = 0 had no time step)
    const double diameter = 2.0 * source.sizes.max_radius_m();
    for (int a = 0; a < 3; ++a)
        if (!(source.max_m[a] - source.min_m[a] > diameter))
            r.fail("box", concat("a box ", source.max_m[a] - source.min_m[a], " m wide in ", "xyz"[a]),
                   concat("a box wider than the largest sphere's diameter, ", diameter, " m, in x, y and z"));
    return source;
}

FillSpec read_fill(const Scenario& s, const MapReader& r)
{
    FillSpec fill;
    const std::vector<MapReader> rocks = r.maps("rocks");
    static_cast<ParticleSource&>(fill) = read_source(s, r, rocks.empty());
    dem::require_mass_fits(fill.mass_kg, s.materials.material(s.materials.index_of(fill.material)).density_kg_per_m3,
                           fill.min_m, fill.max_m, r.where("mass_kg"));
    if (rocks.empty()) require_particle_count(s, r, fill);
    fill.rock_elongation_max = r.number("rock_elongation_max");
    require_in_range(fill.rock_elongation_max, 1.0, 4.0, "rock_elongation_max", r.where("rock_elongation_max"));
    const std::int64_t rock_points = r.integer("rock_points");
    if (rock_points < 8 || rock_points > 100) r.fail("rock_points", concat(rock_points), "a number of points from 8 to 100");
    fill.rock_points = static_cast<int>(rock_points);
    if (rocks.empty()) return fill;
    if (fill.sizes.classes.size() != 1)
        r.fail("sizes", concat(fill.sizes.classes.size(), " sphere classes"), "one sphere class in a fill with rocks");
    double sum = fill.sizes.classes[0].mass_fraction;
    for (const MapReader& k : rocks) {
        coupling::RockClass c;
        c.size_m = k.number("size_m");
        require_positive(c.size_m, "size_m", k.where("size_m"));
        c.mass_fraction = k.number("mass_fraction");
        require_in_range(c.mass_fraction, 0.0, 1.0, "mass_fraction", k.where("mass_fraction"));
        sum += c.mass_fraction;
        fill.rocks.push_back(c);
    }
    if (std::abs(sum - 1.0) > 1e-6)
        r.fail("rocks", concat("mass fractions summing to ", sum, " with the spheres'"),
               "the sphere class and the rock classes to sum to 1");
    return fill;
}

ShovelSpec read_shovel(const Scenario& s, const MapReader& m)
{
    ShovelSpec sh;
    sh.where = s.source;
    sh.position_m = m.vector3("position_m");
    sh.heading_deg = m.number("heading_deg");
    sh.rake_angle_deg = m.number("rake_angle_deg");
    require_in_range(sh.rake_angle_deg, 40.0, 80.0, "rake_angle_deg", m.where("rake_angle_deg"));
    sh.wear_bars = m.one_of("wear_bars", {"baseline", "transverse", "diagonal"});
    sh.element_size_m = m.number("element_size_m");
    require_in_range(sh.element_size_m, 0.02, 1.0, "element_size_m", m.where("element_size_m"));
    sh.material = material_known(s, m, "material", true);
    sh.motion = m.text("motion");
    const bool built_in = sh.motion == "default_cycle" || sh.motion == "dig_and_return";
    if (!built_in) sh.motion = resolved(s.base_dir, sh.motion);
    const std::int64_t passes = m.integer("passes");
    if (passes < 0 || passes > 1000) m.fail("passes", concat(passes), "0 (run for time.duration_s) or a number of passes");
    sh.passes = static_cast<int>(passes);
    sh.start_s = m.number("start_s");
    require_non_negative(sh.start_s, "start_s", m.where("start_s"));
    sh.dig_speed_factor = m.number("dig_speed_factor");
    require_in_range(sh.dig_speed_factor, 0.5, 2.0, "dig_speed_factor", m.where("dig_speed_factor"));
    if (sh.dig_speed_factor != 1.0 && !built_in)
        m.fail("dig_speed_factor", concat(sh.dig_speed_factor), "1 with a motion file (the factor reshapes the built-in cycles only)");
    sh.advance_per_pass_m = m.number("advance_per_pass_m");
    require_in_range(sh.advance_per_pass_m, 0.0, 10.0, "advance_per_pass_m", m.where("advance_per_pass_m"));
    if (sh.advance_per_pass_m != 0.0 && sh.motion != "default_cycle")
        m.fail("advance_per_pass_m", concat(sh.advance_per_pass_m),
               "0 unless shovel.motion is default_cycle (a motion file moves the machine with its propel_m column)");
    sh.bulk_density_kg_per_m3 = m.number("bulk_density_kg_per_m3");
    require_positive(sh.bulk_density_kg_per_m3, "bulk_density_kg_per_m3", m.where("bulk_density_kg_per_m3"));
    sh.where = m.where("motion");
    return sh;
}

}  // namespace

Scenario parse_scenario(const std::string& text, const std::string& source, const std::string& base_dir)
{
    detail::require_utf8(text, source);
    detail::require_quotes_closed(text, source);
    detail::require_one_document(text, source);
    YAML::Node root;
    try {
        root = YAML::Load(text);
    } catch (const YAML::Exception& e) {
        throw InputError(concat(source, ":", e.mark.line + 1, ":", e.mark.column + 1, ": not valid YAML: ", e.msg));
    }
    Scenario s;
    s.source = source;
    s.text = text;
    s.base_dir = base_dir;
    const MapReader top(root, "", "", s.source, YAML::Mark());

    const std::int64_t version = top.integer("dipper_scenario");
    if (version != 1) top.fail("dipper_scenario", concat(version), "1 (the format this dipper reads)");
    s.name = top.optional_text("name").value_or(std::filesystem::path(source).stem().string());
    const std::int64_t seed = top.integer("seed");
    if (seed < 0) top.fail("seed", concat(seed), "an integer >= 0");
    s.seed = static_cast<std::uint64_t>(seed);
    const std::int64_t threads = top.integer("threads");
    if (threads < 0 || threads > 1024) top.fail("threads", concat(threads), "0 (all cores) or a thread count up to 1024");
    s.threads = static_cast<int>(threads);
    s.gravity_m_per_s2 = top.vector3("gravity_m_per_s2");

    const MapReader time = top.map("time");
    s.duration_s = time.number("duration_s");
    require_positive(s.duration_s, "duration_s", time.where("duration_s"));
    s.step_s = time.number("step_s");
    require_non_negative(s.step_s, "step_s", time.where("step_s"));

    read_materials(top, s);

    for (const MapReader& p : top.maps("planes")) {
        PlaneSpec plane;
        plane.name = p.text("name");
        plane.point_m = p.vector3("point_m");
        plane.normal = p.vector3("normal");
        if (!(norm(plane.normal) > 0.0)) p.fail("normal", "[0, 0, 0]", "a non-zero vector");
        plane.normal = plane.normal * (1.0 / norm(plane.normal));
        plane.material = material_known(s, p, "material", true);
        plane.removed_at_s = removal_time(p);
        plane.material_only = p.boolean("material_only");
        s.planes.push_back(plane);
    }
    for (const MapReader& m : top.maps("meshes")) {
        MeshSpec mesh;
        mesh.where = m.where("file");
        mesh.name = m.text("name");
        mesh.file = m.optional_text("file").value_or("");
        mesh.part = m.optional_text("part").value_or("");
        if (mesh.file.empty() == mesh.part.empty())
            m.fail(mesh.file.empty() ? "file" : "part", mesh.file.empty() ? "neither file nor part" : "both file and part",
                   "a mesh file or a generated part, one of the two");
        if (!mesh.part.empty()) {
            mesh.where = m.where("part");
            (void)m.one_of("part", {"truck_body", "feeder_pan", "feeder_bin"});
        }
        mesh.element_size_m = m.number("element_size_m");
        require_in_range(mesh.element_size_m, 0.02, 2.0, "element_size_m", m.where("element_size_m"));
        mesh.material = material_known(s, m, "material", true);
        mesh.scale = m.number("scale");
        require_positive(mesh.scale, "scale", m.where("scale"));
        if (mesh.scale > 1e6) m.fail("scale", concat(mesh.scale), "a scale factor of at most 1e6");
        mesh.rotate_deg = m.vector3("rotate_deg");
        mesh.translate_m = m.vector3("translate_m");
        if (m.has("motion")) {
            const MapReader mo = m.map("motion");
            dem::PrescribedMotion motion;
            motion.velocity_m_per_s = mo.vector3("velocity_m_per_s");
            motion.angular_velocity_rad_per_s = mo.vector3("angular_velocity_rad_per_s");
            motion.pivot_m = mo.vector3("pivot_m");
            motion.oscillation_amplitude_m = mo.vector3("oscillation_amplitude_m");
            motion.oscillation_frequency_Hz = mo.number("oscillation_frequency_Hz");
            require_non_negative(motion.oscillation_frequency_Hz, "oscillation_frequency_Hz", mo.where("oscillation_frequency_Hz"));
            motion.start_s = mo.number("start_s");
            require_non_negative(motion.start_s, "start_s", mo.where("start_s"));
            if (mo.has("end_s")) {
                motion.end_s = mo.number("end_s");
                if (!(motion.end_s > motion.start_s))
                    mo.fail("end_s", concat(motion.end_s), concat("a time after start_s (", motion.start_s, " s)"));
            }
            mesh.motion = motion;
        }
        mesh.removed_at_s = removal_time(m);
        mesh.material_only = m.boolean("material_only");
        s.meshes.push_back(mesh);
    }
    // wall names are unique across planes and meshes
    {
        std::vector<std::string> names;
        for (const auto& p : s.planes) names.push_back(p.name);
        for (const auto& m : s.meshes) names.push_back(m.name);
        for (std::size_t a = 0; a < names.size(); ++a)
            for (std::size_t b = a + 1; b < names.size(); ++b)
                if (names[a] == names[b])
                    throw InputError(concat(s.source, ": wall name '", names[a], "' is used twice; planes and meshes need unique names"));
    }

    if (const auto pile = top.optional_text("pile")) {
        s.pile = resolved(s.base_dir, *pile);
        if (!std::filesystem::exists(s.pile))
            top.fail("pile", concat("\"", *pile, "\""), concat("a saved pile file (", s.pile, " does not exist)"));
    }
    if (top.has("pile_region")) {
        const MapReader r = top.map("pile_region");
        if (s.pile.empty()) throw InputError(concat(top.where("pile_region"), ": a region of a pile, but the scenario has no 'pile' to cut"));
        Scenario::PileRegion region;
        read_box(r, region.min_m, region.max_m, "min_m", "max_m");
        if (r.has("hold_m")) region.hold_m = r.number("hold_m");
        require_non_negative(region.hold_m, "hold_m", r.where("hold_m"));
        double smallest = region.max_m.x - region.min_m.x;
        for (int a = 1; a < 3; ++a) smallest = std::min(smallest, region.max_m[a] - region.min_m[a]);
        if (!(2.0 * region.hold_m < smallest))
            r.fail("hold_m", concat(region.hold_m), concat("less than half the region's narrowest side (", smallest, " m): else all of it is held"));
        s.pile_region = region;
    }
    for (const MapReader& f : top.maps("fills")) s.fills.push_back(read_fill(s, f));
    for (const MapReader& p : top.maps("pours")) {
        PourSpec pour;
        static_cast<ParticleSource&>(pour) = read_source(s, p);
        require_particle_count(s, p, pour);
        pour.rate_kg_per_s = p.number("rate_kg_per_s");
        require_positive(pour.rate_kg_per_s, "rate_kg_per_s", p.where("rate_kg_per_s"));
        pour.velocity_m_per_s = p.vector3("velocity_m_per_s");
        pour.start_s = p.number("start_s");
        require_non_negative(pour.start_s, "start_s", p.where("start_s"));
        s.pours.push_back(pour);
    }
    if (s.fills.empty() && s.pours.empty() && s.pile.empty())
        throw InputError(concat(s.source, ": the scenario has no particles; add a 'fills', 'pours' or 'pile' entry"));
    // the default time step comes from the spheres present at t = 0 (fills, pile, a pour starting at 0)
    const auto has_spheres = [](const FillSpec& f) {
        for (const auto& c : f.sizes.classes)
            if (c.mass_fraction > 0.0) return true;
        return false;
    };
    if (s.pile.empty() && s.step_s == 0.0 && std::none_of(s.fills.begin(), s.fills.end(), has_spheres)) {
        double first_s = std::numeric_limits<double>::infinity();
        for (const PourSpec& p : s.pours) first_s = std::min(first_s, p.start_s);
        if (first_s > 0.0 && !s.pours.empty() && s.fills.empty())
            throw InputError(concat(s.pours.front().where, ": no particle exists before the first pour starts at t = ", first_s,
                                    " s, so the default time step cannot be derived; set time.step_s or let a pour start at 0"));
        if (first_s > 0.0)
            throw InputError(concat(s.fills.front().where, ": the fills hold rocks but no spheres (the sphere class's mass_fraction is 0)",
                                    first_s < std::numeric_limits<double>::infinity() ? concat(" before the first pour starts at t = ", first_s, " s") : std::string(),
                                    ", so the default time step, which comes from the spheres, cannot be derived; set time.step_s "
                                    "(for rocks alone, e.g. 2e-4 s: Bullet then steps 1e-3 s with coupling.substeps 5)"));
    }

    const MapReader coupling = top.map("coupling");
    const std::int64_t substeps = coupling.integer("substeps");
    if (substeps < 1 || substeps > 100) coupling.fail("substeps", concat(substeps), "a whole number of DEM steps per rigid step, 1 to 100");
    s.coupling.substeps = static_cast<int>(substeps);
    s.coupling.runaway_guard = coupling.boolean("runaway_guard");
    const std::string exchange = coupling.text("rock_exchange");
    if (exchange == "coupling_step") s.coupling.rock_exchange = coupling::RockExchange::coupling_step;
    else if (exchange == "dem_step") s.coupling.rock_exchange = coupling::RockExchange::dem_step;
    else coupling.fail("rock_exchange", concat("\"", exchange, "\""), "coupling_step or dem_step");
    if (top.has("dynamic_domain")) {
        const MapReader d = top.map("dynamic_domain");
        coupling::DynamicDomainSettings& dd = s.dynamic_domain;
        dd.enabled = true;
        dd.margin_m = d.number("margin_m");
        dd.rest_speed_m_per_s = d.number("rest_speed_m_per_s");
        dd.rest_time_s = d.number("rest_time_s");
        if (!(dd.margin_m > 0.0) || dd.margin_m > 1e3) d.fail("margin_m", concat(dd.margin_m), "a distance > 0 and at most 1000 m");
        if (!(dd.rest_speed_m_per_s > 0.0) || dd.rest_speed_m_per_s > 1e3)
            d.fail("rest_speed_m_per_s", concat(dd.rest_speed_m_per_s), "a speed > 0 and at most 1000 m/s");
        if (!(dd.rest_time_s > 0.0) || dd.rest_time_s > 1e6) d.fail("rest_time_s", concat(dd.rest_time_s), "a time > 0 and at most 10^6 s");
    }
    if (top.has("shovel")) s.shovel = read_shovel(s, top.map("shovel"));
    for (const MapReader& w : top.maps("wear")) {
        WearSpec spec;
        spec.where = w.where("part");
        spec.part = w.text("part");
        bool known = (spec.part == "dipper" || spec.part == "door") && s.shovel.has_value();
        std::vector<std::string> parts;
        if (s.shovel) parts = {"dipper", "door"};
        for (const MeshSpec& mesh : s.meshes) {
            parts.push_back(mesh.name);
            known = known || mesh.name == spec.part;
        }
        if (!known)
            w.fail("part", concat("\"", spec.part, "\""),
                   parts.empty() ? std::string("a machine part, but the scenario has no shovel and no mesh walls")
                                 : concat("one of the parts: ", joined(parts)));
        for (const WearSpec& other : s.wear)
            if (other.part == spec.part) w.fail("part", concat("\"", spec.part, "\""), "each part once in the wear list");
        spec.law = w.text("law");
        spec.constant = w.number("constant");
        require_positive(spec.constant, "constant", w.where("constant"));
        (void)wear::WearLaw::from_name(spec.law, spec.constant, w.where("law"));  // an unknown law names its key
        const std::int64_t it = w.integer("smoothing_iterations");
        if (it < 0 || it > 100) w.fail("smoothing_iterations", concat(it), "0 to 100");
        spec.smoothing_iterations = static_cast<int>(it);
        spec.tonnage_t = w.number("tonnage_t");
        require_non_negative(spec.tonnage_t, "tonnage_t", w.where("tonnage_t"));
        if (const auto file = w.optional_text("measured_file")) {
            spec.measured_file = resolved(s.base_dir, *file);
            try {
                (void)wear::read_measured_points(spec.measured_file);  // its errors name file, line and column
            } catch (const InputError& e) {
                throw InputError(concat(w.where("measured_file"), ": ", e.what()));
            }
        }
        for (const MapReader& sec : w.maps("sections")) {
            WearSectionSpec section;
            section.where = sec.where("name");
            section.name = sec.text("name");
            if (section.name.empty() || section.name.find_first_not_of(
                                            "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") != std::string::npos)
                sec.fail("name", concat("\"", section.name, "\""), "a name of letters, digits, '_' and '-' (it names a file)");
            for (const WearSectionSpec& other : spec.sections)
                if (other.name == section.name) sec.fail("name", concat("\"", section.name, "\""), "each section name once per part");
            section.points_m = sec.vector3_list("points_m", 2);
            for (std::size_t k = 0; k + 1 < section.points_m.size(); ++k)
                if (norm(section.points_m[k + 1] - section.points_m[k]) < 1e-6)
                    sec.fail("points_m", concat("points ", k, " and ", k + 1, " at the same place"), "distinct consecutive points");
            section.spacing_m = sec.number("spacing_m");
            require_in_range(section.spacing_m, 1e-3, 10.0, "spacing_m", sec.where("spacing_m"));
            spec.sections.push_back(section);
        }
        s.wear.push_back(spec);
    }

    const MapReader probes = top.map("probes");
    for (const MapReader& r : probes.maps("regions")) {
        RegionProbe region;
        region.name = r.text("name");
        for (const RegionProbe& other : s.regions)
            if (other.name == region.name) r.fail("name", concat("\"", region.name, "\""), "a name no other region has (it names a column of probes.csv)");
        read_box(r, region.min_m, region.max_m, "min_m", "max_m");
        s.regions.push_back(region);
    }

    if (probes.has("repose")) {
        const MapReader r = probes.map("repose");
        ReposeProbe p;
        p.where = r.where("min_m");
        read_box(r, p.window.min_m, p.window.max_m, "min_m", "max_m");
        p.window.along = r.one_of("along", {"x", "y"})[0];
        p.window.bin_m = r.number("bin_m");
        require_positive(p.window.bin_m, "bin_m", r.where("bin_m"));
        p.window.validate(r.where("bin_m"));
        s.repose = p;
    }

    const MapReader out = top.map("output");
    s.output.vtk_interval_s = out.number("vtk_interval_s");
    s.output.vtk_where = out.where("vtk_interval_s");
    require_non_negative(s.output.vtk_interval_s, "vtk_interval_s", out.where("vtk_interval_s"));
    s.output.csv_interval_s = out.number("csv_interval_s");
    s.output.csv_where = out.where("csv_interval_s");
    require_positive(s.output.csv_interval_s, "csv_interval_s", out.where("csv_interval_s"));
    s.output.checkpoint_interval_s = out.number("checkpoint_interval_s");
    s.output.checkpoint_where = out.where("checkpoint_interval_s");
    require_non_negative(s.output.checkpoint_interval_s, "checkpoint_interval_s", out.where("checkpoint_interval_s"));
    s.output.progress_interval_s = out.number("progress_interval_s");
    require_positive(s.output.progress_interval_s, "progress_interval_s", out.where("progress_interval_s"));
    if (const auto file = out.optional_text("pile_file")) {
        if (file->empty() || file->find('/') != std::string::npos)
            out.fail("pile_file", concat("\"", *file, "\""), "a file name (it is written into the output folder)");
        s.output.pile_file = *file;
    }
    s.output.pile_cut_above_m = out.number("pile_cut_above_m");
    // a wall taken out is taken out of the spheres' world; Bullet's copy for rocks and the machine stays
    if (s.uses_coupling()) {
        for (std::size_t k = 0; k < s.planes.size(); ++k)
            if (std::isfinite(s.planes[k].removed_at_s))
                throw InputError(concat(s.source, ": planes[", k, "].removed_at_s: walls are removed for spheres only; this scenario has "
                                        "rocks, the shovel, wear surfaces or a pile, whose walls cannot be removed"));
        for (std::size_t k = 0; k < s.meshes.size(); ++k)
            if (std::isfinite(s.meshes[k].removed_at_s))
                throw InputError(concat(s.source, ": meshes[", k, "].removed_at_s: walls are removed for spheres only; this scenario has "
                                        "rocks, the shovel, wear surfaces or a pile, whose walls cannot be removed"));
    }
    if (s.dynamic_domain.enabled && !s.uses_coupling())
        throw InputError(concat(s.source, ": dynamic_domain: it freezes bodies of the co-simulation; this scenario has no rocks, "
                                "shovel, wear surface or pile (a bed of spheres alone runs without it)"));
    return s;
}

bool Scenario::uses_coupling() const
{
    if (shovel || !wear.empty() || !pile.empty() || !output.pile_file.empty()) return true;
    for (const FillSpec& f : fills)
        if (!f.rocks.empty()) return true;
    return false;
}

Scenario load_scenario(const std::string& path)
{
    std::ifstream in(path);
    if (!in) throw InputError(concat("cannot open scenario file '", path, "'"));
    std::stringstream text;
    text << in.rdbuf();
    const std::filesystem::path p = std::filesystem::absolute(path);
    return parse_scenario(text.str(), path, p.parent_path().string());
}

std::unique_ptr<dem::World> build_world(const Scenario& s)
{
    dem::WorldSettings settings;
    settings.gravity_m_per_s2 = s.gravity_m_per_s2;
    settings.step_s = s.step_s;
    settings.threads = s.threads;
    // a saved pile holds the overlaps of a bed at rest under its own weight (1-2 % of a radius in a deep
    // one): it loads as it was written, up to the overlap at which any run stops as diverged
    if (!s.pile.empty()) settings.initial_overlap_tolerance = settings.max_overlap_ratio;
    auto world = std::make_unique<dem::World>(s.materials, settings);
    for (const PlaneSpec& p : s.planes) world->add_plane(p.point_m, p.normal, s.materials.index_of(p.material), p.name);
    for (const MeshSpec& m : s.meshes) {
        meshes::TriangleMesh mesh;
        std::string source;
        try {
            if (!m.part.empty()) {
                meshes::FeederParameters feeder;
                feeder.element_size_m = m.element_size_m;
                meshes::TruckBodyParameters truck;
                truck.element_size_m = m.element_size_m;
                mesh = m.part == "truck_body" ? meshes::make_truck_body(truck).surface
                       : m.part == "feeder_pan" ? meshes::make_feeder(feeder).pan.surface
                                                : meshes::make_feeder(feeder).bin.surface;
                source = concat("generated ", m.part);
                std::vector<Vec3> scaled = mesh.vertices_m();
                for (Vec3& v : scaled) v = v * m.scale;
                mesh = meshes::TriangleMesh(std::move(scaled), mesh.triangles(), source);
            } else {
                source = resolved(s.base_dir, m.file);
                mesh = meshes::load_triangle_mesh(source, m.scale);
            }
        } catch (const InputError& e) {
            throw InputError(concat(m.where, ": ", e.what()));
        }
        const Mat3 turn = rotation_about_axis({0, 0, 1}, m.rotate_deg.z * M_PI / 180.0) *
                          rotation_about_axis({0, 1, 0}, m.rotate_deg.y * M_PI / 180.0) *
                          rotation_about_axis({1, 0, 0}, m.rotate_deg.x * M_PI / 180.0);
        std::vector<Vec3> vertices = mesh.vertices_m();
        for (Vec3& v : vertices) v = turn * v + m.translate_m;
        mesh = meshes::TriangleMesh(std::move(vertices), mesh.triangles(), source);
        world->add_mesh(std::move(mesh), s.materials.index_of(m.material), m.name, m.motion);
    }
    return world;
}

void check_pairs(const Scenario& s)
{
    std::vector<std::string> particle_materials;
    for (const auto& f : s.fills) particle_materials.push_back(f.material);
    for (const auto& p : s.pours) particle_materials.push_back(p.material);
    std::vector<std::string> others = particle_materials;
    for (const auto& p : s.planes) others.push_back(p.material);
    for (const auto& m : s.meshes) others.push_back(m.material);
    if (s.shovel) others.push_back(s.shovel->material);
    for (const auto& f : s.fills)
        if (!f.rocks.empty()) others.push_back("rock");  // the DEM material spheres see on rocks
    for (const std::string& a : particle_materials)
        for (const std::string& b : others)
            if (!s.materials.has_pair(s.materials.index_of(a), s.materials.index_of(b)))
                throw InputError(concat(s.source, ": materials '", a, "' and '", b,
                                        "' meet but have no pair coefficients; add them under materials.pairs"));
}

namespace {

/// A fill box less what the walls take: a sphere must lie on the particle side of every plane and
/// clear of every mesh wall's surface (in its pose at t = 0).
class ClearOfWalls final : public dem::Region {
public:
    ClearOfWalls(const Vec3& lo, const Vec3& hi, const dem::World& world) : box_(lo, hi), world_(world) {}
    bool holds(const Vec3& c, double r) const override
    {
        if (!box_.holds(c, r)) return false;
        for (std::size_t w = 0; w < world_.wall_count(); ++w) {
            const int id = static_cast<int>(w);
            if (!world_.is_mesh(id)) {
                const dem::PlaneWall& p = world_.plane_wall(id);
                if (dot(c - p.point_m, p.normal) < r) return false;
                continue;
            }
            if (!world_.mesh_wall(id).sphere_clear(c, r)) return false;
        }
        return true;
    }
    Vec3 bounds_min_m() const override { return box_.bounds_min_m(); }
    Vec3 bounds_max_m() const override { return box_.bounds_max_m(); }

private:
    dem::BoxRegion box_;
    const dem::World& world_;
};

}  // namespace

void build_particles(const Scenario& s, dem::World& world)
{
    for (std::size_t k = 0; k < s.fills.size(); ++k) {
        const FillSpec& f = s.fills[k];
        if (!f.rocks.empty()) continue;
        try {
            dem::fill_random(world, ClearOfWalls(f.min_m, f.max_m, world), f.sizes, s.materials.index_of(f.material), f.mass_kg,
                             s.seed * 1000003ull + k);
        } catch (const InputError& e) {
            throw InputError(concat(f.where, ": ", e.what()));
        }
    }
}

std::vector<dem::Pourer> make_pourers(const Scenario& s, const dem::World& world)
{
    std::vector<dem::Pourer> pourers;
    for (std::size_t k = 0; k < s.pours.size(); ++k) {
        const PourSpec& p = s.pours[k];
        pourers.emplace_back(dem::BoxRegion(p.min_m, p.max_m), p.sizes, world.materials().index_of(p.material),
                             p.rate_kg_per_s, p.mass_kg, p.velocity_m_per_s, s.seed * 7919ull + 17ull * k + 1ull, p.start_s);
    }
    return pourers;
}

}  // namespace dipper::scenario
