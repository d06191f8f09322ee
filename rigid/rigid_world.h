// Rigid bodies on Bullet (double precision): polyhedral rocks, static and moving machine surfaces, and the
// contacts between them. Bullet stays inside this module: nothing here names a Bullet type.
#pragma once

#include "core/contact_record.h"
#include "core/state_io.h"
#include "core/vec3.h"
#include "meshes/machine_geometry.h"
#include "meshes/triangle_mesh.h"
#include "rigid/convex_polyhedron.h"
#include "rigid/rope_shovel.h"

#include <memory>
#include <string>
#include <vector>

namespace dipper::rigid {

using BodyId = int;

/// How the rigid world steps. The defaults are the ones the verification tests justify (docs/rigid.md).
struct RigidSettings {
    Vec3 gravity_m_per_s2{0.0, 0.0, -9.81};
    int solver_iterations = 10;
    /// Overlap that Bullet corrects inside the contact impulse; deeper overlaps are pushed apart by a
    /// separate position correction that adds no momentum. 0: contact impulses carry physical loads only.
    double split_impulse_threshold_m = 0.0;
    /// Collision margin of rocks: at most rock_margin_m and at most rock_margin_fraction of the rock's inner
    /// radius. The hull is shrunk by the margin first, so the rounded shape Bullet sees has the rock's true
    /// faces; only its sharpest corners are rounded (tests: volume within 1 %, extents within 2 %).
    double rock_margin_m = 0.02;
    double rock_margin_fraction = 0.05;
    /// Contact manifolds and pair algorithms Bullet keeps in its fixed pools before it falls back to the
    /// heap (slower, scattered in memory). Size it to the number of touching pairs expected (about 3.5 per
    /// rock in a pile).
    int contact_pool_size = 4096;
    /// Narrow phase of two convex hulls (rock-rock, rock-plate). By default dipper's: the same contact points as
    /// Bullet's convex-convex algorithm, but a contact manifold only for pairs within the breaking distance,
    /// and a pair found apart is not searched again until the bodies' motion may have closed its gap
    /// (docs/rigid.md). true: Bullet's own algorithm, for comparison.
    bool bullet_convex_pairs = false;
    /// Threads of the narrow phase (the contact search of each pair). The results do not depend on it: the
    /// same bits on any number of threads.
    int threads = 1;
};

/// Position, orientation and velocities of a body's centre of mass, world frame.
struct BodyState {
    Vec3 position_m;
    Mat3 rotation;
    Vec3 velocity_m_per_s;
    Vec3 angular_velocity_rad_per_s;
};

class RigidWorld {
public:
    explicit RigidWorld(RigidSettings settings = {});
    ~RigidWorld();
    RigidWorld(RigidWorld&&) noexcept;
    RigidWorld& operator=(RigidWorld&&) noexcept;

    // ---- materials: contact friction and restitution per pair (symmetric), no product rule
    int add_material(const std::string& name);
    int material_index(const std::string& name) const;
    const std::string& material_name(int material) const;
    void set_pair(const std::string& a, const std::string& b, double friction, double restitution);
    double pair_friction(int a, int b) const;
    double pair_restitution(int a, int b) const;

