// Spheres and rigid bodies in one time loop (DESIGN 1.3 and 3). The only module that sees both the DEM
// and Bullet's side: a rigid body the spheres may touch is a mesh wall in the DEM (a rock by its convex
// hull, a machine part by its surface mesh) that follows the body, and the spheres' reaction goes back to
// the body as a force and a torque about its centre of mass.
#pragma once

#include "core/state_io.h"
#include "core/vec3.h"
#include "dem/world.h"
#include "meshes/triangle_mesh.h"
#include "rigid/convex_polyhedron.h"
#include "rigid/rigid_world.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace dipper::coupling {

/// DEM steps per rigid-body step that scenarios use unless they say otherwise. Chosen from the tests of
/// docs/coupling.md: loads and momentum do not depend on n; a sphere's rebound from a light rock gains
/// +2 % restitution at n = 2, +11 % at 5, +42 % at 10, +76 % at 20; a 20,000-sphere, 1,000-rock bed ran at
/// n = 10 and diverged at n = 20; n = 5 makes Bullet's share of the step a fifth of n = 1's.
inline constexpr int kDefaultSubsteps = 5;

/// The runaway guard (CouplingSettings::runaway_guard, docs/coupling.md). A rock that answers stiff sphere contacts a coupling step late can
/// gain speed from them: its velocity change flips direction every coupling step and grows. The guard
/// watches each rock's velocity change over a coupling step (the rotation's scaled by the radius of
/// gyration) and, once it has flipped and grown kRunawayStreak times in a row by kRunawayGrowth in all,
/// from at least kRunawayFloor_m_per_s, runs the next kRunawayHoldSteps coupling steps with one DEM step per
/// Bullet step, where the exchange is stable.
inline constexpr int kRunawayStreak = 3;
inline constexpr double kRunawayGrowth = 8.0;
inline constexpr double kRunawayFloor_m_per_s = 0.1;
inline constexpr int kRunawayHoldSteps = 50;

/// How the rocks (bodies made with CoupledWorld::add_rock) take the spheres' forces (docs/coupling.md).
enum class RockExchange {
    /// Bullet's step gives each rock the mean reaction of the last exchange's sub-steps: the rock answers the
    /// spheres one coupling step late (the step described at CoupledWorld).
    coupling_step,
    /// Each DEM sub-step's reaction turns the rock's velocity and moves its surface at once (the DEM's rate), on
    /// top of the motion Bullet's last step gave it; at the end of the coupling step that motion goes back into
    /// Bullet, whose step then takes only gravity and the rocks' contacts with rocks and steel (a multi-rate
    /// scheme: Bullet at substeps x the DEM step). A sphere's rebound from a rock is then the same at any n, and
    /// no rock runs away as one answering a coupling step late does. Machine parts keep the coupling-step
    /// exchange (their motors and joints are Bullet's).
    dem_step,
};

struct CouplingSettings {
    /// DEM steps per rigid-body step (DESIGN 1.3). 1 exchanges forces every DEM step; larger values give
    /// Bullet one step of substeps x the DEM step with the mean reaction of the sub-steps.
    int substeps = kDefaultSubsteps;
    /// The runaway guard (kRunawayStreak and below). Off by default: it changes a run's bits wherever it acts,
    /// and in a falling column of the Table 1 mix it acts often (docs/coupling.md).
    bool runaway_guard = false;
    RockExchange rock_exchange = RockExchange::coupling_step;
};

/// A rigid body the spheres touch, and what passed between the two at the last step.
struct CoupledBody {
    rigid::BodyId body = -1;
    int wall = -1;           ///< the DEM mesh wall that carries its surface
    bool dynamic = false;    ///< receives the spheres' reaction (rocks, the dipper, the door)
    Vec3 applied_force_N;    ///< force Bullet's last step received from the spheres
    Vec3 applied_torque_N_m; ///< torque about the centre of mass Bullet's last step received
};

/// A rock made with CoupledWorld::add_rock: what it takes to make it again (saved states).
struct RockRecord {
    rigid::BodyId body = -1;
    rigid::ConvexPolyhedron shape;  ///< principal frame
    double density_kg_per_m3 = 0.0;
    int rigid_material = 0;
    dem::MaterialIndex dem_material = 0;
};

