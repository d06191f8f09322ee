#include "coupling/coupled_world.h"

#include "core/errors.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <set>
#include <utility>

namespace dipper::coupling {

namespace {

/// f(k) for k in [0, n) on `threads` threads. An exception stops nothing midway; the one of the lowest k is
/// rethrown after the loop, so the error a user sees does not depend on the thread count.
template <class F>
void for_each_body(std::size_t n, int threads, F&& f)
{
    std::exception_ptr first;
    std::size_t first_k = n;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::size_t k = 0; k < n; ++k) {
        try {
            f(k);
        } catch (...) {
#pragma omp critical(dipper_coupling_error)
            if (k < first_k) {
                first_k = k;
                first = std::current_exception();
            }
        }
    }
    if (first) std::rethrow_exception(first);
}

/// The rotation by a rotation vector (axis times angle).
Mat3 rotation_of(const Vec3& turn_rad)
{
    const double angle = norm(turn_rad);
    return angle > 0.0 ? rotation_about_axis(turn_rad * (1.0 / angle), angle) : Mat3::identity();
}

}  // namespace

Vec3 rotation_vector(const Mat3& r)
{
    const auto& m = r.m;
    const double trace = m[0][0] + m[1][1] + m[2][2];
    const double cos_angle = std::clamp(0.5 * (trace - 1.0), -1.0, 1.0);
    const double angle = std::acos(cos_angle);
    const Vec3 skew{m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]};  // 2 sin(angle) axis
    if (angle < 1e-6) return skew * 0.5;                                        // sin(angle) ~ angle
    if (angle < M_PI - 1e-3) return skew * (angle / (2.0 * std::sin(angle)));
    // near a half turn sin(angle) is small: the axis from the diagonal of R = cos I + (1 - cos) a a^T + sin [a]x,
    // its signs from the largest component's row, and the overall sign from the skew part
    Vec3 a{std::sqrt(std::max(0.0, (m[0][0] - cos_angle) / (1.0 - cos_angle))),
           std::sqrt(std::max(0.0, (m[1][1] - cos_angle) / (1.0 - cos_angle))),
           std::sqrt(std::max(0.0, (m[2][2] - cos_angle) / (1.0 - cos_angle)))};
    if (a.x >= a.y && a.x >= a.z) {
        a.y = std::copysign(a.y, m[0][1] + m[1][0]);
        a.z = std::copysign(a.z, m[0][2] + m[2][0]);
    } else if (a.y >= a.z) {
        a.x = std::copysign(a.x, m[0][1] + m[1][0]);
        a.z = std::copysign(a.z, m[1][2] + m[2][1]);
    } else {
        a.x = std::copysign(a.x, m[0][2] + m[2][0]);
        a.y = std::copysign(a.y, m[1][2] + m[2][1]);
    }
    if (dot(a, skew) < 0.0) a = a * -1.0;
    return normalized(a) * angle;
}

CoupledWorld::CoupledWorld(dem::World& dem, rigid::RigidWorld& rigid, CouplingSettings settings)
    : dem_(dem), rigid_(rigid), settings_(settings)
{
    if (settings_.substeps < 1)
        throw InputError(concat("coupling substeps = ", settings_.substeps, "; expected a whole number >= 1 of DEM steps per rigid-body step"));
}

