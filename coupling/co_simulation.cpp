#include "coupling/co_simulation.h"

#include "core/errors.h"
#include "meshes/vtk_surface.h"
#include "rigid/rope_shovel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace dipper::coupling {

namespace {

/// A large square of two triangles in a plane, for Bullet (which has a ground plane only for z = const).
meshes::TriangleMesh plane_patch(const Vec3& point, const Vec3& normal, double half_size_m)
{
    const Vec3 helper = std::abs(normal.z) < 0.9 ? Vec3{0, 0, 1} : Vec3{1, 0, 0};
    const Vec3 u = normalized(cross(helper, normal)), v = cross(normal, u);
    const std::vector<Vec3> x{point + (u + v) * -half_size_m, point + (u - v) * half_size_m, point + (u + v) * half_size_m,
                              point + (v - u) * half_size_m};
    return meshes::TriangleMesh(x, {{0, 1, 2}, {0, 2, 3}}, "plane");
}

int rigid_material_or_none(const rigid::RigidWorld& w, const std::string& name)
{
    try {
        return w.material_index(name);
    } catch (const InputError&) {
        return -1;
    }
}

std::string joined(const std::vector<std::string>& names)
{
    std::string s;
    for (std::size_t k = 0; k < names.size(); ++k) s += (k ? ", " : "") + names[k];
    return s;
}

}  // namespace

const std::vector<std::string>& rigid_material_names()
{
    static const std::vector<std::string> names{"rock", "ground", "bucket", "truck", "steel"};
    return names;
}

rigid::MotionCurves dig_speed_scaled(const rigid::MotionCurves& cycle, double factor, double pass_s)
{
    if (factor == 1.0) return cycle;
    const double dig = rigid::kBuiltInDig_s;
    const double new_pass = pass_s - dig + dig / factor;
    std::vector<rigid::MotionSample> samples = cycle.samples();
    for (rigid::MotionSample& s : samples) {
        const double k = std::floor(s.time_s / pass_s + 1e-9);
        const double local = s.time_s - k * pass_s;
        s.time_s = k * new_pass + (local <= dig ? local / factor : local - dig + dig / factor);
    }
    return rigid::MotionCurves::from_samples(std::move(samples), concat(cycle.source(), ", dig ", factor, " times as fast"));
}

