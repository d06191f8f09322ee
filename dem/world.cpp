#include "dem/world.h"

#include "core/errors.h"
#include "dem/pair_batch.h"

#include <algorithm>
#include <chrono>
#include <cctype>
#include <cmath>
#include <limits>
#include <numeric>
#include <omp.h>

namespace dipper::dem {

World::World(MaterialTable materials, WorldSettings settings) : materials_(std::move(materials)), settings_(settings)
{
    const std::string at = "WorldSettings";
    if (!is_finite(settings_.gravity_m_per_s2)) throw InputError("gravity_m_per_s2 must be finite (WorldSettings)");
    require_non_negative(settings_.step_s, "step_s", at);
    require_positive(settings_.skin_fraction_of_radius, "skin_fraction_of_radius", at);
    require_in_range(settings_.max_overlap_ratio, 1e-6, 1.0, "max_overlap_ratio", at);
    require_in_range(settings_.initial_overlap_tolerance, 0.0, 1.0, "initial_overlap_tolerance", at);
    if (settings_.threads < 0 || settings_.threads > 1024)
        throw InputError(concat("threads must be 0 (all cores) to 1024; got ", settings_.threads, " (", at, ")"));
    threads_ = settings_.threads > 0 ? settings_.threads : omp_get_max_threads();
    for (std::size_t m = 0; m < materials_.size(); ++m)
        bulk_modulus_Pa_.push_back(materials_.material(static_cast<MaterialIndex>(m)).is_surface
                                       ? 0.0
                                       : materials_.material(static_cast<MaterialIndex>(m)).bulk_modulus_Pa());
    thread_wall_contacts_.resize(static_cast<std::size_t>(threads_));
    thread_wall_hits_.resize(static_cast<std::size_t>(threads_));
}

std::uint32_t World::add_particle(const ParticleSpawn& spawn, const std::string& where)
{
    const std::uint32_t id = particles_.add(spawn, materials_, where);
    // until its first force evaluation, a particle added during a run feels gravity only
    particles_.force_N.back() = settings_.gravity_m_per_s2 * particles_.mass_kg.back();
    rebuild_needed_ = true;
    step_checked_ = false;
    return id;
}

void World::check_wall_name(const std::string& name) const
{
    // names become column headers and file names: letters, digits, '_', '-', '.'
    const bool plain = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
    });
    if (!plain)
        throw InputError(concat("wall name '", name, "' must be non-empty and use only letters, digits, '_', '-' and '.'"));
    if (wall_names_.count(name)) throw InputError(concat("wall name '", name, "' is used twice"));
}

int World::add_plane(const Vec3& point_m, const Vec3& normal, MaterialIndex material, const std::string& name)
{
    check_wall_name(name);
    const std::string at = "plane '" + name + "'";
    if (!is_finite(point_m) || !is_finite(normal) || norm(normal) < 1e-12)
        throw InputError(concat("plane point and normal must be finite and the normal non-zero (", at, ")"));
    if (material >= materials_.size())
        throw InputError(concat("material index ", material, " does not exist (", at, ")"));
    planes_.push_back({point_m, normalized(normal), material, name});
    plane_offset_m_.push_back(dot(planes_.back().point_m, planes_.back().normal));
    walls_.push_back({false, static_cast<int>(planes_.size() - 1)});
    wall_names_.insert(name);
    plane_wall_id_.push_back(static_cast<std::int32_t>(walls_.size() - 1));
    wall_force_N_.resize(walls_.size());
    wall_torque_N_m_.resize(walls_.size());
    wall_removed_.push_back(0);
    wall_frozen_.push_back(0);
    rebuild_needed_ = true;
    step_checked_ = false;
    return static_cast<int>(walls_.size() - 1);
}

void World::set_frozen(std::size_t i, bool frozen)
{
    if (i >= particles_.size()) throw InputError(concat("set_frozen: particle index ", i, " of ", particles_.size()));
    if (particles_.frozen[i] != (frozen ? 1 : 0)) ++frozen_version_;
    particles_.frozen[i] = frozen ? 1 : 0;
    if (!frozen) return;
    particles_.velocity_m_per_s[i] = Vec3{};
    particles_.angular_velocity_rad_per_s[i] = Vec3{};
    particles_.force_N[i] = Vec3{};
    particles_.torque_N_m[i] = Vec3{};
}

void World::set_wall_frozen(int wall_id, bool frozen)
{
    if (!is_mesh(wall_id) || !mesh_wall(wall_id).convex())
        throw InputError(concat("set_wall_frozen: wall ", wall_id, " is not a convex mesh"));
    const auto w = static_cast<std::size_t>(wall_id);
    if (wall_frozen_[w] == (frozen ? 1 : 0)) return;
    wall_frozen_[w] = frozen ? 1 : 0;
    ++frozen_version_;
    mesh_moved_[static_cast<std::size_t>(walls_[w].index)] = 1;  // its frame is made again with the flag
}