int CoupledWorld::couple(rigid::BodyId body, meshes::TriangleMesh surface, dem::MaterialIndex material, const std::string& name)
{
    const std::string& body_name = rigid_.body_name(body);  // validates the id
    if (index_of(body) >= 0) throw InputError(concat("couple: rigid body '", body_name, "' is coupled already"));
    if (surface.triangle_count() == 0)
        throw InputError(concat("couple: rigid body '", body_name, "' was given a surface '", name,
                                "' with no triangles; the spheres need a collision surface to touch"));
    if (material >= dem_.materials().size())
        throw InputError(concat("couple: rigid body '", body_name, "': DEM material index ", material, " does not exist"));
    CoupledBody b;
    b.body = body;
    b.dynamic = rigid_.is_dynamic(body);
    b.wall = dem_.add_mesh(std::move(surface), material, name);
    if (b.dynamic && rigid_.mass_kg(body) > 0.0) dem_.set_wall_mass_kg(b.wall, rigid_.mass_kg(body));
    bodies_.push_back(b);
    if (index_by_body_.size() <= static_cast<std::size_t>(body)) index_by_body_.resize(static_cast<std::size_t>(body) + 1, -1);
    index_by_body_[static_cast<std::size_t>(body)] = static_cast<int>(bodies_.size() - 1);
    // the surface starts where the body is, moving as it moves
    const Pose p = pose_of(b);
    const rigid::BodyState s = rigid_.state(body);
    dem_.set_mesh_pose(b.wall, p.rotation, p.origin_m, p.centre_m, s.velocity_m_per_s, s.angular_velocity_rad_per_s);
    before_.push_back(p);
    after_.push_back(p);
    spin_rad_.push_back({});
    force_sum_.push_back({});
    torque_sum_.push_back({});
    response_.push_back({});
    Watch w;
    w.velocity_m_per_s = s.velocity_m_per_s;
    w.angular_velocity_rad_per_s = s.angular_velocity_rad_per_s;
    watch_.push_back(w);
    return static_cast<int>(bodies_.size() - 1);
}

rigid::BodyId CoupledWorld::add_rock(const rigid::ConvexPolyhedron& shape, double density_kg_per_m3, int rigid_material,
                                     dem::MaterialIndex dem_material, const Vec3& position_m, const Mat3& rotation,
                                     const Vec3& velocity_m_per_s, const Vec3& angular_velocity_rad_per_s)
{
    const rigid::BodyId id = rigid_.add_rock(shape, density_kg_per_m3, rigid_material, position_m, rotation,
                                             velocity_m_per_s, angular_velocity_rad_per_s);
    std::string name = rigid_.body_name(id);  // "rock 12" -> DEM wall "rock_12" (wall names are file-name safe)
    std::replace(name.begin(), name.end(), ' ', '_');
    const auto k = static_cast<std::size_t>(couple(id, shape.to_mesh(), dem_material, name));
    // the shape is in its principal frame: its inertia about the centroid is diagonal there
    const Mat3 inertia = shape.inertia_about_centroid(density_kg_per_m3);
    const double mass = rigid_.mass_kg(id);
    watch_[k].radius_of_gyration_m = {std::sqrt(inertia.m[0][0] / mass), std::sqrt(inertia.m[1][1] / mass), std::sqrt(inertia.m[2][2] / mass)};
    rocks_.push_back({id, shape, density_kg_per_m3, rigid_material, dem_material});
    return id;
}

namespace {

/// What a checkpoint holds of each rock, listed once for writing and reading (core/state_io.h): its hull and
/// its materials; its pose is the rigid world's.
struct RockFields {
    std::vector<Vec3> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    double density = 0.0;
    std::int32_t rigid_material = 0;
    dem::MaterialIndex dem_material = 0;

    template <class IO>
    void fields(IO& io)
    {
        io(vertices, triangles, density, rigid_material, dem_material);
    }
};

}  // namespace

void CoupledWorld::write_rocks(StateWriter& out) const
{
    out.tag("rocks");
    out.value<std::uint64_t>(rocks_.size());
    for (const RockRecord& r : rocks_) {
        RockFields f{r.shape.vertices_m(), r.shape.triangles(), r.density_kg_per_m3, r.rigid_material, r.dem_material};
        f.fields(out);
    }
}