CoSimulation::CoSimulation(std::unique_ptr<dem::World> dem, CoSimulationSettings settings)
    : dem_(std::move(dem)), domain_(settings.dynamic_domain)
{
    if (!dem_) throw InputError("CoSimulation: no DEM world given");
    given_walls_ = dem_->wall_count();
    rigid::RigidSettings rs;
    rs.gravity_m_per_s2 = dem_->settings().gravity_m_per_s2;
    rs.threads = dem_->threads();  // the narrow phase on the DEM's threads (the same bits on any number)
    rigid_ = std::make_unique<rigid::RigidWorld>(rs);
    rigid::add_aitik_copper_ore_materials(*rigid_);
    // the DEM preset's other surfaces, with the same friction against rocks as against spheres (Table 2:
    // FE truck-DE 0.85; DE-remaining 0, the frictionless walls of calibration boxes)
    rigid_->add_material("truck");
    rigid_->add_material("steel");
    rigid_->set_pair("rock", "truck", rigid::kTable2RockFriction.truck, 0.0);
    rigid_->set_pair("rock", "steel", 0.0, 0.0);
    for (const RockPair& p : settings.rock_pairs) rigid_->set_pair(p.a, p.b, p.friction, p.restitution);
    coupled_ = std::make_unique<coupling::CoupledWorld>(*dem_, *rigid_, settings.coupling);

    // the DEM's walls in Bullet, for rocks and the dipper; a wall whose material Bullet lacks is an error only
    // where rocks could meet it. They hold material; the machine follows its prescribed motion through them.
    for (int wall = 0; wall < static_cast<int>(given_walls_); ++wall) {
        const std::string& name = dem_->wall_name(wall);
        const dem::MaterialIndex dem_material = dem_->is_mesh(wall) ? dem_->mesh_wall(wall).material() : dem_->plane_wall(wall).material;
        const std::string& material = dem_->materials().material(dem_material).name;
        const int m = rigid_material_or_none(*rigid_, material);
        if (m < 0) {
            if (settings.rocks)
                throw InputError(concat("rocks meet wall '", name, "' of material '", material,
                                        "', which has no rock coefficients in the rigid world; give it one of the rigid materials ",
                                        joined(rigid_material_names())));
            continue;
        }
        if (!dem_->is_mesh(wall)) {
            const dem::PlaneWall& p = dem_->plane_wall(wall);
            rigid_->set_blocks_machine(p.normal.z > 1.0 - 1e-12 ? rigid_->add_ground_plane(p.point_m.z, m, name)
                                                                 : rigid_->add_static_mesh(plane_patch(p.point_m, p.normal, 500.0), m, name),
                                       false);
            continue;
        }
        const dem::MeshWall& mesh = dem_->mesh_wall(wall);
        rigid::BodyId body = -1;
        if (mesh.motion()) {
            // a moving wall is a kinematic body in Bullet that step() places where the DEM wall will be
            Mat3 r;
            Vec3 t;
            mesh.motion()->pose(dem_->time_s(), r, t);
            body = rigid_->add_kinematic_mesh(mesh.mesh(), m, name, r, t);
            moving_meshes_.push_back({body, *mesh.motion()});
        } else {
            body = rigid_->add_static_mesh(mesh.mesh(), m, name);
        }
        rigid_->set_blocks_machine(body, false);
        mesh_bodies_.emplace_back(name, body);
    }
}

CoSimulation::~CoSimulation() = default;

std::vector<rigid::PartPath> CoSimulation::shovel_path(double max_move_m) const
{
    if (!has_shovel()) return {};
    return rigid::shovel_path(rigid::ShovelGeometry{}, dipper_, *motion_, shovel_position_m_, shovel_heading_deg_, max_move_m);
}

