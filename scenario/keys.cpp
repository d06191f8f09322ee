#include "scenario/keys.h"

#include "coupling/coupled_world.h"

namespace dipper::scenario {

const std::vector<KeySpec>& scenario_keys()
{
    static const std::vector<KeySpec> keys = {
        {"dipper_scenario", "integer", "required", "format version of the file; 1"},
        {"name", "string", "none", "name of the run in reports; the file name without extension if absent"},
        {"seed", "integer", "1", "seed of every random choice (fills, pours); same seed, same run"},
        {"threads", "integer", "0", "OpenMP threads of the spheres, the coupling and Bullet's narrow phase; 0 takes OMP_NUM_THREADS or all cores. "
                                        "The rigid bodies' result is the same on any count; the spheres' parallel sums make a run's bits depend on it"},
        {"gravity_m_per_s2", "vector3", "[0, 0, -9.81]", "gravitational acceleration"},

        {"time", "map", "required", "time stepping"},
        {"time.duration_s", "number", "required", "simulated time to run, from 0"},
        {"time.step_s", "number", "0", "DEM time step; 0 takes 0.15 sqrt(m/K) of the smallest, stiffest particle, "
                                      "a value above the stable limit 0.2 sqrt(m/K) is refused"},

        {"materials", "map", "{}", "materials and pair coefficients (thesis Paper A Table 2)"},
        {"materials.preset", "string", "aitik_copper_ore",
         "starting table: aitik_copper_ore (materials ore, rock, ground, bucket, truck, steel and their pairs) or none"},
        {"materials.particle_density_kg_per_m3", "number", "3700",
         "density of the preset's ore and rock (the bulk-density calibration scales it)"},
        {"materials.rolling_resistance", "string", "relative_spring",
         "how rolling friction (eq. 8) acts: relative_spring (an elastic-plastic spring on a pair's relative rolling, "
         "limit mu_roll R* Fn) or own_spin (each contact resists the sphere's own spin with mu_roll r Fn, r its "
         "radius); docs/contact_model.md"},
        {"materials.add", "list", "[]", "materials added to the preset"},
        {"materials.add[].name", "string", "required", "unique material name"},
        {"materials.add[].surface", "boolean", "false", "true for a wall material (infinitely stiff and massive)"},
        {"materials.add[].density_kg_per_m3", "number", "required", "particle density (ignored for a surface)"},
        {"materials.add[].youngs_modulus_Pa", "number", "required", "Young's modulus E (eq. 5)"},
        {"materials.add[].poisson_ratio", "number", "required", "Poisson's ratio, 0 to 0.5 (eq. 5)"},
        {"materials.pairs", "list", "[]", "pair coefficients set or changed; a key left out keeps the pair's value "
                                         "(or the default of a new pair)"},
        {"materials.pairs[].materials", "list", "required", "the two material names, [a, b]"},
        {"materials.pairs[].normal_stiffness_scale", "number", "0.05", "C_norm of eq. 4"},
        {"materials.pairs[].tangential_stiffness_scale", "number", "0.27", "C_tan: Kt = C_tan Kn"},
        {"materials.pairs[].friction", "number", "0", "Coulomb friction mu (eq. 7)"},
        {"materials.pairs[].rolling_friction", "number", "0", "rolling friction mu_roll (eq. 8)"},
        {"materials.pairs[].normal_damping_ratio", "number", "1", "D_n, fraction of critical damping (eq. 6)"},
        {"materials.pairs[].tangential_damping_ratio", "number", "1", "D_t, fraction of critical damping"},
        {"materials.rock_pairs", "list", "[]", "coefficients of the rocks in Bullet (rock against rock or a wall), set or "
                                              "changed; the preset: rock 0.85, ground 0.9, bucket 0.53, truck 0.85, steel 0, restitution 0"},
        {"materials.rock_pairs[].materials", "list", "required", "rock and the other rigid material: rock, ground, bucket, truck or steel"},
        {"materials.rock_pairs[].friction", "number", "required", "Coulomb friction mu of the pair, 0 to 2"},
        {"materials.rock_pairs[].restitution", "number", "0", "restitution of the pair's impacts, 0 to 1"},

        {"planes", "list", "[]", "infinite static walls"},
        {"planes[].name", "string", "required", "unique wall name (used in outputs)"},
        {"planes[].point_m", "vector3", "required", "a point on the plane"},
        {"planes[].normal", "vector3", "required", "towards the side the particles are on; normalised"},
        {"planes[].material", "string", "required", "surface material"},
        {"planes[].removed_at_s", "number", "none", "time from which no sphere touches the plane (a gate opened); spheres only, not with rocks or the shovel"},
        {"planes[].material_only", "boolean", "false", "the plane only holds material (a slice's side): the shovel's path may cross it with a warning; else it stands for steel and a path into it is refused"},

        {"meshes", "list", "[]", "triangle-mesh walls from files (STL, OBJ, PLY) or generated machine parts"},
        {"meshes[].name", "string", "required", "unique wall name (used in outputs)"},
        {"meshes[].file", "string", "none", "mesh file, relative to the scenario file's folder (give file or part)"},
        {"meshes[].part", "string", "none", "a generated machine part instead of a file (docs/machine.md): truck_body, feeder_pan, feeder_bin"},
        {"meshes[].element_size_m", "number", "0.15", "largest surface element of a generated part"},
        {"meshes[].material", "string", "required", "surface material"},
        {"meshes[].scale", "number", "1", "factor from file units to metres (0.001 for millimetres)"},
        {"meshes[].rotate_deg", "vector3", "[0, 0, 0]", "turns about x, then y, then z, after scaling and before translating"},
        {"meshes[].translate_m", "vector3", "[0, 0, 0]", "added to every vertex after scaling and turning"},
        {"meshes[].motion", "map", "none", "prescribed rigid motion; without it the mesh stays put"},
        {"meshes[].motion.velocity_m_per_s", "vector3", "[0, 0, 0]", "constant velocity of the pivot"},
        {"meshes[].motion.angular_velocity_rad_per_s", "vector3", "[0, 0, 0]", "constant angular velocity about the pivot"},
        {"meshes[].motion.pivot_m", "vector3", "[0, 0, 0]", "the point that moves and that the mesh turns about, at t = 0"},
        {"meshes[].motion.oscillation_amplitude_m", "vector3", "[0, 0, 0]", "A in pivot + v t + A sin(2 pi f t)"},
        {"meshes[].motion.oscillation_frequency_Hz", "number", "0", "f of the oscillation"},
        {"meshes[].motion.start_s", "number", "0", "the motion starts then (t in the formulas counts from it); before, the mesh rests at its t = 0 pose"},
        {"meshes[].motion.end_s", "number", "none", "the motion stops then and the mesh stays where it was brought"},
        {"meshes[].removed_at_s", "number", "none", "time from which no sphere touches the mesh (a plug pulled); spheres only, not with rocks or the shovel"},
        {"meshes[].material_only", "boolean", "false", "the mesh only holds material: the shovel's path may cross it with a warning; else it stands for steel (the truck) and a path through it is refused"},

        {"pile", "string", "none",
         "a saved pile (output.pile_file of an earlier run), relative to this file: its spheres and rocks are placed at t = 0, "
         "before the fills"},
        {"pile_region", "map", "none",
         "keeps only the part of the pile whose centres lie in this box, and holds fixed the bodies within hold_m of each face "
         "that cuts the pile (the thesis' simplified model: the pile cut to the region the dipper works in, its boundary "
         "layer constrained)"},
        {"pile_region.min_m", "vector3", "required", "lower corner"},
        {"pile_region.max_m", "vector3", "required", "upper corner"},
        {"pile_region.hold_m", "number", "0.5", "width of the held layer inside each face that cuts the pile (the thesis: about 0.5 m)"},
        {"fills", "list", "[]", "particles placed at t = 0, seeded random and non-overlapping"},
        {"fills[].material", "string", "ore", "particle material"},
        {"fills[].mass_kg", "number", "required", "total mass to place: at most 74 % of the box as solid, and 10^8 spheres"},
        {"fills[].box", "map", "required", "the region: an axis-aligned box a whole sphere must fit in"},
        {"fills[].box.min_m", "vector3", "required", "lower corner"},
        {"fills[].box.max_m", "vector3", "required", "upper corner"},
        {"fills[].sizes", "list", "required", "size classes by mass fraction (sum 1)"},
        {"fills[].sizes[].radius_m", "number", "required", "sphere radius"},
        {"fills[].sizes[].mass_fraction", "number", "required", "fraction of the mass"},
        {"fills[].rocks", "list", "[]", "polyhedral rock classes of a mixed fill (Bullet bodies, thesis Paper A Table 1); "
                                       "with rocks, sizes holds one sphere class and all fractions sum to 1; a sphere fraction "
                                       "of 0 places rocks alone (then set time.step_s)"},
        {"fills[].rocks[].size_m", "number", "required", "diameter of the sphere of equal volume"},
        {"fills[].rocks[].mass_fraction", "number", "required", "fraction of the fill's mass"},
        {"fills[].rock_elongation_max", "number", "2", "largest length-to-width ratio of the random rock shapes (1 to 4)"},
        {"fills[].rock_points", "integer", "20", "points drawn per rock before its convex hull (8 to 100): fewer points give more "
                                              "angular rocks with larger flat faces (docs/rigid.md)"},

        {"pours", "list", "[]", "particles entering from a box at a mass flow rate"},
        {"pours[].material", "string", "ore", "particle material"},
        {"pours[].mass_kg", "number", "required", "total mass to pour: at most 10^8 spheres"},
        {"pours[].rate_kg_per_s", "number", "required", "mass flow rate"},
        {"pours[].velocity_m_per_s", "vector3", "[0, 0, 0]", "velocity of entering particles"},
        {"pours[].start_s", "number", "0", "time the pour begins (one loader bucket after another)"},
        {"pours[].box", "map", "required", "where particles enter"},
        {"pours[].box.min_m", "vector3", "required", "lower corner"},
        {"pours[].box.max_m", "vector3", "required", "upper corner"},
        {"pours[].sizes", "list", "required", "size classes by mass fraction (sum 1)"},
        {"pours[].sizes[].radius_m", "number", "required", "sphere radius"},
        {"pours[].sizes[].mass_fraction", "number", "required", "fraction of the mass"},

        {"coupling", "map", "{}", "spheres with rigid bodies (rocks, the shovel)"},
        {"coupling.substeps", "integer", std::to_string(coupling::kDefaultSubsteps), "DEM steps per rigid-body step (docs/coupling.md)"},
        {"coupling.runaway_guard", "boolean", coupling::CouplingSettings{}.runaway_guard ? "true" : "false", "one DEM step per rigid-body step for a while when a rock runs away (docs/coupling.md)"},
        {"coupling.rock_exchange", "string", "coupling_step",
         "how rocks take the spheres' forces: coupling_step (the mean of the sub-steps, at Bullet's step) or dem_step (at every DEM step; Bullet's step then takes the rocks' own contacts only; docs/coupling.md)"},

        {"dynamic_domain", "map", "none", "freeze spheres and rocks at rest away from the machine and moving material (docs/coupling.md); none: every body moves"},
        {"dynamic_domain.margin_m", "number", "1.0", "how far from anything moving a body must be to freeze (cells this wide)"},
        {"dynamic_domain.rest_speed_m_per_s", "number", "0.01", "at rest: on average no faster than this (stays within this times rest_time_s of one point) and no faster over the last rest_time_s/20 to rest_time_s/10; moving: faster than ten times this over that window"},
        {"dynamic_domain.rest_time_s", "number", "0.2", "over this long (> 0): at rest when it has stayed so near one point this long"},

        {"shovel", "map", "none", "the rope shovel (docs/machine.md), driven by motion curves"},
        {"shovel.position_m", "vector3", "[0, 0, 0]", "machine origin: on the ground, on the swing axis"},
        {"shovel.heading_deg", "number", "0", "turn of the machine about z; 0 digs towards +x"},
        {"shovel.rake_angle_deg", "number", "61.8", "dipper handle centre line to heel-tooth-tip line (thesis Fig. 4b)"},
        {"shovel.wear_bars", "string", "baseline", "flat bars on the dipper bottom: baseline (none), transverse (90 deg to the flow) or diagonal (45 deg)"},
        {"shovel.element_size_m", "number", "0.15", "largest surface element of dipper and door (contacts and wear maps)"},
        {"shovel.material", "string", "bucket", "surface material of dipper and door (spheres); rocks see the rigid 'bucket' material"},
        {"shovel.motion", "string", "default_cycle",
         "default_cycle (three passes of 46 s: dig 15 s, swing, dump, return), dig_and_return (fillings of 30 s emptied "
         "over the toe, no swing; as many as shovel.passes, else 3) or a CSV file of time_s, hoist_length_m, "
         "crowd_extension_m, swing_deg, door_deg and optionally propel_m"},
        {"shovel.start_s", "number", "0", "the motion starts at this time; before it the shovel holds its first pose (a pile settles)"},
        {"shovel.passes", "integer", "0", "the run ends 1 s after the door of this pass opened; 0: it runs for time.duration_s"},
        {"shovel.advance_per_pass_m", "number", "0",
         "default cycle: the crawlers carry the machine this far forward (along heading_deg) while it swings back after each dump"},
        {"shovel.dig_speed_factor", "number", "1", "the built-in cycle's dig done this many times faster (0.5 to 2)"},
        {"shovel.bulk_density_kg_per_m3", "number", "1903", "bulk density for the fill factor: mass in the dipper / (bulk density x struck volume)"},

        {"wear", "list", "[]", "wear surfaces: contact work on a machine part summed into wear (docs/wear.md)"},
        {"wear[].part", "string", "required", "dipper, door, or the name of a mesh wall"},
        {"wear[].law", "string", "force_work", "archard, finnie, force_work (thesis eq. 2.8) or impact_energy"},
        {"wear[].constant", "number", "required", "the law's constant: K (archard, m3/(N m)), phi (force_work, m3/J), "
                                                  "K (impact_energy, m3/J); finnie: the flow stress, Pa"},
        {"wear[].smoothing_iterations", "integer", "2", "volume-conserving smoothing of the nodal wear (thesis Paper B 3.4)"},
        {"wear[].tonnage_t", "number", "0", "material that passed over the part in the run, for mm/t; 0 takes the shovel's passes"},
        {"wear[].measured_file", "string", "none",
         "measured wear: CSV of id, x_m, y_m, z_m (part frame), depth_mm, tonnage_t; the run compares and calibrates against it"},
        {"wear[].sections", "list", "[]",
         "lines across the part along which the wear rate is written, with the measured points within 0.1 m (thesis Paper B Fig. 16)"},
        {"wear[].sections[].name", "string", "required", "names the file wear_<part>_section_<name>.csv"},
        {"wear[].sections[].points_m", "list", "required", "the line: at least two points [x, y, z] in the part's own frame, on its surface"},
        {"wear[].sections[].spacing_m", "number", "0.05", "distance between the samples along the line"},

        {"probes", "map", "{}", "quantities written to probes.csv besides the standard columns"},
        {"probes.regions", "list", "[]", "boxes whose particle mass is recorded (particles by centre)"},
        {"probes.regions[].name", "string", "required", "column name stem: <name>_mass_kg"},
        {"probes.regions[].min_m", "vector3", "required", "lower corner"},
        {"probes.regions[].max_m", "vector3", "required", "upper corner"},
        {"probes.repose", "map", "none", "angle of repose: a line fitted to the pile surface in a window (column repose_angle_deg)"},
        {"probes.repose.min_m", "vector3", "required", "lower corner of the window (spheres by centre, rocks by vertex)"},
        {"probes.repose.max_m", "vector3", "required", "upper corner of the window"},
        {"probes.repose.along", "string", "x", "x or y: the direction the slope runs in"},
        {"probes.repose.bin_m", "number", "0.2", "bin width along the slope; each bin's surface is its highest sphere top or rock vertex"},

        {"output", "map", "{}", "what is written, and how often"},
        {"output.vtk_interval_s", "number", "0.1", "simulated seconds between ParaView snapshots; 0: first and last only"},
        {"output.csv_interval_s", "number", "0.01", "simulated seconds between probes.csv rows"},
        {"output.checkpoint_interval_s", "number", "0",
         "simulated seconds between checkpoints; 0: only on SIGINT/SIGTERM and at the end"},
        {"output.progress_interval_s", "number", "10", "wall-clock seconds between progress lines when not on a terminal"},
        {"output.pile_file", "string", "none", "at the end of a completed run, the spheres and rocks are saved to this file in the "
                                               "output folder, for a later scenario's pile key"},
        {"output.pile_cut_above_m", "number", "1e9", "only spheres whose centre and rocks whose centroid lie at or below this height are saved"},
    };
    return keys;
}

const KeySpec* find_key(const std::string& path)
{
    for (const KeySpec& k : scenario_keys())
        if (k.path == path) return &k;
    return nullptr;
}

std::vector<std::string> child_keys(const std::string& path)
{
    std::vector<std::string> names;
    const std::string prefix = path.empty() ? "" : path + ".";
    for (const KeySpec& k : scenario_keys()) {
        if (k.path.compare(0, prefix.size(), prefix) != 0) continue;
        const std::string rest = k.path.substr(prefix.size());
        if (!rest.empty() && rest.find('.') == std::string::npos) names.push_back(rest);
    }
    return names;
}

const std::vector<std::pair<std::string, std::string>>& library_settings_as_keys()
{
    static const std::vector<std::pair<std::string, std::string>> names{
        {"WorldSettings::step_s", "time.step_s"},
        {"CouplingSettings::substeps", "coupling.substeps"},
        {"CouplingSettings::runaway_guard", "coupling.runaway_guard"},
        {"CouplingSettings::rock_exchange", "coupling.rock_exchange"},
    };
    return names;
}

std::string in_scenario_keys(std::string message)
{
    for (const auto& [setting, key] : library_settings_as_keys())
        for (std::size_t at = message.find(setting); at != std::string::npos; at = message.find(setting, at + key.size()))
            message.replace(at, setting.size(), key);
    return message;
}

}  // namespace dipper::scenario