bool World::wall_frozen(int wall_id) const
{
    wall_name(wall_id);  // checks the id
    return wall_frozen_[static_cast<std::size_t>(wall_id)] != 0;
}

std::size_t World::frozen_count() const
{
    return static_cast<std::size_t>(std::count(particles_.frozen.begin(), particles_.frozen.end(), std::uint8_t{1}));
}

void World::remove_wall(int wall_id)
{
    is_mesh(wall_id);  // validates the id
    if (wall_removed_[static_cast<std::size_t>(wall_id)]) return;
    wall_removed_[static_cast<std::size_t>(wall_id)] = 1;
    rebuild_needed_ = true;  // its candidates go with the next step's rebuild, and with them its contacts
}

bool World::wall_removed(int wall_id) const
{
    is_mesh(wall_id);
    return wall_removed_[static_cast<std::size_t>(wall_id)] != 0;
}

int World::add_mesh(meshes::TriangleMesh mesh, MaterialIndex material, const std::string& name,
                    std::optional<PrescribedMotion> motion)
{
    check_wall_name(name);
    if (material >= materials_.size())
        throw InputError(concat("material index ", material, " does not exist (mesh '", name, "')"));
    if (motion && !(is_finite(motion->velocity_m_per_s) && is_finite(motion->angular_velocity_rad_per_s) &&
                    is_finite(motion->pivot_m) && is_finite(motion->oscillation_amplitude_m) &&
                    std::isfinite(motion->oscillation_frequency_Hz)))
        throw InputError(concat("prescribed motion of mesh '", name, "' must be finite"));
    if (motion && !(motion->start_s >= 0.0 && std::isfinite(motion->start_s) && motion->end_s > motion->start_s))
        throw InputError(concat("prescribed motion of mesh '", name, "' runs from ", motion->start_s, " s to ", motion->end_s,
                                " s; expected a finite start >= 0 and an end after it"));
    meshes_.emplace_back(std::move(mesh), material, name, motion);
    if (motion) {
        // place the mesh at the current time
        Mat3 r;
        Vec3 t;
        motion->pose(time_s_, r, t);
        meshes_.back().set_pose(r, t, motion->pivot_position_m(time_s_), motion->pivot_velocity_m_per_s(time_s_),
                                motion->angular_velocity_at(time_s_));
    }
    walls_.push_back({true, static_cast<int>(meshes_.size() - 1)});
    wall_names_.insert(name);
    mesh_wall_id_.push_back(static_cast<std::int32_t>(walls_.size() - 1));
    mesh_moved_.push_back(1);
    wall_force_N_.resize(walls_.size());
    wall_torque_N_m_.resize(walls_.size());
    wall_removed_.push_back(0);
    wall_frozen_.push_back(0);
    rebuild_needed_ = true;
    step_checked_ = false;
    return static_cast<int>(walls_.size() - 1);
}

void World::set_mesh_pose(int wall_id, const Mat3& rotation, const Vec3& translation_m, const Vec3& reference_point_m,
                          const Vec3& reference_velocity_m_per_s, const Vec3& angular_velocity_rad_per_s)
{
    if (!is_mesh(wall_id)) throw InputError(concat("wall ", wall_id, " is not a mesh wall"));
    const auto m = static_cast<std::size_t>(walls_[static_cast<std::size_t>(wall_id)].index);
    meshes_[m].set_pose(rotation, translation_m, reference_point_m, reference_velocity_m_per_s, angular_velocity_rad_per_s);
    mesh_moved_[m] = 1;
}

bool World::is_mesh(int wall_id) const
{
    if (wall_id < 0 || static_cast<std::size_t>(wall_id) >= walls_.size())
        throw InputError(concat("wall id ", wall_id, " does not exist; the world has ", walls_.size(), " walls"));
    return walls_[static_cast<std::size_t>(wall_id)].is_mesh;
}

const MeshWall& World::mesh_wall(int wall_id) const
{
    if (!is_mesh(wall_id)) throw InputError(concat("wall ", wall_id, " is not a mesh wall"));
    return meshes_[static_cast<std::size_t>(walls_[static_cast<std::size_t>(wall_id)].index)];
}

const PlaneWall& World::plane_wall(int wall_id) const
{
    if (is_mesh(wall_id)) throw InputError(concat("wall ", wall_id, " is not a plane"));
    return planes_[static_cast<std::size_t>(walls_[static_cast<std::size_t>(wall_id)].index)];
}