void CoSimulation::add_shovel(const ShovelSettings& sh)
{
    if (has_shovel()) throw InputError("add_shovel: the co-simulation has a rope shovel already");
    if (!wear_.empty()) throw InputError("add_shovel: add the shovel before the wear surfaces");
    dipper_ = meshes::make_dipper(sh.dipper);
    const rigid::ShovelGeometry geometry;
    const bool built_in = sh.cycle != ShovelCycle::curves;
    if (!built_in && !sh.curves) throw InputError("add_shovel: the cycle is 'curves' and no motion curves were given");
    rigid::MotionCurves motion =
        sh.cycle == ShovelCycle::loading
            ? dig_speed_scaled(rigid::default_loading_cycle(geometry, dipper_, sh.advance_per_pass_m), sh.dig_speed_factor)
        : sh.cycle == ShovelCycle::dig_and_return
            ? dig_speed_scaled(rigid::dig_and_return_cycle(geometry, dipper_, sh.passes), sh.dig_speed_factor, rigid::kDigAndReturnPass_s)
            : *sh.curves;
    if (sh.start_s > 0.0) {
        std::vector<rigid::MotionSample> samples = motion.samples();
        for (rigid::MotionSample& m : samples) m.time_s += sh.start_s;
        motion = rigid::MotionCurves::from_samples(std::move(samples), concat(motion.source(), ", from t = ", sh.start_s, " s"));
    }
    bulk_density_ = sh.bulk_density_kg_per_m3;
    if (built_in) {
        cycle_start_s_ = sh.start_s;
        cycle_dig_s_ = rigid::kBuiltInDig_s / sh.dig_speed_factor;
        cycle_period_s_ = (sh.cycle == ShovelCycle::loading ? rigid::kDefaultCyclePass_s : rigid::kDigAndReturnPass_s) -
                          rigid::kBuiltInDig_s + cycle_dig_s_;
    }
    // a sphere around each part's steel, in its own frame, so that the tunnelling check skips far rocks
    for (int part = 0; part < 2; ++part) {
        std::vector<Vec3> corners;
        for (const meshes::Plate& plate : part == 0 ? dipper_.body.plates : dipper_.door.plates)
            for (const Vec3& c : plate.solid_corners_m()) corners.push_back(c);
        Vec3 centre;
        for (const Vec3& c : corners) centre += c * (1.0 / static_cast<double>(corners.size()));
        double radius = 0.0;
        for (const Vec3& c : corners) radius = std::max(radius, norm(c - centre));
        part_bounds_[static_cast<std::size_t>(part)] = {centre, radius};
    }
    motion_ = std::make_unique<rigid::MotionCurves>(motion);
    shovel_position_m_ = sh.position_m;
    shovel_heading_deg_ = sh.heading_deg;
    const rigid::RigidWorld::ShovelParts parts =
        rigid_->add_rope_shovel(dipper_, geometry, std::move(motion), rigid_->material_index("bucket"), sh.position_m, sh.heading_deg);
    dipper_body_ = parts.dipper;
    door_body_ = parts.door;
    const dem::MaterialIndex steel = dem_->materials().index_of(sh.material);
    dipper_wall_ = coupled_->body(coupled_->couple(parts.dipper, dipper_.body.surface, steel, "dipper")).wall;
    door_wall_ = coupled_->body(coupled_->couple(parts.door, dipper_.door.surface, steel, "door")).wall;
    for (const std::uint32_t plate : dipper_.body.triangle_plate) {
        const std::size_t region = dipper_region(plate);
        lip_triangle_.push_back(region == 1 || region == 4 ? 1 : 0);
    }
    dipper_locator_ = std::make_unique<meshes::TriangleLocator>(dipper_.body.surface);
}

std::size_t CoSimulation::dipper_region(std::uint32_t plate) const
{
    // the plates in make_dipper's order: bottom, lip, two sides, top, the teeth, then the wear bars
    if (plate <= 1) return plate;
    if (plate <= 3) return 2;
    if (plate == 4) return 3;
    return plate < 5 + static_cast<std::size_t>(dipper_.parameters.tooth_count) ? 4 : 5;
}

std::size_t CoSimulation::add_wear(const std::string& part, const wear::WearLaw& law)
{
    WearPart w;
    w.part = part;
    meshes::TriangleMesh mesh;
    if (part == "dipper" || part == "door") {
        if (!has_shovel()) throw InputError(concat("add_wear: part '", part, "' needs the rope shovel (add_shovel first)"));
        const bool d = part == "dipper";
        mesh = d ? dipper_.body.surface : dipper_.door.surface;
        w.wall = d ? dipper_wall_ : door_wall_;
        w.body = d ? dipper_body_ : door_body_;
    } else {
        for (int k = 0; k < static_cast<int>(given_walls_); ++k)
            if (dem_->is_mesh(k) && dem_->wall_name(k) == part) w.wall = k;
        if (w.wall < 0) throw InputError(concat("add_wear: no mesh wall named '", part, "'; expected dipper, door or a mesh wall's name"));
        mesh = dem_->mesh_wall(w.wall).mesh();
        for (const auto& [name, body] : mesh_bodies_)
            if (name == part) w.body = body;
    }
    w.surface = std::make_unique<wear::WearSurface>(part, std::move(mesh), law, w.wall);
    wear_.push_back(std::move(w));
    // the spheres' contacts with the wear surfaces reach them at every DEM step, from inside the DEM's step
    std::vector<int> walls;
    for (const WearPart& p : wear_) walls.push_back(p.wall);
    dem_->set_contact_consumer(
        [this](const std::vector<ContactRecord>& records, double, double dt) {
            for (WearPart& p : wear_) p.surface->accumulate(records, dt);
        },
        walls);
    return wear_.size() - 1;
}

