// The spherical DEM: particles, walls, neighbour search, contact forces and time integration.
#pragma once

#include "core/contact_record.h"
#include "core/vec3.h"
#include "dem/contact_law.h"
#include "dem/convex_pairs.h"
#include "dem/material.h"
#include "dem/particle_store.h"
#include "dem/sphere_pairs.h"
#include "dem/wall_candidates.h"
#include "dem/wall_contact.h"
#include "dem/walls.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

namespace dipper::dem {

/// Settings of a DEM world; validated when the world is made.
struct WorldSettings {
    Vec3 gravity_m_per_s2{0.0, 0.0, -9.81};
    /// Time step. 0 picks kDefaultStepFactor x reference step; a value above the stable limit
    /// (kStableStepFactor x reference step) is refused when the simulation starts.
    double step_s = 0.0;
    /// Verlet skin as a fraction of the largest particle radius: pairs closer than r1 + r2 + skin are
    /// listed, and the list is rebuilt when a particle has moved half the skin.
    double skin_fraction_of_radius = 0.3;
    int threads = 1;                         ///< OpenMP threads; 0 takes OMP_NUM_THREADS / all cores
    double max_overlap_ratio = 0.5;          ///< stop with a diagnosis when overlap / smaller radius exceeds it
    double initial_overlap_tolerance = 0.01; ///< initial overlaps above this fraction of the smaller radius are refused
    /// At a rebuild, a particle that has not moved since the last one (a frozen one) keeps its walls within reach when
    /// no mesh near it has moved either: the same lists a search finds, for a fraction of the cost in a frozen bed.
    /// false searches every particle's walls at every rebuild (what the carried lists are checked and timed against).
    bool carry_wall_candidates = true;
};

/// Reference time step sqrt(m / K) (thesis: dt = c_dt sqrt(m/k)) and its factors.
/// The stable limit is 0.2 x reference: with several contacts per particle and damping up to critical,
/// velocity Verlet needs omega dt well below 1 (docs/contact_model.md gives the derivation).
inline constexpr double kStableStepFactor = 0.2;
inline constexpr double kDefaultStepFactor = 0.15;

/// Wall-clock seconds spent in each phase of step(), summed since the world was made (benchmarks).
struct PhaseSeconds {
    double neighbour_search = 0.0;  ///< neighbour-list and wall-candidate rebuilds
    double pair_forces = 0.0;       ///< sphere-sphere contacts
    double wall_forces = 0.0;       ///< sphere-wall contacts: planes, meshes and coupled rigid bodies
    double convex_forces = 0.0;     ///< of wall_forces: the spheres' pairs with convex bodies (rocks), slowest thread
    double integration = 0.0;       ///< kicks, drift, force gathering, wall reactions and records
};

/// A spherical DEM world. Not thread-safe itself; uses OpenMP threads inside step().
class World {
public:
    World(MaterialTable materials, WorldSettings settings);

    // ---- building ------------------------------------------------------------------------------
    /// Adds a particle (validated); returns its stable id. `where` names the source for errors.
    std::uint32_t add_particle(const ParticleSpawn& spawn, const std::string& where = "add_particle");
    /// Adds an infinite plane through point_m with the given normal (particles on the normal's side).
    int add_plane(const Vec3& point_m, const Vec3& normal, MaterialIndex material, const std::string& name);
    /// Adds a triangle mesh wall; with a motion it moves by itself, without it stays where set_mesh_pose puts it.
    int add_mesh(meshes::TriangleMesh mesh, MaterialIndex material, const std::string& name,
                 std::optional<PrescribedMotion> motion = std::nullopt);
    /// Moves a mesh wall rigidly (used by code that drives machine parts); takes effect for the next step.
    void set_mesh_pose(int wall_id, const Mat3& rotation, const Vec3& translation_m, const Vec3& reference_point_m,
                       const Vec3& reference_velocity_m_per_s, const Vec3& angular_velocity_rad_per_s);
    /// Takes a wall out of the world from the next step on: no sphere touches it again (a gate opened, a plug
    /// pulled). Its force reads zero from then; its name and id stay.
    void remove_wall(int wall_id);
    bool wall_removed(int wall_id) const;
    /// Mass of the body behind a mesh wall (0: immovable), for the damping's effective mass.
    void set_wall_mass_kg(int wall_id, double mass_kg);
    /// Receives at every step the sphere contacts with the given walls (ids), in last_contact_records' order (see
    /// core/contact_record.h): a wear surface's own contacts, without a record made for every contact of the step.
    void set_contact_consumer(ContactConsumer consumer, const std::vector<int>& walls);