void CoupledWorld::read_rocks(StateReader& in)
{
    in.tag("rocks");
    const auto n = in.value<std::uint64_t>();
    if (n > in.left()) in.fail("more rocks than the file holds");
    struct Read {
        rigid::ConvexPolyhedron shape;
        double density;
        int rigid_material;
        dem::MaterialIndex dem_material;
    };
    std::vector<Read> read;
    double reach_m = 0.0;  // of the largest rock, from its centroid
    for (std::uint64_t k = 0; k < n; ++k) {
        RockFields f;
        f.fields(in);
        for (const auto& t : f.triangles)
            for (std::uint32_t v : t)
                if (v >= f.vertices.size()) in.fail(concat("rock ", k, " has a triangle with vertex ", v, " of ", f.vertices.size()));
        try {
            read.push_back({rigid::ConvexPolyhedron::from_mesh(meshes::TriangleMesh(std::move(f.vertices), std::move(f.triangles), "checkpoint rock")),
                            f.density, f.rigid_material, f.dem_material});
        } catch (const InputError& e) {
            in.fail(concat("rock ", k, ": ", e.what()));
        }
        for (const Vec3& v : read.back().shape.vertices_m()) reach_m = std::max(reach_m, norm(v));
    }
    // Each rock is made where it meets no other until read_state puts it in place: on a cubic lattice with gaps,
    // far below the scene. Made at one point, every two of them would overlap, and Bullet's broad phase would
    // list each such pair as the rocks came in (2e8 pairs, minutes and gigabytes, for the thesis' pile of
    // 20,000); made in a row, its tree of boxes would grow as deep as the row is long.
    constexpr double kParkedDepth_m = -1.0e5, kParkedGap_m = 1.0;
    const double spacing = 2.0 * reach_m + kParkedGap_m;
    const auto side = static_cast<std::size_t>(std::ceil(std::cbrt(static_cast<double>(read.size())))) + 1;
    for (std::size_t k = 0; k < read.size(); ++k) {
        const Vec3 parked{spacing * static_cast<double>(k % side), spacing * static_cast<double>(k / side % side),
                          kParkedDepth_m - spacing * static_cast<double>(k / (side * side))};
        add_rock(read[k].shape, read[k].density, read[k].rigid_material, read[k].dem_material, parked);
    }
}

template <class IO, class Self>
void CoupledWorld::state_fields(IO& io, Self& s)
{
    io.tag("coupling");
    io.count(s.bodies_.size(), "coupled bodies");
    for (auto& b : s.bodies_) io(b.applied_force_N, b.applied_torque_N_m);
    io(s.before_, s.after_, s.spin_rad_, s.force_sum_, s.torque_sum_, s.samples_, s.started_, s.rigid_seconds_,
       s.surface_seconds_, s.watch_, s.hold_steps_, s.guarded_steps_, s.runaways_caught_);
}

void CoupledWorld::write_state(StateWriter& out) const { state_fields(out, *this); }

void CoupledWorld::read_state(StateReader& in)
{
    state_fields(in, *this);
    for (std::size_t size : {before_.size(), after_.size(), spin_rad_.size(), force_sum_.size(), torque_sum_.size(), watch_.size(),
                             response_.size()})
        if (size != bodies_.size()) in.fail("coupling or runaway-guard arrays of another number of bodies");
    checked_bodies_ = 0;  // checked again before the next step
}

const CoupledBody& CoupledWorld::body(int index) const
{
    if (index < 0 || static_cast<std::size_t>(index) >= bodies_.size())
        throw InputError(concat("coupled body ", index, " does not exist; there are ", bodies_.size()));
    return bodies_[static_cast<std::size_t>(index)];
}

int CoupledWorld::index_of(rigid::BodyId body) const
{
    // a table, not a search: the dynamic domain asks for each of the full-size pile's 20,188 rocks at every
    // coupling step (a search over the bodies cost 0.1 s a step there)
    if (body < 0 || static_cast<std::size_t>(body) >= index_by_body_.size()) return -1;
    return index_by_body_[static_cast<std::size_t>(body)];
}

Vec3 CoupledWorld::mean_sphere_force_N(int index) const
{
    body(index);
    return samples_ > 0 ? force_sum_[static_cast<std::size_t>(index)] * (1.0 / samples_) : Vec3{};
}

Vec3 CoupledWorld::mean_sphere_torque_N_m(int index) const
{
    body(index);
    return samples_ > 0 ? torque_sum_[static_cast<std::size_t>(index)] * (1.0 / samples_) : Vec3{};
}

CoupledWorld::Pose CoupledWorld::pose_of(const CoupledBody& b) const
{
    Pose p;
    rigid_.part_pose(b.body, p.rotation, p.origin_m);
    p.centre_m = rigid_.state(b.body).position_m;
    return p;
}