void CoSimulation::step()
{
    // a coupling step: one exchange of `substeps` DEM steps (several of one while the runaway guard holds)
    const int steps = coupled_->begin_step();
    for (int e = 0; e < coupled_->settings().substeps / steps; ++e) {
        const double interval = coupled_->send_reactions(steps);  // the spheres' reactions to the bodies
        place_moving_walls(time_s() + interval);                   // kinematic walls where the step ends
        coupled_->step_rigid(interval);                            // Bullet: rocks, the shovel on its curves
        coupled_->run_dem(steps, interval);                        // the DEM sub-steps (sphere wear with them)
    }
    coupled_->end_step();
    check_tunnelling();
    add_rock_wear();
    track_passes();
    domain_.update(*coupled_, coupled_->coupling_step_s());  // what is at rest away from moving things: frozen
}

void CoSimulation::run_until(double t_s)
{
    while (time_s() < t_s - 1e-6 * dem_->step_s()) step();
}

void CoSimulation::place_moving_walls(double t_s)
{
    for (const auto& [body, motion] : moving_meshes_) {
        Mat3 r;
        Vec3 t;
        motion.pose(t_s, r, t);
        rigid_->set_kinematic_pose(body, r, t);
    }
}

void CoSimulation::add_rock_wear()
{
    const double dt = coupled_->coupling_step_s();
    for (WearPart& w : wear_)
        if (w.body >= 0)
            for (const ContactRecord& r : rigid_->surface_contacts(w.body, w.wall, &w.surface->mesh())) w.surface->add_contact(r, dt);
}

template <class IO, class Self>
void CoSimulation::state_fields(IO& io, Self& s)
{
    io.object(*s.rigid_);
    io.object(*s.coupled_);
    io.tag("scene");
    io.count(s.wear_.size(), "wear surfaces");
    for (auto& w : s.wear_) io.object(*w.surface);
    io(s.passes_, s.door_open_, s.pass_start_s_, s.dig_start_s_, s.dig_end_s_, s.dig_force_sum_, s.dig_force_peak_,
       s.interface_force_sum_, s.interface_force_peak_, s.without_lip_sum_, s.without_lip_peak_, s.dig_samples_);
    io.object(s.domain_);
}

void CoSimulation::write_state(StateWriter& out) const { state_fields(out, *this); }

void CoSimulation::read_state(StateReader& in) { state_fields(in, *this); }

double CoSimulation::tonnage_t() const
{
    double kg = 0.0;
    for (const PassRecord& p : passes_) kg += p.mass_kg;
    return kg / 1000.0;
}

bool CoSimulation::clear_of_machine(const Vec3& c, double r) const
{
    for (const int wall : {dipper_wall_, door_wall_}) {
        if (wall < 0) continue;
        if (!dem_->mesh_wall(wall).sphere_clear(c, r)) return false;
    }
    return true;
}