const std::string& World::wall_name(int wall_id) const
{
    return is_mesh(wall_id) ? mesh_wall(wall_id).name() : plane_wall(wall_id).name;
}

Vec3 World::wall_force_N(int wall_id) const
{
    is_mesh(wall_id);  // validates the id
    return wall_force_N_[static_cast<std::size_t>(wall_id)];
}

Vec3 World::wall_torque_N_m(int wall_id) const
{
    is_mesh(wall_id);
    return wall_torque_N_m_[static_cast<std::size_t>(wall_id)];
}

void World::set_contact_consumer(ContactConsumer consumer, const std::vector<int>& walls)
{
    consumer_walls_ = wall_flags(walls, "set_contact_consumer");
    consumer_ = std::move(consumer);
}

void World::set_wall_mass_kg(int wall_id, double mass_kg)
{
    if (!is_mesh(wall_id)) throw InputError(concat("set_wall_mass_kg: wall '", wall_name(wall_id), "' is a plane, which is immovable"));
    const auto m = static_cast<std::size_t>(walls_[static_cast<std::size_t>(wall_id)].index);
    meshes_[m].set_mass_kg(mass_kg);
    mesh_moved_[m] = 1;
    convex_.forget_constants();
}

void World::sum_wall_reactions()
{
    // each thread summed its contacts in list order (compute_wall_contacts); the threads' sums are added
    // in thread order, so the totals are deterministic for a thread count (and the list-order sums on one)
    for (std::size_t w = 0; w < walls_.size(); ++w) {
        Vec3 force = thread_wall_force_N_[0][w], torque = thread_wall_torque_N_m_[0][w];
        for (std::size_t t = 1; t < thread_wall_force_N_.size(); ++t) {
            force += thread_wall_force_N_[t][w];
            torque += thread_wall_torque_N_m_[t][w];
        }
        wall_force_N_[w] = force;
        wall_torque_N_m_[w] = torque;
    }
}

// ---- stepping ------------------------------------------------------------------------------------

void World::prepare()
{
    if (!step_checked_) validate_step();
    if (!prepared_) {
        rebuild();
        check_initial_overlaps();
        // velocity Verlet starts from the forces of the initial state; a zero-length step leaves the
        // contact springs where they are
        evaluate_forces(0.0, 0.0);
        sum_wall_reactions();
        prepared_ = true;
    }
}

namespace {
double seconds_since(std::chrono::steady_clock::time_point& mark)
{
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - mark).count();
    mark = now;
    return s;
}
}  // namespace

void World::evaluate_forces(double dt_s, double half_kick_s)
{
    auto mark = std::chrono::steady_clock::now();
    max_overlap_ratio_ = pairs_.compute_forces(particles_, stiffness_radius_N_per_m_, materials_, dt_s, threads_, frozen_version_);
    phase_seconds_.pair_forces += seconds_since(mark);
    compute_wall_contacts(dt_s);
    phase_seconds_.wall_forces += seconds_since(mark);
    gather_forces_and_kick(half_kick_s, false);
    phase_seconds_.integration += seconds_since(mark);
}

void World::step()
{
    run_steps(1);
}

void World::run_steps(std::uint64_t n, const StepHooks& hooks)
{
    if (n == 0) return;
    prepare();
    const double dt = step_s_;
    if (!(dt > 0.0)) throw InputError("the world has no particles to derive a time step from and step_s is 0");

    auto mark = std::chrono::steady_clock::now();
    // first half kick with last step's forces, then drift (velocity Verlet); the largest move since the
    // last neighbour-list rebuild comes along
    double max_move2 = kick_and_drift(dt);
    phase_seconds_.integration += seconds_since(mark);

    for (std::uint64_t s = 0; s < n; ++s) {
        if (hooks.before_forces) hooks.before_forces(s);
        mark = std::chrono::steady_clock::now();
        // moving walls to the end of the step, their velocities at mid-step
        move_prescribed_meshes(time_s_ + dt, dt);
        phase_seconds_.integration += seconds_since(mark);

        // neighbour lists, rebuilt when a particle or a wall has used up the skin
        const bool tracked = reference_position_m_.size() == particles_.size();
        if (rebuild_needed_ || !tracked || needs_rebuild(std::sqrt(max_move2))) rebuild();
        phase_seconds_.neighbour_search += seconds_since(mark);

        // forces: sphere pairs into per-thread arrays, wall contacts per particle
        max_overlap_ratio_ = pairs_.compute_forces(particles_, stiffness_radius_N_per_m_, materials_, dt, threads_, frozen_version_);
        phase_seconds_.pair_forces += seconds_since(mark);
        compute_wall_contacts(dt);
        phase_seconds_.wall_forces += seconds_since(mark);

        // the step's wall reactions and contact records depend on the wall contacts alone
        finish_step(dt);
        phase_seconds_.integration += seconds_since(mark);
        if (hooks.after_forces) hooks.after_forces(s);

        // per particle the sum of its forces and the second half kick; between two steps of this call,
        // the next step's first half kick and drift in the same pass (the same operations in the same
        // order as two passes, so the same bits)
        if (s + 1 < n)
            max_move2 = gather_forces_and_kick(0.5 * dt, true);
        else
            gather_forces_and_kick(0.5 * dt, false);
        phase_seconds_.integration += seconds_since(mark);
    }
}