    // ---- frozen bodies (what coupling::DynamicDomain decides) --------------------------------------
    /// Freezes particle i (dense index) or lets it go. A frozen particle stays where it is, at rest: it is not
    /// integrated, and its contacts with other frozen particles and frozen convex walls are left as they were
    /// (their springs keep their history); anything else still meets it as a fixed body. Freezing zeroes its
    /// velocities and forces, so that it starts from rest when it is let go.
    void set_frozen(std::size_t i, bool frozen);
    /// Freezes a convex mesh wall (a rock the rigid side holds still) or lets it go: its pairs with frozen
    /// particles are left as they were, and no reaction comes from them.
    void set_wall_frozen(int wall_id, bool frozen);
    bool wall_frozen(int wall_id) const;
    std::size_t frozen_count() const;  ///< frozen particles
    /// Particles whose walls within reach the last rebuild carried over instead of searching (WorldSettings).
    std::size_t carried_wall_candidates() const { return candidates_.carried(); }

    // ---- running -------------------------------------------------------------------------------
    /// Advances one step: half kick and drift, walls moved, neighbour lists refreshed if needed,
    /// forces, second half kick. Throws SimulationError with a diagnosis if the state blows up.
    void step();
    /// Called between the steps of run_steps with the index of the step within the call. before_forces
    /// runs after the particles' drift and before the walls are moved and the forces found (it may place
    /// mesh walls with set_mesh_pose; it must not change particles); after_forces runs once the step's
    /// wall reactions and contact records are final, before the particles' second half kick.
    struct StepHooks {
        std::function<void(std::uint64_t)> before_forces;
        std::function<void(std::uint64_t)> after_forces;
    };
    /// Advances n steps; the same as n calls of step(), bit for bit, with one pass over the particles
    /// fewer per step (the second half kick of a step and the first of the next share it).
    void run_steps(std::uint64_t n, const StepHooks& hooks = {});
    /// Makes the next step rebuild the neighbour lists (history is carried over as always).
    void request_rebuild() { rebuild_needed_ = true; }

    // ---- checkpoints ---------------------------------------------------------------------------
    /// Writes the complete dynamic state: particles, forces, contact history, neighbour and wall-candidate
    /// lists, wall poses, time and counters. read_state on a world built the same way (same materials and
    /// walls, in the same order) then continues bit for bit as this world would have.
    void write_state(StateWriter& out) const;
    /// Replaces the particles and the dynamic state by a saved one. The walls and materials are checked
    /// against the saved names; the file is refused with an InputError if they differ.
    void read_state(StateReader& in);

    // ---- time step -----------------------------------------------------------------------------
    /// sqrt(m_i / K_max,i) minimised over particles, K_max,i the stiffest contact particle i can have.
    double reference_step_s() const;
    /// The particle (dense index) whose sqrt(m_i / K_max,i) is reference_step_s; size() when none has a contact.
    std::size_t step_setting_particle() const;
    /// K_max,i of particle i: its normal stiffness against a wall with the largest C_norm of its material's pairs.
    double stiffest_contact_N_per_m(std::size_t i) const;
    /// The same for a particle of this radius and material, placed or not.
    double stiffest_contact_N_per_m(double radius_m, MaterialIndex material) const;
    /// The default step a particle of this radius and material would bring (infinite if it has no pair).
    double default_step_s(double radius_m, MaterialIndex material) const;
    double stable_step_limit_s() const { return kStableStepFactor * reference_step_s(); }
    double step_s() const;  ///< the step in use (the default is resolved when particles exist)

    // ---- state ---------------------------------------------------------------------------------
    const ParticleStore& particles() const { return particles_; }
    ParticleStore& particles() { return particles_; }
    const MaterialTable& materials() const { return materials_; }
    const WorldSettings& settings() const { return settings_; }
    double time_s() const { return time_s_; }
    std::uint64_t step_count() const { return step_count_; }
    std::uint64_t rebuild_count() const { return rebuild_count_; }
    std::size_t wall_count() const { return walls_.size(); }
    const std::string& wall_name(int wall_id) const;
    const MeshWall& mesh_wall(int wall_id) const;
    const PlaneWall& plane_wall(int wall_id) const;
    bool is_mesh(int wall_id) const;