/// The coupled step. Both worlds stay usable on their own (add walls, planes and particles to the DEM,
/// ground and rock-rock contacts to Bullet); this class moves the coupled surfaces and exchanges forces.
///
/// One step of the coupling is `substeps` DEM steps and one Bullet step of the same length:
///   1. Bullet steps with the spheres' mean reaction from the previous coupling step's sub-steps
///      (force and torque about each body's centre of mass, as sampled at those configurations);
///   2. each coupled surface moves through the DEM sub-steps from its pose before that Bullet step to its
///      pose after it, at the constant velocity that joins them (the velocity Bullet integrated with);
///   3. each DEM sub-step computes sphere forces against those surfaces and the reactions are summed.
/// Forces are thus always evaluated at a configuration both sides share; with substeps = 1 the exchange is
/// the staggered scheme in which each impulse the spheres receive, the body receives too, so a closed
/// system keeps its linear momentum to round-off (docs/coupling.md).
///
/// With substeps > 1 a light rock held by stiff, damped sphere contacts can run away (docs/coupling.md): the
/// runaway guard above, where it is on, then makes each coupling step `substeps` exchanges of one DEM step
/// for a while.
/// A coupling step is always `substeps` DEM steps; momentum passes in full either way.
class CoupledWorld {
public:
    CoupledWorld(dem::World& dem, rigid::RigidWorld& rigid, CouplingSettings settings = {});

    /// Lets the spheres touch `body` through `surface`, a closed or open triangle mesh in the body's part
    /// frame (RigidWorld::part_pose), with DEM surface material `material`. Returns the coupled index.
    int couple(rigid::BodyId body, meshes::TriangleMesh surface, dem::MaterialIndex material, const std::string& name);
    /// A rock in both worlds: a Bullet body from `shape` (principal frame, RigidWorld::add_rock) and its hull
    /// as a sphere surface of DEM material `dem_material`.
    rigid::BodyId add_rock(const rigid::ConvexPolyhedron& shape, double density_kg_per_m3, int rigid_material,
                           dem::MaterialIndex dem_material, const Vec3& position_m, const Mat3& rotation = Mat3::identity(),
                           const Vec3& velocity_m_per_s = {}, const Vec3& angular_velocity_rad_per_s = {});

    /// One coupling step (substeps DEM steps). Throws SimulationError with a diagnosis if either side blows up.
    /// It is, in order:
    ///     const int steps = begin_step();
    ///     for each of the substeps / steps exchanges:
    ///         const double interval = send_reactions(steps);  // 1. the reactions to the bodies
    ///         step_rigid(interval);                           //    Bullet's step
    ///         run_dem(steps, interval);                       // 2., 3. the DEM sub-steps
    ///     end_step();
    /// A caller that must act between the parts (place kinematic bodies before Bullet's step: CoSimulation)
    /// calls them itself in this order.
    void step();
    void run_steps(std::uint64_t n);

    /// Starts a coupling step; returns the DEM steps of each of its exchanges: substeps, or 1 while the runaway
    /// guard holds (then the step is substeps exchanges of one DEM step).
    int begin_step();
    /// Gives each dynamic body the spheres' mean reaction over the last exchange and records the bodies' poses
    /// before Bullet's step. Returns the length of that step: `steps` DEM steps.
    double send_reactions(int steps);
    /// Bullet's step of step_s (timed in rigid_seconds()).
    void step_rigid(double step_s);
    /// The DEM's `steps` sub-steps over Bullet's step of interval_s, the coupled surfaces moving from the poses
    /// before it to those after it, the spheres' reactions summed for the next exchange.
    void run_dem(int steps, double interval_s);
    /// Ends the coupling step: the runaway guard's count and watch.
    void end_step();

    double time_s() const { return dem_.time_s(); }
    double dem_step_s() const { return dem_.step_s(); }
    double coupling_step_s() const { return dem_.step_s() * settings_.substeps; }
    const CouplingSettings& settings() const { return settings_; }
    const std::vector<CoupledBody>& bodies() const { return bodies_; }
    const std::vector<RockRecord>& rocks() const { return rocks_; }
    const CoupledBody& body(int index) const;
    /// Index of a coupled body by its rigid body id, or -1.
    int index_of(rigid::BodyId body) const;
    /// Mean force and torque the spheres exerted on a coupled body over the sub-steps of the last step (what
    /// Bullet receives at the next step).
    Vec3 mean_sphere_force_N(int index) const;
    Vec3 mean_sphere_torque_N_m(int index) const;

    dem::World& dem() { return dem_; }
    rigid::RigidWorld& rigid() { return rigid_; }
    const dem::World& dem() const { return dem_; }
    const rigid::RigidWorld& rigid() const { return rigid_; }