void CoSimulation::check_tunnelling() const
{
    // one pass over the rocks for both parts: a pile has 20,000 rocks, and this runs after every coupling step
    if (!has_shovel() || coupled_->rocks().empty()) return;
    struct Part {
        Mat3 back;
        Vec3 origin;
        const std::vector<meshes::Plate>* plates;
        Sphere bound;
    };
    std::array<Part, 2> parts;
    for (int part = 0; part < 2; ++part) {
        Mat3 r;
        Vec3 o;
        if (part == 0) rigid_->dipper_pose(r, o);
        else rigid_->door_pose(r, o);
        parts[static_cast<std::size_t>(part)] = {r.transposed(), o, part == 0 ? &dipper_.body.plates : &dipper_.door.plates,
                                                 part_bounds_[static_cast<std::size_t>(part)]};
    }
    // the plate a rock's centre lies inside, if any (part * 2^16 + plate), read on all threads at full size
    constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
    auto plate_holding = [&](std::size_t k) {
        const Vec3 c = rigid_->position_m(coupled_->rocks()[k].body);
        for (std::size_t part = 0; part < parts.size(); ++part) {
            const Part& pt = parts[part];
            const Vec3 q = pt.back * (c - pt.origin);
            if (norm_squared(q - pt.bound.centre) > pt.bound.radius * pt.bound.radius) continue;  // far from every plate
            for (std::size_t p = 0; p < pt.plates->size(); ++p)
                if ((*pt.plates)[p].contains(q)) return (part << 16) + p;
        }
        return kNone;
    };
    const auto rock_count = static_cast<std::ptrdiff_t>(coupled_->rocks().size());
    std::size_t first = kNone;  // the first rock in order, as one thread would find it
#pragma omp parallel for schedule(static) reduction(min : first) num_threads(coupled_->dem().threads()) if (rock_count > 256)
    for (std::ptrdiff_t q = 0; q < rock_count; ++q)
        if (plate_holding(static_cast<std::size_t>(q)) != kNone) first = std::min(first, static_cast<std::size_t>(q));
    if (first == kNone) return;
    const std::size_t k = first, where = plate_holding(k), part = where >> 16, p = where & 0xffffu;
    const rigid::BodyId id = coupled_->rocks()[k].body;
    const Vec3 c = rigid_->position_m(id);
    const double dt = coupled_->dem_step_s();
    throw SimulationError(concat("t = ", coupled_->time_s(), " s: rock ", k, " (", coupled_->rocks()[k].shape.equivalent_diameter_m(),
                                 " m, speed ", norm(rigid_->state(id).velocity_m_per_s), " m/s) has its centre at (", c.x, ", ",
                                 c.y, ", ", c.z, ") m inside plate ", p, " of the ", part == 0 ? "dipper" : "door",
                                 ": it went through the steel. Reduce WorldSettings::step_s (now ", dt, " s; try ", dt / 2.0,
                                 " s) or CouplingSettings::substeps (now ", coupled_->settings().substeps, ")"));
}

const rigid::ShovelReading& CoSimulation::reading() const
{
    return rigid_->shovel_reading();
}

BucketContents CoSimulation::bucket() const
{
    BucketContents b;
    if (!has_shovel()) return b;
    Mat3 r;
    Vec3 o;
    rigid_->dipper_pose(r, o);
    const Mat3 back = r.transposed();
    const meshes::DipperParameters& p = dipper_.parameters;
    const auto inside = [&](const Vec3& x) {
        const Vec3 q = back * (x - o);
        if (q.x < 0.0 || q.z < 0.0 || q.z > p.height_m || std::abs(q.y) > p.width_m / 2.0) return false;
        // the struck plane from the lip (bottom_length, 0) to the top plate's front edge (top_length, H)
        return q.x <= p.bottom_length_m + (p.top_length_m - p.bottom_length_m) * q.z / p.height_m;
    };
    const dem::ParticleStore& s = dem_->particles();
    for (std::size_t i = 0; i < s.size(); ++i)
        if (inside(s.position_m[i])) {
            b.mass_kg += s.mass_kg[i];
            ++b.spheres;
        }
    for (const coupling::RockRecord& rock : coupled_->rocks())
        if (inside(rigid_->state(rock.body).position_m)) {
            b.mass_kg += rigid_->mass_kg(rock.body);
            ++b.rocks;
        }
    b.fill_factor = b.mass_kg / (bulk_density_ * dipper_.struck_volume_m3);
    return b;
}

Vec3 CoSimulation::interface_force_N() const
{
    if (!has_shovel()) return {};
    // spheres through the DEM walls, rocks through Bullet's contacts (the machine's own parts and the
    // scenario's walls do not touch it there)
    return dem_->wall_force_N(dipper_wall_) + dem_->wall_force_N(door_wall_) + rigid_->contact_force_N(dipper_body_) +
           rigid_->contact_force_N(door_body_);
}