void CoupledWorld::check_pairs() const
{
    std::set<dem::MaterialIndex> present(dem_.particles().material.begin(), dem_.particles().material.end());
    const dem::MaterialTable& table = dem_.materials();
    for (std::size_t k = checked_bodies_; k < bodies_.size(); ++k) {
        const dem::MaterialIndex wall_material = dem_.mesh_wall(bodies_[k].wall).material();
        for (dem::MaterialIndex m : present)
            if (!table.has_pair(m, wall_material))
                throw InputError(concat("coupled body '", rigid_.body_name(bodies_[k].body), "' (DEM material '",
                                        table.material(wall_material).name, "') and spheres of material '",
                                        table.material(m).name, "': no contact coefficients for this pair; set them with "
                                        "MaterialTable::set_pair (or the scenario's pairs)"));
    }
}

void CoupledWorld::start()
{
    const double dt = dem_.step_s();
    if (!(dt > 0.0)) throw InputError("coupling: the DEM has no time step yet (no particles and step_s = 0)");
    // the reaction of the initial state is the first one Bullet receives
    dem_.prepare();
    for (std::size_t k = 0; k < bodies_.size(); ++k) {
        force_sum_[k] = dem_.wall_force_N(bodies_[k].wall);
        torque_sum_[k] = dem_.wall_torque_N_m(bodies_[k].wall);
    }
    samples_ = 1;
    initial_reaction_ = true;
    started_ = true;
}

void CoupledWorld::move_surfaces(double fraction, double interval_s)
{
    for_each_body(bodies_.size(), dem_.threads(), [&](std::size_t k) {
        const Pose& a = before_[k];
        const Pose& b = after_[k];
        const Vec3 spin = spin_rad_[k];
        RockResponse& r = response_[k];
        const bool responding = r.velocity_m_per_s != Vec3{} || r.angular_velocity_rad_per_s != Vec3{} ||
                                r.displacement_m != Vec3{} || r.turn_rad != Vec3{};
        if (spin == Vec3{} && a.centre_m == b.centre_m && a.origin_m == b.origin_m && !responding) {
            // a fixed part, a frozen rock or one at rest: place it once, at rest, and leave it (no vertex work, no
            // neighbour-list churn)
            const dem::MeshWall& wall = dem_.mesh_wall(bodies_[k].wall);
            if (wall.velocity_at(wall.reference_point_m()) == Vec3{} && wall.angular_velocity_rad_per_s() == Vec3{} &&
                wall.translation_m() == b.origin_m)
                return;
        }
        const double angle = norm(spin);
        Mat3 turn = angle > 0.0 ? rotation_about_axis(spin * (1.0 / angle), angle * fraction) : Mat3::identity();
        Vec3 centre = a.centre_m + (b.centre_m - a.centre_m) * fraction;
        Vec3 velocity = (b.centre_m - a.centre_m) * (1.0 / interval_s), angular_velocity = spin * (1.0 / interval_s);
        if (responding) {
            // the spheres' own motion of the rock since Bullet's step, drifted over this sub-step, on top
            const double dt = dem_.step_s();
            r.displacement_m += r.velocity_m_per_s * dt;
            r.turn_rad += r.angular_velocity_rad_per_s * dt;
            turn = rotation_of(r.turn_rad) * turn;
            centre += r.displacement_m;
            velocity += r.velocity_m_per_s;
            angular_velocity += r.angular_velocity_rad_per_s;
        }
        dem_.set_mesh_pose(bodies_[k].wall, turn * a.rotation, centre + turn * (a.origin_m - a.centre_m), centre, velocity,
                           angular_velocity);
    });
}