    /// Coupling steps the runaway guard has run as exchanges of one DEM step, and the times it was set off,
    /// since the start.
    std::uint64_t guarded_steps() const { return guarded_steps_; }
    std::uint64_t runaways_caught() const { return runaways_caught_; }

    /// Wall-clock seconds in Bullet's steps and in moving the coupled surfaces (the DEM's own phases are in
    /// dem().phase_seconds()), summed since the start.
    double rigid_seconds() const { return rigid_seconds_; }
    double surface_seconds() const { return surface_seconds_; }

    // ---- checkpoints (with RigidWorld and dem::World's own write_state and read_state)
    /// The rocks made with add_rock: shape, density and materials, in order.
    void write_rocks(StateWriter& out) const;
    /// Makes the rocks of write_rocks again, in a world built like the one written (before the worlds'
    /// own read_state, which then sets their poses and velocities).
    void read_rocks(StateReader& in);
    /// What passes between the worlds: surface poses over the step, the sub-steps' reaction sums.
    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

    // ---- whole-system balances (tests, probes)
    Vec3 linear_momentum_kg_m_per_s() const;   ///< spheres and dynamic rocks
    Vec3 angular_momentum_kg_m2_per_s() const; ///< about the origin, spins included
    double kinetic_energy_J() const;

private:
    /// The checkpoint's fields, listed once for writing and reading (core/state_io.h).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& s);
    struct Pose {
        Mat3 rotation;
        Vec3 origin_m, centre_m;
    };
    Pose pose_of(const CoupledBody& b) const;
    void start();
    void check_pairs() const;
    void move_surfaces(double fraction, double interval_s);
    /// RockExchange::dem_step: a rock's motion from the spheres since Bullet's last step, and what it takes.
    struct RockResponse {
        Vec3 velocity_m_per_s, angular_velocity_rad_per_s;  ///< world frame, added to Bullet's
        Vec3 displacement_m, turn_rad;                      ///< of the centre; rotation vector, world frame
        Mat3 inverse_inertia;                               ///< world frame, at Bullet's last step
        double inverse_mass = 0.0;                          ///< 0: takes no response (not a rock, or frozen)
    };
    bool responds_at_dem_rate(std::size_t k) const;
    /// At the start of an exchange: each rock's response from rest, its inertia at its pose after Bullet's step.
    void start_responses();
    /// After the last sub-step: each rock's response added to its pose and velocities in Bullet.
    void hand_responses_to_rigid();
    /// The runaway guard's watch over the rocks at the end of a coupling step.
    void watch_for_runaways();

    dem::World& dem_;
    rigid::RigidWorld& rigid_;
    CouplingSettings settings_;
    std::vector<CoupledBody> bodies_;
    std::vector<int> index_by_body_;  ///< by rigid body id: its index in bodies_, or -1 (index_of, once per rock per step)
    std::vector<RockRecord> rocks_;
    std::vector<Pose> before_, after_;
    std::vector<Vec3> spin_rad_;             ///< rotation vector from `before_` to `after_`
    std::vector<Vec3> force_sum_, torque_sum_;
    std::vector<RockResponse> response_;  ///< RockExchange::dem_step; all zero between coupling steps
    /// The runaway guard's record of each coupled body (rocks only; `radius_of_gyration_m` 0 for others):
    /// velocities at the last coupling step's end, the velocity change over it, and the current streak.
    struct Watch {
        Vec3 radius_of_gyration_m;  ///< sqrt(I / m) along the principal axes
        Vec3 velocity_m_per_s, angular_velocity_rad_per_s;
        Vec3 change_m_per_s, angular_change_m_per_s;
        std::int64_t streak = 0;  ///< 64 bits: no padding in the checkpoint's bytes
        double growth = 1.0;
    };
    std::vector<Watch> watch_;
    std::int32_t hold_steps_ = 0;  ///< coupling steps still to run as exchanges of one DEM step
    std::uint64_t guarded_steps_ = 0, runaways_caught_ = 0;
    int samples_ = 0;
    bool initial_reaction_ = false;  ///< the sums hold the initial state's force, not an exchange's sub-steps
    double rigid_seconds_ = 0.0, surface_seconds_ = 0.0;
    bool started_ = false;
    bool held_ = false;  ///< the step in progress is split by the runaway guard
    std::size_t checked_bodies_ = 0;
};

/// Rotation vector (axis times angle, |angle| <= pi) of a rotation matrix.
Vec3 rotation_vector(const Mat3& rotation);

}  // namespace dipper::coupling