double World::kick_and_drift(double dt_s)
{
    const std::size_t n = particles_.size();
    auto& x = particles_.position_m;
    auto& v = particles_.velocity_m_per_s;
    auto& w = particles_.angular_velocity_rad_per_s;
    const bool tracked = reference_position_m_.size() == n;
    const Vec3* reference = reference_position_m_.data();
    const std::uint8_t* frozen = particles_.frozen.data();
    double max_move2 = 0.0;
#pragma omp parallel for schedule(static) num_threads(threads_) reduction(max : max_move2)
    for (std::size_t i = 0; i < n; ++i) {
        if (frozen[i]) continue;
        v[i] += particles_.force_N[i] * (0.5 * dt_s * particles_.inverse_mass_per_kg[i]);
        w[i] += particles_.torque_N_m[i] * (0.5 * dt_s * particles_.inverse_inertia_per_kg_m2[i]);
        x[i] += v[i] * dt_s;
        if (tracked) max_move2 = std::max(max_move2, norm_squared(x[i] - reference[i]));
    }
    return max_move2;
}

void World::move_prescribed_meshes(double t_end_s, double dt_s)
{
    for (std::size_t q = 0; q < meshes_.size(); ++q) {
        MeshWall& m = meshes_[q];
        if (!m.motion()) continue;
        mesh_moved_[q] = 1;
        const PrescribedMotion& motion = *m.motion();
        Mat3 r;
        Vec3 t;
        motion.pose(t_end_s, r, t);
        // the rigid velocity field at mid-step, referred to the pivot's position at the end of the step
        const Vec3 mid_velocity = motion.pivot_velocity_m_per_s(t_end_s - 0.5 * dt_s);
        m.set_pose(r, t, motion.pivot_position_m(t_end_s), mid_velocity, motion.angular_velocity_at(t_end_s - 0.5 * dt_s));
    }
}

void World::finish_step(double dt_s)
{
    time_s_ += dt_s;
    ++step_count_;

    sum_wall_reactions();

    if (consumer_) {
        records_of(consumer_walls_, consumer_records_);
        consumer_(consumer_records_, time_s_, dt_s);
    }

    // the first wall contact (in list order) past the overlap limit, found by the wall phase
    std::size_t first = kNoContact, first_convex = kNoContact;
    for (std::size_t f : thread_first_deep_contact_) first = std::min(first, f);
    for (std::size_t f : thread_first_deep_convex_) first_convex = std::min(first_convex, f);
    if (first != kNoContact || first_convex != kNoContact) {
        const WallContact& c = first != kNoContact ? wall_contacts_[first] : convex_.contact(first_convex);
        const double ratio = c.overlap_m / particles_.radius_m[c.particle];
        const Vec3 p = particles_.position_m[c.particle];
        const WallMotion& wall = wall_motion_[static_cast<std::size_t>(c.wall)];
        // For a wall with a body behind it, the body's mass and speed there let the user tell a runaway body from a
        // fast sphere: a light body answering its sphere contacts late (several DEM steps per rigid-body step) can
        // pump energy into them.
        const std::string body = wall.mass_kg > 0.0
            ? concat("; the body behind the wall (", wall.mass_kg, " kg) moves at ", norm(wall.velocity_at(c.point)),
                     " m/s there: if that is far faster than anything drives it, the body has run away (a light body"
                     " coupled with several DEM steps per rigid-body step can, against stiff sphere contacts): the runaway"
                     " guard (CouplingSettings::runaway_guard) or fewer DEM steps per rigid-body step (CouplingSettings::substeps) keep it stable")
            : "";
        throw SimulationError(concat(where_in_time(), ": particle ", particles_.id[c.particle], " overlaps wall '",
                                     wall_name(c.wall), "'", c.triangle >= 0 ? concat(" (triangle ", c.triangle, ")") : "",
                                     " by ", ratio, " of its radius (limit ", settings_.max_overlap_ratio, ") at (",
                                     p.x, ", ", p.y, ", ", p.z, "), speed ", norm(particles_.velocity_m_per_s[c.particle]),
                                     " m/s; step_s = ", step_s_, " s (stable limit ", stable_step_limit_s(),
                                     " s): reduce WorldSettings::step_s, e.g. to ", 0.5 * step_s_, " s, or slow the wall", body));
    }
    if (max_overlap_ratio_ > settings_.max_overlap_ratio) fail_overlap();
}