Vec3 CoSimulation::lip_force_N() const
{
    if (!has_shovel()) return {};
    Vec3 f;
    for (const ContactRecord& r : dem_->contact_records({dipper_wall_}))
        if (r.triangle_id >= 0 && lip_triangle_[static_cast<std::size_t>(r.triangle_id)])
            f -= r.normal_world * r.normal_force_N + r.tangential_force_N;  // the records hold the force on the sphere
    Mat3 rotation;
    Vec3 origin;
    rigid_->dipper_pose(rotation, origin);
    const Mat3 back = rotation.transposed();
    for (const rigid::RigidWorld::PointForce& p : rigid_->contact_point_forces(dipper_body_)) {
        const std::int32_t t = dipper_locator_->nearest(back * (p.point_m - origin)).triangle;
        if (t >= 0 && lip_triangle_[static_cast<std::size_t>(t)]) f += p.force_N;
    }
    return f;
}

void CoSimulation::track_passes()
{
    if (!has_shovel()) return;
    const rigid::ShovelReading& r = reading();
    const double t = coupled_->time_s(), dt = coupled_->coupling_step_s();
    // the dig phase: a built-in cycle's digs by their times; with a motion file, the swing at rest, the
    // door shut, and the hoist rope being hauled in
    bool digging = false;
    if (cycle_period_s_ > 0.0) {
        const double local = t - cycle_start_s_;
        digging = local > 0.0 && local - std::floor(local / cycle_period_s_) * cycle_period_s_ <= cycle_dig_s_;
    } else {
        const rigid::MotionSample now = motion_->at(t), before = motion_->at(t - dt);
        digging = std::abs(now.swing_deg) < 2.0 && now.door_deg < 1.0 && now.hoist_length_m < before.hoist_length_m;
    }
    if (!door_open_ && digging) {
        dig_force_sum_ += r.dig_force_N;
        dig_force_peak_ = std::max(dig_force_peak_, r.dig_force_N);
        const Vec3 total = interface_force_N();
        const double interface = norm(total), without_lip = norm(total - lip_force_N());
        interface_force_sum_ += interface;
        interface_force_peak_ = std::max(interface_force_peak_, interface);
        without_lip_sum_ += without_lip;
        without_lip_peak_ = std::max(without_lip_peak_, without_lip);
        if (dig_samples_++ == 0) dig_start_s_ = t;
        dig_end_s_ = t;
    }
    if (!door_open_ && r.door_deg > 5.0) {
        door_open_ = true;
        const BucketContents b = bucket();
        PassRecord pass;
        pass.start_s = pass_start_s_;
        pass.dig_start_s = dig_start_s_;
        pass.dig_end_s = dig_end_s_;
        pass.dump_s = t;
        pass.mass_kg = b.mass_kg;
        pass.fill_factor = b.fill_factor;
        pass.mean_dig_force_N = dig_samples_ > 0 ? dig_force_sum_ / static_cast<double>(dig_samples_) : 0.0;
        pass.peak_dig_force_N = dig_force_peak_;
        pass.mean_interface_force_N = dig_samples_ > 0 ? interface_force_sum_ / static_cast<double>(dig_samples_) : 0.0;
        pass.peak_interface_force_N = interface_force_peak_;
        pass.mean_interface_force_without_lip_N = dig_samples_ > 0 ? without_lip_sum_ / static_cast<double>(dig_samples_) : 0.0;
        pass.peak_interface_force_without_lip_N = without_lip_peak_;
        passes_.push_back(pass);
    }
    if (door_open_ && r.door_deg < 1.0) {
        door_open_ = false;
        pass_start_s_ = t;
        dig_force_sum_ = dig_force_peak_ = 0.0;
        interface_force_sum_ = interface_force_peak_ = 0.0;
        without_lip_sum_ = without_lip_peak_ = 0.0;
        dig_samples_ = 0;
        dig_start_s_ = dig_end_s_ = -1.0;
    }
}