    /// Total force the particles exert on a wall during the last step, N (deterministic sum).
    Vec3 wall_force_N(int wall_id) const;
    /// Torque of the same forces (and of the rolling resistance) about the wall's reference point (a mesh
    /// wall's MeshWall::reference_point_m, the origin for a plane), N m. After the first step or prepare().
    Vec3 wall_torque_N_m(int wall_id) const;
    /// The same two for every wall, indexed by wall id (for a caller that reads them all at every step).
    const std::vector<Vec3>& wall_forces_N() const { return wall_force_N_; }
    const std::vector<Vec3>& wall_torques_N_m() const { return wall_torque_N_m_; }
    /// Builds the neighbour lists and computes the forces of the initial state, as the first step would;
    /// wall forces and torques are then those of the initial state. Called by step() when needed.
    void prepare();
    /// Surface contacts of the last step.
    const std::vector<ContactRecord>& last_contact_records() const;  ///< built when first asked for
    /// The last step's surface contacts with the given walls (ids), in last_contact_records' order.
    std::vector<ContactRecord> contact_records(const std::vector<int>& walls) const;
    std::size_t pair_contact_count() const;          ///< touching sphere pairs in the last step
    std::size_t wall_contact_count() const { return wall_contacts_.size() + convex_contact_count_; }
    std::size_t neighbour_pair_count() const { return pairs_.size(); }
    double max_overlap_ratio() const { return max_overlap_ratio_; }  ///< largest overlap / smaller radius, last step
    std::vector<PairContactView> pair_contacts() const;
    double kinetic_energy_J() const;                 ///< translational + rotational
    double gravitational_potential_energy_J() const; ///< -m g . x summed
    Vec3 linear_momentum_kg_m_per_s() const;
    Vec3 angular_momentum_kg_m2_per_s() const;        ///< about the origin, including spin
    double total_mass_kg() const;
    int threads() const { return threads_; }
    const PhaseSeconds& phase_seconds() const { return phase_seconds_; }

private:
    /// The checkpoint's fields, listed once for writing and reading (core/state_io.h).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& s);
    struct WallRef { bool is_mesh; int index; };

    void sum_wall_reactions();
    void wall_thread_block(int t, std::size_t& begin, std::size_t& end) const;
    void check_wall_name(const std::string& name) const;
    void validate_step();
    void check_initial_overlaps() const;
    void move_prescribed_meshes(double t_end_s, double dt_s);
    bool needs_rebuild(double particle_move_m) const;
    void rebuild();
    /// The pairs of spheres and convex bodies and the per-particle lists of the other walls, from candidates_.
    void split_candidates();
    /// The walls as the wall-candidate search and the contact geometry read them.
    WallSet wall_set() const { return {planes_, plane_offset_m_, plane_wall_id_, meshes_, mesh_wall_id_, wall_removed_}; }
    /// Moves the history of wall_contacts_ on convex bodies into their pairs; the rest stay, indexed by particle.
    void split_convex_contacts();
    /// wall_contacts_ with the touching pairs' contacts added, sorted by particle (rebuilds and checkpoints).
    std::vector<WallContact> merged_wall_contacts() const;
    /// Fills a wall contact's forces from its geometry and history (DESIGN 1.1).
    void apply_wall_law(WallContact& c, const Vec3& x, const Vec3& v, const Vec3& w, double r, double dt_s) const;
    void evaluate_forces(double dt_s, double half_kick_s);
    void compute_wall_contacts(double dt_s);
    void find_wall_contacts(std::uint32_t i, double dt_s, std::vector<WallHit>& hits, std::vector<WallContact>& out) const;
    /// Sums each particle's forces and kicks it by half_kick_s; with next_drift also gives it the next
    /// step's first half kick and drift and returns the largest squared move since the last rebuild.
    double gather_forces_and_kick(double half_kick_s, bool next_drift);
    double kick_and_drift(double dt_s);
    void finish_step(double dt_s);
    [[noreturn]] void fail_overlap() const;
    std::string where_in_time() const;