std::string World::where_in_time() const
{
    return concat("step ", step_count_, " (t=", time_s_, " s)");
}

// ---- forces --------------------------------------------------------------------------------------

void World::find_wall_contacts(std::uint32_t i, double dt_s, std::vector<WallHit>& hits, std::vector<WallContact>& out) const
{
    const Vec3 x = particles_.position_m[i];
    const double r = particles_.radius_m[i];
    candidates_.touching(i, x, r, wall_set(), hits);
    if (hits.empty()) return;

    // forces, with history matched to last step's contact of the same wall whose normal is closest
    const std::uint32_t old_begin = i < wall_contact_start_.size() - 1 ? wall_contact_start_[i] : 0;
    const std::uint32_t old_end = i < wall_contact_start_.size() - 1 ? wall_contact_start_[i + 1] : 0;
    std::uint32_t used = 0;  // bit k: last step's contact k of this particle has been matched
    const Vec3 v = particles_.velocity_m_per_s[i];
    const Vec3 w = particles_.angular_velocity_rad_per_s[i];
    for (const WallHit& h : hits) {
        if (!h.keep) continue;
        WallContact& c = out.emplace_back();  // filled in place: a contact is some 200 bytes
        c.particle = i;
        c.wall = h.wall;
        c.triangle = h.triangle;
        c.normal = h.normal;
        c.point = h.point;
        c.overlap_m = h.overlap;
        c.first_step = true;
        int best = -1;
        double best_dot = 0.9;  // within about 25 degrees: the same contact moving over the surface
        for (std::uint32_t o = old_begin; o < old_end; ++o) {
            const WallContact& old = wall_contacts_[o];
            const int slot = static_cast<int>(o - old_begin);
            if (old.wall != h.wall || slot >= 32 || (used >> slot) & 1u) continue;
            const double d = dot(old.normal, h.normal);
            if (d > best_dot) { best_dot = d; best = slot; }
        }
        if (best >= 0) {
            used |= 1u << best;
            c.history = wall_contacts_[old_begin + static_cast<std::uint32_t>(best)].history;
            c.first_step = false;
        }

        apply_wall_law(c, x, v, w, r, dt_s);
    }
}

void World::apply_wall_law(WallContact& c, const Vec3& x, const Vec3& v, const Vec3& w, double r, double dt_s) const
{
    const std::uint32_t i = c.particle;
    const WallMotion& wall = wall_motion_[static_cast<std::size_t>(c.wall)];
    const PairCoefficients& p = materials_.pair_unchecked(particles_.material[i], wall.material);
    const Vec3 arm = c.point - x;
    ContactState s;
    s.overlap_m = c.overlap_m;
    s.normal = c.normal;
    s.relative_velocity_m_per_s = v + cross(w, arm) - wall.velocity_at(c.point);
    s.relative_angular_velocity_rad_per_s = w - wall.angular_velocity_rad_per_s;
    s.effective_radius_m = r;
    s.effective_mass_kg = wall.mass_kg > 0.0 ? particles_.mass_kg[i] * wall.mass_kg / (particles_.mass_kg[i] + wall.mass_kg)
                                             : particles_.mass_kg[i];
    s.normal_stiffness_N_per_m = wall_normal_stiffness(bulk_modulus_Pa_[particles_.material[i]], r, p.normal_stiffness_scale);
    c.forces = linear_spring_dashpot(s, law_coefficients(p, materials_.rolling_resistance()), c.history, dt_s);
    c.relative_displacement_m = s.relative_velocity_m_per_s * dt_s;
}

void World::wall_thread_block(int t, std::size_t& begin, std::size_t& end) const
{
    // Blocks of particles with equal work: a wall candidate weighs as much as kCandidateWeight particles
    // without one (the candidates sit at the bottom and the sides of a bed, so equal particle counts
    // would give one thread most of the work). Bounds from the candidates' prefix sum by bisection.
    const std::size_t n = particles_.size();
    if (!candidates_.lists_for(n)) {
        thread_block(n, t, threads_, begin, end);
        return;
    }
    constexpr std::size_t kCandidateWeight = 16;
    auto weight = [&](std::size_t i) { return i + kCandidateWeight * candidates_.first(i); };
    const std::size_t total = weight(n);
    auto bound = [&](int q) {
        const std::size_t target = total * static_cast<std::size_t>(q) / static_cast<std::size_t>(threads_);
        std::size_t lo = 0, hi = n;  // the first i with weight(i) >= target
        while (lo < hi) {
            const std::size_t mid = lo + (hi - lo) / 2;
            if (weight(mid) < target) lo = mid + 1;
            else hi = mid;
        }
        return lo;
    };
    begin = t == 0 ? 0 : bound(t);
    end = t + 1 == threads_ ? n : bound(t + 1);
}