void CoupledWorld::watch_for_runaways()
{
    // Each rock's velocity change over the coupling step just done, as a 6-vector in m/s (the angular part in
    // the principal frame, times the radius of gyration: its kinetic energy weighs as the linear part's). A
    // streak counts the steps in a row in which the change turned by more than 120 degrees and grew.
    bool caught = false;
    for (std::size_t k = 0; k < bodies_.size(); ++k) {
        Watch& w = watch_[k];
        if (w.radius_of_gyration_m == Vec3{}) continue;
        const rigid::BodyState s = rigid_.state(bodies_[k].body);
        const Vec3 change = s.velocity_m_per_s - w.velocity_m_per_s;
        const Vec3 turn = after_[k].rotation.transposed() * (s.angular_velocity_rad_per_s - w.angular_velocity_rad_per_s);
        const Vec3 angular_change{turn.x * w.radius_of_gyration_m.x, turn.y * w.radius_of_gyration_m.y, turn.z * w.radius_of_gyration_m.z};
        const double size = std::sqrt(norm_squared(change) + norm_squared(angular_change));
        const double before = std::sqrt(norm_squared(w.change_m_per_s) + norm_squared(w.angular_change_m_per_s));
        const double along = dot(change, w.change_m_per_s) + dot(angular_change, w.angular_change_m_per_s);
        if (before >= kRunawayFloor_m_per_s && size > before && along < -0.5 * size * before) {
            ++w.streak;
            w.growth *= size / before;
        } else {
            w.streak = 0;
            w.growth = 1.0;
        }
        if (w.streak >= kRunawayStreak && w.growth >= kRunawayGrowth) {
            caught = true;
            w.streak = 0;
            w.growth = 1.0;
        }
        w.velocity_m_per_s = s.velocity_m_per_s;
        w.angular_velocity_rad_per_s = s.angular_velocity_rad_per_s;
        w.change_m_per_s = change;
        w.angular_change_m_per_s = angular_change;
    }
    if (caught) {
        hold_steps_ = kRunawayHoldSteps;
        ++runaways_caught_;
    }
}

int CoupledWorld::begin_step()
{
    if (checked_bodies_ != bodies_.size()) {
        check_pairs();
        checked_bodies_ = bodies_.size();
    }
    if (!started_) start();
    // one exchange of all the coupling step's DEM steps, or, while the runaway guard holds, one per DEM step
    held_ = settings_.substeps > 1 && hold_steps_ > 0;
    return held_ ? 1 : settings_.substeps;
}

double CoupledWorld::send_reactions(int steps)
{
    // The body receives in full the impulse the spheres received in the last exchange's sub-steps, sum x dt,
    // spread over this exchange of steps x dt: the sub-steps' mean force when the two exchanges are equally
    // long, as they are except where the runaway guard starts or ends a hold. The first step holds the
    // initial state's force. (The per-body loops touch each body's own data and run on the DEM's threads.)
    const double scale = samples_ == 0 ? 0.0 : 1.0 / (initial_reaction_ ? samples_ : steps);
    initial_reaction_ = false;
    for_each_body(bodies_.size(), dem_.threads(), [&](std::size_t k) {
        CoupledBody& b = bodies_[k];
        b.applied_force_N = force_sum_[k] * scale;
        b.applied_torque_N_m = torque_sum_[k] * scale;
        if (b.dynamic && !responds_at_dem_rate(k)) rigid_.apply_force_and_torque(b.body, b.applied_force_N, b.applied_torque_N_m);
        before_[k] = pose_of(b);
        force_sum_[k] = Vec3{};
        torque_sum_[k] = Vec3{};
    });
    samples_ = 0;
    return dem_.step_s() * steps;
}

void CoupledWorld::step_rigid(double step_s)
{
    const auto mark = std::chrono::steady_clock::now();
    rigid_.step(step_s);
    rigid_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - mark).count();
}