std::vector<std::pair<std::string, double>> CoSimulation::wear_by_region(const WearPart& w) const
{
    if (w.part != "dipper") return {};
    std::vector<std::pair<std::string, double>> v{{"bottom", 0.0}, {"lip", 0.0}, {"sides", 0.0}, {"top", 0.0}, {"teeth", 0.0}, {"bars", 0.0}};
    const std::vector<double>& volume = w.surface->triangle_volume_m3();
    for (std::size_t t = 0; t < volume.size(); ++t) v[dipper_region(dipper_.body.triangle_plate[t])].second += volume[t];
    return v;
}

std::vector<std::string> CoSimulation::plate_names(const WearPart& w) const
{
    if (w.part == "door") return std::vector<std::string>(dipper_.door.plates.size(), "door");
    if (w.part != "dipper") return {};
    std::vector<std::string> names{"bottom", "lip", "side_minus_y", "side_plus_y", "top"};
    const auto teeth = static_cast<std::size_t>(dipper_.parameters.tooth_count);
    for (std::size_t k = 0; k < teeth; ++k) names.push_back(concat("tooth_", k + 1));
    for (std::size_t k = names.size(); k < dipper_.body.plates.size(); ++k) names.push_back(concat("bar_", k - 4 - teeth));
    return names;
}

const std::vector<std::uint32_t>& CoSimulation::triangle_plates(const WearPart& w) const
{
    static const std::vector<std::uint32_t> none;
    if (w.part == "door") return dipper_.door.triangle_plate;
    if (w.part == "dipper") return dipper_.body.triangle_plate;
    return none;
}

void CoSimulation::wear_pose(const WearPart& w, Mat3& rotation, Vec3& origin_m) const
{
    if (w.body >= 0 && rigid_->is_dynamic(w.body)) {
        rigid_->part_pose(w.body, rotation, origin_m);
        return;
    }
    const dem::MeshWall& wall = dem_->mesh_wall(w.wall);
    rotation = wall.rotation();
    origin_m = wall.translation_m();
}

std::vector<int> CoSimulation::listed_walls() const
{
    std::vector<int> walls;
    for (std::size_t w = 0; w < given_walls_; ++w) walls.push_back(static_cast<int>(w));
    if (dipper_wall_ >= 0) walls.push_back(dipper_wall_);
    if (door_wall_ >= 0) walls.push_back(door_wall_);
    return walls;
}

bool CoSimulation::is_rock_wall(int wall) const
{
    return wall >= static_cast<int>(given_walls_) && wall != dipper_wall_ && wall != door_wall_;
}

std::vector<Vec3> CoSimulation::rock_surface_points() const
{
    std::vector<Vec3> points;
    for (const coupling::RockRecord& rock : coupled_->rocks()) {
        const rigid::BodyState st = rigid_->state(rock.body);
        for (const Vec3& v : rock.shape.vertices_m()) points.push_back(st.rotation * v + st.position_m);
    }
    return points;
}

void CoSimulation::write_rocks_vtp(const std::string& path) const
{
    const std::vector<Vec3> x = rock_surface_points();  // each rock's vertices in turn
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<double> index, speed, size;
    std::uint32_t first = 0;
    for (std::size_t k = 0; k < coupled_->rocks().size(); ++k) {
        const coupling::RockRecord& rock = coupled_->rocks()[k];
        const rigid::BodyState st = rigid_->state(rock.body);
        for (const auto& t : rock.shape.triangles()) {
            triangles.push_back({first + t[0], first + t[1], first + t[2]});
            index.push_back(static_cast<double>(k));
            speed.push_back(norm(st.velocity_m_per_s));
            size.push_back(rock.shape.equivalent_diameter_m());
        }
        first += static_cast<std::uint32_t>(rock.shape.vertices_m().size());
    }
    meshes::write_surface_vtp(path, x, triangles, {}, {{"rock", index}, {"speed_m_per_s", speed}, {"size_m", size}});
}

}  // namespace dipper::coupling