    // ---- bodies
    /// The plane z = height_m, solid below.
    BodyId add_ground_plane(double height_m, int material, const std::string& name);
    /// A fixed triangle-mesh surface, placed by rotation and translation.
    BodyId add_static_mesh(const meshes::TriangleMesh& mesh, int material, const std::string& name,
                           const Mat3& rotation = Mat3::identity(), const Vec3& translation_m = {});
    /// A triangle-mesh surface moved from outside (a machine part): set_kinematic_pose before each step
    /// gives its pose at the end of that step; Bullet sees the finite-difference velocity.
    BodyId add_kinematic_mesh(const meshes::TriangleMesh& mesh, int material, const std::string& name,
                              const Mat3& rotation = Mat3::identity(), const Vec3& translation_m = {});
    /// A part made of plates (meshes/machine_geometry.h), fixed or moved from outside like a kinematic
    /// mesh. Each plate is a convex solid; its collision margin lies inside it, so its faces are exact.
    BodyId add_plates(const std::vector<meshes::Plate>& plates, int material, const std::string& name, bool kinematic,
                      const Mat3& rotation = Mat3::identity(), const Vec3& translation_m = {});
    void set_kinematic_pose(BodyId body, const Mat3& rotation, const Vec3& translation_m);
    /// Whether the rope shovel's links collide with the fixed or kinematic body `body` (default: they do).
    /// Call before stepping. Boundaries that only hold material (a slice's side walls, a truck body the
    /// prescribed motion clears) can let the machine pass instead of stopping its drives.
    void set_blocks_machine(BodyId body, bool blocks);
    /// A rock: `shape` in its principal frame (ConvexPolyhedron::in_principal_frame, or generate_rock), placed
    /// with its centroid at `position_m`. Mass and inertia come from the shape and density.
    BodyId add_rock(const ConvexPolyhedron& shape, double density_kg_per_m3, int material, const Vec3& position_m,
                    const Mat3& rotation = Mat3::identity(), const Vec3& velocity_m_per_s = {},
                    const Vec3& angular_velocity_rad_per_s = {});

    std::size_t body_count() const;
    const std::string& body_name(BodyId body) const;
    double mass_kg(BodyId body) const;  ///< 0 for static and kinematic bodies
    BodyState state(BodyId body) const;
    /// The body's centre of mass (a mesh's or link's origin), m: state()'s position without the rest.
    Vec3 position_m(BodyId body) const;
    /// The collision margin a rock was given, m (0 for meshes and planes).
    double margin_m(BodyId body) const;

    /// Adds a force acting at a world point during the next step only (Bullet clears forces each step).
    void apply_force(BodyId body, const Vec3& force_N, const Vec3& point_world_m);
    /// Adds a force at the centre of mass and a torque, for the next step only.
    void apply_force_and_torque(BodyId body, const Vec3& force_N, const Vec3& torque_N_m);
    /// Pose of the frame the body's shape was given in (x_world = R x_part + origin): a rock's principal
    /// frame at its centroid, a mesh's or plate set's own frame, the dipper's and door's part frames.
    void part_pose(BodyId body, Mat3& rotation, Vec3& origin_m) const;
    /// True for bodies that move under forces (rocks, the shovel's dipper and door; a frozen rock too).
    bool is_dynamic(BodyId body) const;
    /// Freezes a rock in place or lets it go: a frozen rock is a fixed body, at rest, that other bodies meet as
    /// they meet the ground, and its contacts with the ground and other frozen rocks are not searched or solved
    /// (their manifolds are kept for when it is let go). Forces applied to it are ignored; it starts from rest.
    void set_frozen(BodyId rock, bool frozen);
    bool frozen(BodyId body) const;
    /// Puts a rock (not frozen) at a new pose with new velocities between steps, as the coupling does when the
    /// spheres have moved it at their own rate (coupling::RockExchange::dem_step). Its world inertia follows the
    /// new orientation; its contacts are found again at the next step, as after any move.
    void set_rock_motion(BodyId rock, const BodyState& state);

    // ---- the rope shovel (one per world)
    struct ShovelParts {
        BodyId dipper = -1, door = -1;
    };
    /// Builds the shovel as a Bullet multibody: crawlers fixed; upper body on a swing hinge (motor);
    /// boom part of the upper body; saddle block on a free hinge at the shipper shaft; dipper handle
    /// prismatic in the saddle block (motor) with the dipper fixed on it; door hinged at the dipper's
    /// rear (motor); two hoist ropes from the boom-point sheave to the bail pins, tension only. The motors
    /// follow `motion`; the ropes pay out its hoist length. The machine frame is placed at `position_m`
    /// turned by `heading_deg` about z. The dipper and door collide with rocks through their plates.
    ShovelParts add_rope_shovel(const meshes::Dipper& dipper, const ShovelGeometry& geometry, MotionCurves motion,
                                int dipper_material, const Vec3& position_m = {}, double heading_deg = 0.0);
    /// The shovel's forces and pose after the last step.
    const ShovelReading& shovel_reading() const;
    /// The dipper frame and the door frame (rotation, origin) in the world, for surfaces that follow them.
    void dipper_pose(Mat3& rotation, Vec3& origin_m) const;
    void door_pose(Mat3& rotation, Vec3& origin_m) const;