void World::compute_wall_contacts(double dt_s)
{
    const std::size_t n = particles_.size();
    const bool any_wall = !walls_.empty();
    // the small records of the walls: the planes' here, the meshes' at the start of the parallel part
    wall_motion_.resize(walls_.size());
    for (std::size_t q = 0; q < planes_.size(); ++q)
        wall_motion_[static_cast<std::size_t>(plane_wall_id_[q])] = {Vec3{}, Vec3{}, Vec3{}, 0.0, planes_[q].material};
    convex_frames_.resize(meshes_.size());
    const auto mesh_count = static_cast<std::ptrdiff_t>(meshes_.size());
    std::size_t convex_touching = 0;
    thread_wall_force_N_.resize(static_cast<std::size_t>(threads_));
    thread_wall_torque_N_m_.resize(static_cast<std::size_t>(threads_));
    for (std::size_t q = 0; q < static_cast<std::size_t>(threads_); ++q) {
        thread_wall_force_N_[q].resize(walls_.size());
        thread_wall_torque_N_m_[q].resize(walls_.size());
    }
    thread_first_deep_contact_.assign(static_cast<std::size_t>(threads_), kNoContact);
    thread_first_deep_convex_.assign(static_cast<std::size_t>(threads_), kNoContact);
    thread_convex_seconds_.assign(static_cast<std::size_t>(threads_), 0.0);
    convex_.start_step(threads_);
    convex_.update_live(particles_.frozen, wall_frozen_, mesh_wall_id_, frozen_version_);
    convex_touching = convex_.frozen_touching();
#pragma omp parallel num_threads(threads_) reduction(+ : convex_touching)
    {
        // the records of the meshes moved (or given a mass) since the last wall phase: in a coupled bed every rock
        // moves at every step, a thousand records (the loop's end waits for all of them)
#pragma omp for schedule(static)
        for (std::ptrdiff_t q = 0; q < mesh_count; ++q) {
            const auto m = static_cast<std::size_t>(q);
            if (!mesh_moved_[m]) continue;
            mesh_moved_[m] = 0;
            const MeshWall& mw = meshes_[m];
            const auto w = static_cast<std::size_t>(mesh_wall_id_[m]);
            wall_motion_[w] = {mw.reference_point_m(), mw.reference_velocity_m_per_s(), mw.angular_velocity_rad_per_s(), mw.mass_kg(), mw.material()};
            if (mw.convex())
                convex_frames_[m] = {mw.rotation().transposed(), mw.translation_m(), mw.convex_slack_m(), mesh_wall_id_[m], wall_frozen_[w],
                                     wall_motion_[w]};
        }
        const int t = omp_get_thread_num();
        std::size_t begin, end;
        wall_thread_block(t, begin, end);
        // the thread's share of each wall's reaction, summed after the barrier: a convex body's from the thread's
        // share of the pairs, the others' from the thread's contacts (no wall has both)
        Vec3* __restrict wall_force = thread_wall_force_N_[static_cast<std::size_t>(t)].data();
        Vec3* __restrict wall_torque = thread_wall_torque_N_m_[static_cast<std::size_t>(t)].data();
        std::fill(wall_force, wall_force + walls_.size(), Vec3{});
        std::fill(wall_torque, wall_torque + walls_.size(), Vec3{});
        // the thread's vectors are moved into locals while it fills them: their headers sit side by side in
        // one cache line, and a push_back into the shared arrays would bounce that line between the cores
        std::vector<WallContact> out = std::move(thread_wall_contacts_[static_cast<std::size_t>(t)]);
        std::vector<WallHit> hits = std::move(thread_wall_hits_[static_cast<std::size_t>(t)]);
        out.clear();
        if (any_wall) {  // only the thread's particles with a plane or an open mesh within reach can touch one
            const auto first = std::lower_bound(candidates_.particles().begin(), candidates_.particles().end(), begin);
            const auto last = std::lower_bound(first, candidates_.particles().end(), end);
            for (auto i = first; i != last; ++i) find_wall_contacts(*i, dt_s, hits, out);
        }
        // the spheres near convex bodies, in particle order: each pair's contact in its place
        std::size_t first_deep_convex = kNoContact;
        auto convex_start = std::chrono::steady_clock::now();
        const auto ut = static_cast<std::size_t>(t);
        convex_touching += convex_.compute(convex_.pass_begin(t), convex_.pass_end(t), particles_, convex_frames_, materials_, bulk_modulus_Pa_,
                                           settings_.max_overlap_ratio, dt_s, first_deep_convex, wall_force, wall_torque);
        thread_convex_seconds_[ut] = seconds_since(convex_start);
        thread_first_deep_convex_[ut] = first_deep_convex;

        // Last step's contacts have been read (their history): each thread's contacts, in particle order,
        // replace them at the thread's offset, and each thread indexes its own particles.
        thread_wall_hits_[static_cast<std::size_t>(t)] = std::move(hits);
        thread_wall_contacts_[static_cast<std::size_t>(t)] = std::move(out);
#pragma omp barrier
#pragma omp single
        {
            wall_contact_offset_.assign(static_cast<std::size_t>(threads_) + 1, 0);
            for (std::size_t q = 0; q < static_cast<std::size_t>(threads_); ++q)
                wall_contact_offset_[q + 1] = wall_contact_offset_[q] + thread_wall_contacts_[q].size();
            // one thread: its list becomes the step's as it is; more: each copies its list to its offset below
            if (threads_ == 1)
                wall_contacts_.swap(thread_wall_contacts_[0]);
            else
                wall_contacts_.resize(wall_contact_offset_.back());
            wall_contact_start_.resize(n + 1);
            wall_contact_start_[n] = static_cast<std::uint32_t>(wall_contacts_.size());
        }
        std::size_t k = wall_contact_offset_[static_cast<std::size_t>(t)];
        const auto& filled = threads_ == 1 ? wall_contacts_ : thread_wall_contacts_[static_cast<std::size_t>(t)];
        if (threads_ > 1) std::copy(filled.begin(), filled.end(), wall_contacts_.begin() + static_cast<std::ptrdiff_t>(k));
        // each particle's first contact: the contacts are in particle order, and a particle without one starts
        // where the next contact is
        const std::size_t k_end = wall_contact_offset_[static_cast<std::size_t>(t) + 1];
        std::size_t i = begin;
        for (; k < k_end; ++k)
            for (const std::size_t p = wall_contacts_[k].particle; i <= p; ++i) wall_contact_start_[i] = static_cast<std::uint32_t>(k);
        for (; i < end; ++i) wall_contact_start_[i] = static_cast<std::uint32_t>(k_end);

        // the reaction of the planes and open meshes, in list order, and the thread's first contact past the
        // overlap limit
        std::size_t first_deep = kNoContact;
        const std::size_t offset = wall_contact_offset_[static_cast<std::size_t>(t)];
        for (std::size_t q = 0; q < filled.size(); ++q) {
            const WallContact& c = filled[q];
            const auto w = static_cast<std::size_t>(c.wall);
            const Vec3 on_wall = -(c.normal * c.forces.normal_force_N + c.forces.tangential_force_N);
            wall_force[w] += on_wall;
            wall_torque[w] += cross(c.point - wall_motion_[w].reference_point_m, on_wall) - c.forces.rolling_torque_N_m;
            if (first_deep == kNoContact && c.overlap_m / particles_.radius_m[c.particle] > settings_.max_overlap_ratio)
                first_deep = offset + q;
        }
        thread_first_deep_contact_[static_cast<std::size_t>(t)] = first_deep;
    }
    convex_contact_count_ = convex_touching;
    phase_seconds_.convex_forces += *std::max_element(thread_convex_seconds_.begin(), thread_convex_seconds_.end());
    records_stale_ = true;
}