void CoupledWorld::run_dem(int steps, double interval_s)
{
    // the surfaces' poses at both ends of Bullet's step
    for_each_body(bodies_.size(), dem_.threads(), [&](std::size_t k) {
        after_[k] = pose_of(bodies_[k]);
        spin_rad_[k] = rotation_vector(after_[k].rotation * before_[k].rotation.transposed());
    });
    if (settings_.rock_exchange == RockExchange::dem_step) start_responses();
    // the DEM sub-steps, the surfaces moving from the old poses to the new ones, the reactions summed
    dem::World::StepHooks hooks;
    hooks.before_forces = [&](std::uint64_t s) {
        const auto start = std::chrono::steady_clock::now();
        move_surfaces(static_cast<double>(s + 1) / steps, interval_s);
        surface_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    hooks.after_forces = [&](std::uint64_t) {
        // a few additions per body: on one thread, cheaper than waking the others
        const std::vector<Vec3>& force = dem_.wall_forces_N();
        const std::vector<Vec3>& torque = dem_.wall_torques_N_m();
        for (std::size_t k = 0; k < bodies_.size(); ++k) {
            const auto w = static_cast<std::size_t>(bodies_[k].wall);
            force_sum_[k] += force[w];
            torque_sum_[k] += torque[w];
            RockResponse& r = response_[k];
            if (r.inverse_mass > 0.0) {  // the rock takes the sub-step's impulse at once (semi-implicit Euler)
                const double dt = dem_.step_s();
                r.velocity_m_per_s += force[w] * (r.inverse_mass * dt);
                r.angular_velocity_rad_per_s += r.inverse_inertia * (torque[w] * dt);
            }
        }
        ++samples_;
    };
    dem_.run_steps(static_cast<std::uint64_t>(steps), hooks);
    if (settings_.rock_exchange == RockExchange::dem_step) hand_responses_to_rigid();
}

bool CoupledWorld::responds_at_dem_rate(std::size_t k) const
{
    // rocks are the coupled bodies with a radius of gyration (add_rock)
    return settings_.rock_exchange == RockExchange::dem_step && watch_[k].radius_of_gyration_m != Vec3{};
}

void CoupledWorld::start_responses()
{
    for_each_body(bodies_.size(), dem_.threads(), [&](std::size_t k) {
        RockResponse& r = response_[k];
        r = RockResponse{};
        if (!responds_at_dem_rate(k) || rigid_.frozen(bodies_[k].body)) return;  // a frozen rock is held: no response
        const double mass = rigid_.mass_kg(bodies_[k].body);
        const Vec3 g = watch_[k].radius_of_gyration_m;  // principal moments m g^2
        Mat3 inverse_principal;
        inverse_principal.m[0][0] = 1.0 / (mass * g.x * g.x);
        inverse_principal.m[1][1] = 1.0 / (mass * g.y * g.y);
        inverse_principal.m[2][2] = 1.0 / (mass * g.z * g.z);
        const Mat3& rotation = after_[k].rotation;  // a rock's part frame is its principal frame
        r.inverse_inertia = rotation * inverse_principal * rotation.transposed();
        r.inverse_mass = 1.0 / mass;
    });
}

void CoupledWorld::hand_responses_to_rigid()
{
    for_each_body(bodies_.size(), dem_.threads(), [&](std::size_t k) {
        RockResponse& r = response_[k];
        if (r.inverse_mass == 0.0) return;
        rigid::BodyState s = rigid_.state(bodies_[k].body);
        s.position_m += r.displacement_m;
        s.rotation = rotation_of(r.turn_rad) * s.rotation;
        s.velocity_m_per_s += r.velocity_m_per_s;
        s.angular_velocity_rad_per_s += r.angular_velocity_rad_per_s;
        rigid_.set_rock_motion(bodies_[k].body, s);
        r = RockResponse{};
    });
}

void CoupledWorld::end_step()
{
    const int n = settings_.substeps;
    if (held_) {
        --hold_steps_;
        ++guarded_steps_;
    }
    if (n > 1 && settings_.runaway_guard) watch_for_runaways();
}

void CoupledWorld::step()
{
    const int steps = begin_step();
    for (int e = 0; e < settings_.substeps / steps; ++e) {
        const double interval = send_reactions(steps);
        step_rigid(interval);
        run_dem(steps, interval);
    }
    end_step();
}

void CoupledWorld::run_steps(std::uint64_t n)
{
    for (std::uint64_t s = 0; s < n; ++s) step();
}

Vec3 CoupledWorld::linear_momentum_kg_m_per_s() const
{
    return dem_.linear_momentum_kg_m_per_s() + rigid_.linear_momentum_kg_m_per_s();
}

Vec3 CoupledWorld::angular_momentum_kg_m2_per_s() const
{
    return dem_.angular_momentum_kg_m2_per_s() + rigid_.angular_momentum_kg_m2_per_s();
}

double CoupledWorld::kinetic_energy_J() const
{
    return dem_.kinetic_energy_J() + rigid_.kinetic_energy_J();
}

}  // namespace dipper::coupling