    // ---- stepping
    /// Exactly one Bullet step of step_s: no sub-steps, no interpolation. Each step may have its own length.
    void step(double step_s);
    double time_s() const;
    /// Length of the last step, s (0 before the first): what the shovel's forces and the links' velocities
    /// are differences over.
    double last_step_s() const;
    const RigidSettings& settings() const;

    // ---- checkpoints
    /// Writes the moving state: time, every rock's and kinematic part's pose and velocities, the shovel's
    /// joints, ropes and force filter, and Bullet's contact history (its broad phase, pairs, manifolds with
    /// their warm-starting impulses, in their order), so that a run continued from it takes the same steps as
    /// the uninterrupted run, bit for bit, on the same build and thread count.
    void write_state(StateWriter& out) const;
    /// Reads what write_state wrote into a world built the same way (same bodies in the same order);
    /// anything else is an InputError naming what differs.
    void read_state(StateReader& in);

    // ---- contacts of the last step
    /// Sum of contact forces (impulses / step) on a body during the last step, N.
    Vec3 contact_force_N(BodyId body) const;
    /// Where a contact point of the last step acts on a body, and its force on that body (impulse / step).
    struct PointForce {
        Vec3 point_m, force_N;
    };
    /// The contact points that make up contact_force_N(body), each with its force, the point on `body`. Keeps
    /// no state: call it as often as needed.
    std::vector<PointForce> contact_point_forces(BodyId body) const;
    /// Every contact point on `surface` during the last step, as a record: the point on the surface, the
    /// normal from the surface towards the other body, normal and friction force (impulse / step), the
    /// other body's contact point displacement relative to the surface over the step, and the surface's
    /// triangle. `surface_id` is written into the records. Rocks only (not plane-plane or mesh-mesh).
    /// With `wear_mesh` (the part's surface mesh in its own frame) each record's triangle is the wear-mesh
    /// triangle nearest to the contact point; without it, the Bullet mesh's own triangle (-1 for plates).
    /// Only touching points are reported. One record per start of contact between a rock and the part has
    /// first_step set (an impact), with the rock's velocity from before the step: call this once per step
    /// for a part, since it tells a new contact from one that continues by the previous call.
    std::vector<ContactRecord> surface_contacts(BodyId surface, std::int32_t surface_id,
                                                const meshes::TriangleMesh* wear_mesh = nullptr) const;
    std::size_t contact_point_count() const;
    /// What Bullet's collision stages hold after the last step: pairs of bodies whose bounding boxes overlap
    /// (broad phase), contact manifolds, manifolds with at least one point, and contact points.
    struct PairCounts {
        std::size_t broadphase_pairs = 0, manifolds = 0, touching_manifolds = 0, contact_points = 0;
    };
    PairCounts pair_counts() const;
    /// Deepest overlap among the contact points of the last step, m (0 if none overlap).
    double max_penetration_m() const;
    /// Kinetic energy of the dynamic bodies (rocks), J.
    double kinetic_energy_J() const;
    /// Linear momentum of the rocks, and their angular momentum about the origin (spins included).
    Vec3 linear_momentum_kg_m_per_s() const;
    Vec3 angular_momentum_kg_m2_per_s() const;

    struct Impl;  ///< Bullet's side, opaque outside rigid/

private:
    std::unique_ptr<Impl> impl_;
};

/// Thesis Paper A Table 2 as Bullet's rocks see it, written once: the preset, the tests and the benchmarks
/// read these. Coulomb friction of a rock against another rock, the ground, the bucket (the Hardox
/// pin-on-disc value) and the truck; Table 2 gives no restitution, and where it is silent the thesis damps
/// fully, so restitution is 0.
struct RockFriction {
    double rock = 0.85, ground = 0.9, bucket = 0.53, truck = 0.85;
};
inline constexpr RockFriction kTable2RockFriction{};

/// Rock materials of the Aitik copper ore as Bullet sees them: "rock", "ground", "bucket", with the
/// friction of kTable2RockFriction and restitution 0.
void add_aitik_copper_ore_materials(RigidWorld& world);

}  // namespace dipper::rigid