double World::gather_forces_and_kick(double half_kick_s, bool next_drift)
{
    const std::size_t n = particles_.size();
    const Vec3 g = settings_.gravity_m_per_s2;
    const double dt = 2.0 * half_kick_s;
    const bool tracked = next_drift && reference_position_m_.size() == n;
    const Vec3* reference = reference_position_m_.data();
    auto& x = particles_.position_m;
    auto& v = particles_.velocity_m_per_s;
    auto& w = particles_.angular_velocity_rad_per_s;
    const std::uint8_t* frozen = particles_.frozen.data();
    const bool own_spin = materials_.rolling_resistance() == RollingResistance::own_spin;
    double max_move2 = 0.0;
    int bad = -1;
#pragma omp parallel for schedule(static) num_threads(threads_) reduction(max : bad, max_move2)
    for (std::size_t i = 0; i < n; ++i) {
        Vec3 f = g * particles_.mass_kg[i];
        Vec3 torque{};
        double spin_resistance = 0.0;  // own_spin: the sum of mu_roll r Fn over the contacts
        if (own_spin) pairs_.take_spin_resistance(i, spin_resistance);
        pairs_.take(i, f, torque);
        if (frozen[i]) continue;  // at rest where it is (its share of the pairs' sums is cleared all the same)
        for (std::uint32_t k = wall_contact_start_[i]; k < wall_contact_start_[i + 1]; ++k) {
            const WallContact& c = wall_contacts_[k];
            const Vec3 force = c.normal * c.forces.normal_force_N + c.forces.tangential_force_N;
            f += force;
            torque += cross(c.point - x[i], force) + c.forces.rolling_torque_N_m;
            if (own_spin)
                spin_resistance += materials_.pair_unchecked(particles_.material[i], wall_motion_[static_cast<std::size_t>(c.wall)].material)
                                       .rolling_friction *
                                   particles_.radius_m[i] * c.forces.normal_force_N;
        }
        convex_.push(i, f, torque);
        if (own_spin) {
            convex_.push_spin_resistance(i, spin_resistance);
            torque += spin_resisting_torque(w[i], torque, spin_resistance, dt * particles_.inverse_inertia_per_kg_m2[i]);
        }
        if (!next_drift) {  // within a run of steps the force is used here and nowhere else
            particles_.force_N[i] = f;
            particles_.torque_N_m[i] = torque;
        }
        const Vec3 dv = f * (half_kick_s * particles_.inverse_mass_per_kg[i]);
        const Vec3 dw = torque * (half_kick_s * particles_.inverse_inertia_per_kg_m2[i]);
        v[i] += dv;
        w[i] += dw;
        if (!is_finite(f) || !is_finite(torque) || !is_finite(x[i])) bad = std::max(bad, static_cast<int>(i));
        if (next_drift) {
            // the next step's first half kick (the same force, the same factor) and drift
            v[i] += dv;
            w[i] += dw;
            x[i] += v[i] * dt;
            if (tracked) max_move2 = std::max(max_move2, norm_squared(x[i] - reference[i]));
        }
    }
    pairs_.gathered();
    if (bad >= 0) {
        const auto i = static_cast<std::size_t>(bad);
        throw SimulationError(concat(where_in_time(), ": particle ", particles_.id[i], " has a non-finite force or position (x = ",
                                     particles_.position_m[i].x, ", ", particles_.position_m[i].y, ", ",
                                     particles_.position_m[i].z, "); step_s = ", step_s_,
                                     " s; try step_s <= ", 0.5 * step_s_, " s (stable limit ", stable_step_limit_s(), " s)"));
    }
    return max_move2;
}