    MaterialTable materials_;
    std::vector<double> bulk_modulus_Pa_;  ///< per material, cached (eq. 5)
    WorldSettings settings_;
    int threads_ = 1;
    ParticleStore particles_;
    std::vector<PlaneWall> planes_;
    std::vector<MeshWall> meshes_;
    std::vector<WallRef> walls_;
    std::unordered_set<std::string> wall_names_;  ///< of walls_, for check_wall_name (a pile has 20,000 rocks)
    std::vector<WallMotion> wall_motion_;  ///< beside walls_, refreshed by compute_wall_contacts
    std::vector<ConvexFrame> convex_frames_;  ///< beside meshes_ (convex ones only), refreshed by compute_wall_contacts
    std::vector<std::int32_t> mesh_wall_id_;  ///< wall id of each mesh
    std::vector<std::uint8_t> mesh_moved_;    ///< beside meshes_: posed or given a mass since the last wall phase
    std::vector<std::int32_t> plane_wall_id_; ///< wall id of each plane
    std::vector<std::uint8_t> wall_removed_;  ///< per wall id: 1 once remove_wall took it out
    std::vector<std::uint8_t> wall_frozen_;   ///< per wall id: 1 while set_wall_frozen holds it
    std::uint64_t frozen_version_ = 0;        ///< counts changes of the frozen flags (particles' and walls'), and reads
    std::vector<double> plane_offset_m_;      ///< point . normal of each plane
    ContactConsumer consumer_;
    /// Walls whose contacts are asked for: a flag per wall id (walls added later are not), and whether one is convex.
    struct WallFlags {
        std::vector<std::uint8_t> flag;
        bool any_convex = false;
    };
    WallFlags consumer_walls_;                     ///< the walls whose contacts the consumer takes
    std::vector<ContactRecord> consumer_records_;  ///< this step's records for the consumer

    double time_s_ = 0.0, step_s_ = 0.0;
    std::uint64_t step_count_ = 0, rebuild_count_ = 0;
    bool prepared_ = false, rebuild_needed_ = true, step_checked_ = false;

    SpherePairs pairs_;  ///< the neighbour list of sphere pairs with their contact history and forces
    std::vector<Vec3> reference_position_m_;
    std::vector<double> reference_radius_m_;        ///< at the last rebuild; not in a checkpoint (nothing carried after one)
    std::vector<double> stiffness_radius_N_per_m_;  ///< k r per particle (eq. 4), refreshed at each rebuild
    std::vector<Mat3> reference_mesh_rotation_;     ///< each mesh's pose at the last rebuild
    std::vector<Vec3> reference_mesh_translation_m_;
    std::vector<std::uint64_t> reference_mesh_version_;
    double skin_m_ = 0.0;

    // sphere-wall contacts of the last step, sorted by particle, and mesh triangle candidates
    std::vector<WallContact> wall_contacts_;
    std::vector<std::uint32_t> wall_contact_start_;
    std::vector<std::size_t> wall_contact_offset_;  ///< per-thread offsets into wall_contacts_, this step
    WallCandidates candidates_;  ///< the walls within reach of each particle, found at each rebuild
    ConvexPairs convex_;  ///< the spheres within reach of convex bodies, with their contacts
    std::size_t convex_contact_count_ = 0;
    std::vector<std::size_t> thread_first_deep_convex_;  ///< per thread: first convex pair past the overlap limit
    std::vector<double> thread_convex_seconds_;           ///< per thread: its pass over its convex pairs, this step
    std::vector<std::vector<WallContact>> thread_wall_contacts_;
    std::vector<std::vector<WallHit>> thread_wall_hits_;
    std::vector<Vec3> wall_force_N_, wall_torque_N_m_;
    std::vector<std::vector<Vec3>> thread_wall_force_N_, thread_wall_torque_N_m_;  ///< per thread and wall, this step
    std::vector<std::size_t> thread_first_deep_contact_;  ///< per thread: first wall contact past the overlap limit
    /// The records of the last step's contacts with the flagged walls, into `out`.
    void records_of(const WallFlags& walls, std::vector<ContactRecord>& out) const;
    WallFlags wall_flags(const std::vector<int>& walls, const char* caller) const;
    mutable std::vector<ContactRecord> records_;
    mutable bool records_stale_ = true;
    double max_overlap_ratio_ = 0.0;
    PhaseSeconds phase_seconds_;
};

}  // namespace dipper::dem