[[noreturn]] void World::fail_overlap() const
{
    // find the worst pair for the diagnosis
    std::size_t worst = 0;
    double worst_ratio = -1.0;
    for (std::size_t k = 0; k < pairs_.size(); ++k) {
        const std::uint32_t i = pairs_.first(k), j = pairs_.second(k);
        const double ov = particles_.radius_m[i] + particles_.radius_m[j] - norm(particles_.position_m[i] - particles_.position_m[j]);
        const double ratio = ov / std::min(particles_.radius_m[i], particles_.radius_m[j]);
        if (ratio > worst_ratio) { worst_ratio = ratio; worst = k; }
    }
    const std::uint32_t i = pairs_.first(worst), j = pairs_.second(worst);
    const Vec3 p = particles_.position_m[i];
    throw SimulationError(concat(where_in_time(), ": particles ", particles_.id[i], " and ", particles_.id[j],
                                 " overlap by ", worst_ratio, " of the smaller radius (limit ", settings_.max_overlap_ratio,
                                 ") near (", p.x, ", ", p.y, ", ", p.z, "); relative speed ",
                                 norm(particles_.velocity_m_per_s[i] - particles_.velocity_m_per_s[j]),
                                 " m/s; step_s = ", step_s_, " s (stable limit ", stable_step_limit_s(),
                                 " s): reduce WorldSettings::step_s, e.g. to ", 0.5 * step_s_, " s, or check for particles created inside each other"));
}

void World::check_initial_overlaps() const
{
    for (std::size_t k = 0; k < pairs_.size(); ++k) {
        const std::uint32_t i = pairs_.first(k), j = pairs_.second(k);
        const double smaller = std::min(particles_.radius_m[i], particles_.radius_m[j]);
        const double ov = particles_.radius_m[i] + particles_.radius_m[j] - norm(particles_.position_m[i] - particles_.position_m[j]);
        if (ov > settings_.initial_overlap_tolerance * smaller)
            throw InputError(concat("initial particles ", particles_.id[i], " and ", particles_.id[j], " overlap by ", ov,
                                    " m = ", ov / smaller, " of the smaller radius; at most ",
                                    settings_.initial_overlap_tolerance, " (initial_overlap_tolerance) is accepted"));
    }
}

}  // namespace dipper::dem
