// The rigid side of a scenario: rocks and the rope shovel in Bullet, coupled to the DEM world, with the
// wear surfaces and the shovel's probes (mass in the dipper, fill factor, drive forces, passes).
#pragma once

#include "coupling/coupled_world.h"
#include "meshes/machine_geometry.h"
#include "meshes/triangle_locator.h"
#include "rigid/motion_curves.h"
#include "rigid/rigid_world.h"
#include "scenario/scenario.h"
#include "wear/wear_surface.h"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace dipper::scenario {

/// How far a measured wear point may lie from its part's surface, m.
inline constexpr double kMeasuredPointTolerance_m = 0.1;

/// One pass of the shovel: from the end of the previous dump (or t = 0) to the moment its door opens.
struct PassRecord {
    double start_s = 0.0;
    double dig_start_s = -1.0;       ///< the dig phase: the swing at rest, the door shut, the hoist hauling in
    double dig_end_s = -1.0;         ///< (its first and last step in this pass; -1 if there was none)
    double dump_s = 0.0;             ///< the door passed 5 deg open
    double mass_kg = 0.0;            ///< material in the dipper when the door opened
    double fill_factor = 0.0;        ///< that mass / (bulk density x struck volume)
    double mean_dig_force_N = 0.0;   ///< mean of sqrt(F_crowd^2 + F_hoist^2) over the dig phase (thesis eq. 11)
    double peak_dig_force_N = 0.0;
    /// Mean and peak over the dig phase of the resultant force of the material on dipper and door (spheres
    /// and rocks): the "resultant interface force" of thesis Paper B Fig. 19, which compares the wear bars.
    double mean_interface_force_N = 0.0;
    double peak_interface_force_N = 0.0;
    /// The same without the lip and its teeth: what Fig. 19 plots ("acting on the bucket (excluding lip)").
    double mean_interface_force_without_lip_N = 0.0;
    double peak_interface_force_without_lip_N = 0.0;
};

/// What the dipper holds now.
struct BucketContents {
    double mass_kg = 0.0;
    double fill_factor = 0.0;
    std::size_t spheres = 0, rocks = 0;
};

/// A wear surface of a scenario with where its contacts come from.
struct SceneWear {
    WearSpec spec;
    std::unique_ptr<wear::WearSurface> surface;
    int wall = -1;              ///< DEM wall whose sphere contacts it sums
    rigid::BodyId body = -1;    ///< Bullet body whose rock contacts it sums (-1: none)
};

/// A built-in cycle (passes of `pass_s` that each start with a dig of rigid::kBuiltInDig_s) with each dig
/// done `factor` times faster; what follows a dig keeps its duration, so a pass lasts
/// pass_s - 15 s + 15 s / factor. The positions the curves pass through do not change.
rigid::MotionCurves dig_speed_scaled(const rigid::MotionCurves& cycle, double factor, double pass_s = rigid::kDefaultCyclePass_s);

class RigidScene {
public:
    /// Builds Bullet's side for `scenario` around `dem` (its planes and meshes already added): the walls
    /// rocks touch, the shovel with dipper and door coupled to the spheres, and the coupling itself.
    RigidScene(const Scenario& scenario, dem::World& dem);
    ~RigidScene();
    RigidScene(const RigidScene&) = delete;
    RigidScene& operator=(const RigidScene&) = delete;

    /// Places the fills that have rocks (the others go through build_particles).
    void fill_mixed(const Scenario& scenario);
    /// Sets up the wear surfaces; call after the fills.
    void add_wear(const Scenario& scenario);

    /// One coupling step (substeps DEM steps), wear and passes included.
    void step();

    /// Checkpoints, after the DEM world's state: Bullet's bodies and shovel, the coupling, the wear sums
    /// and the passes. The rocks themselves go first, with coupled().write_rocks.
    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

    coupling::CoupledWorld& coupled() { return *coupled_; }
    const coupling::CoupledWorld& coupled() const { return *coupled_; }
    rigid::RigidWorld& rigid() { return *rigid_; }
    const rigid::RigidWorld& rigid() const { return *rigid_; }

    bool has_shovel() const { return dipper_body_ >= 0; }
    /// The shovel's dipper and door in the rigid world (-1 without a shovel).
    rigid::BodyId dipper_body() const { return dipper_body_; }
    rigid::BodyId door_body() const { return door_body_; }
    const meshes::Dipper& dipper() const { return dipper_; }
    const rigid::ShovelReading& reading() const;
    /// Resultant force of the spheres and rocks on dipper and door in the last step, N (0 without a shovel).
    Vec3 interface_force_N() const;
    /// The part of it on the dipper's lip and teeth, N: the spheres' contacts on those triangles and the rocks'
    /// contact points nearest to them.
    Vec3 lip_force_N() const;
    BucketContents bucket() const;
    const std::vector<PassRecord>& passes() const { return passes_; }
    /// Mass carried out of the dipper so far: the sum of the passes' masses, t.
    double tonnage_t() const;
    /// The tonnage a wear surface's rates divide by: its tonnage_t key, or the passes' tonnage.
    double tonnage_t(const SceneWear& w) const { return w.spec.tonnage_t > 0.0 ? w.spec.tonnage_t : tonnage_t(); }
    const std::vector<SceneWear>& wear() const { return wear_; }
    /// The dipper's wear volume by part of it (bottom, lip, sides, top, teeth, bars), m^3; empty for other
    /// parts.
    std::vector<std::pair<std::string, double>> wear_by_region(const SceneWear& w) const;
    /// Pose of a wear surface's mesh frame in the world now.
    void wear_pose(const SceneWear& w, Mat3& rotation, Vec3& origin_m) const;

    /// Whether a sphere of radius r at c is clear of the dipper's and the door's surfaces in their present
    /// pose (true without a shovel): a saved pile, built without the machine, loses what the dipper
    /// occupies where a run starts (thesis Paper A §3.3 moved or removed those rocks by hand).
    bool clear_of_machine(const Vec3& c, double r) const;
    /// The DEM walls that are machine parts or scenario walls (not rock hulls), for outputs.
    std::vector<int> listed_walls() const;
    bool is_rock_wall(int wall) const;
    /// Every rock as one ParaView surface: triangles of each hull with cell fields rock (index),
    /// speed_m_per_s and size_m.
    void write_rocks_vtp(const std::string& path) const;
    /// Every rock's hull vertices where the rock is now (world frame): the rocks' part of a pile's surface.
    std::vector<Vec3> rock_surface_points() const;
    double rock_kinetic_energy_J() const { return rigid_->kinetic_energy_J(); }

    /// Throws SimulationError naming the rock, where and when, if a rock's centre lies inside the steel
    /// of the dipper or door (it went through a plate). Called after every step.
    void check_tunnelling() const;

private:
    void track_passes();
    /// 0 bottom, 1 lip, 2 sides, 3 top, 4 teeth, 5 wear bars: the dipper's regions by plate.
    std::size_t dipper_region(std::uint32_t plate) const;

    const dem::World* dem_ = nullptr;
    std::unique_ptr<rigid::RigidWorld> rigid_;
    std::unique_ptr<coupling::CoupledWorld> coupled_;
    meshes::Dipper dipper_;
    struct Sphere {
        Vec3 centre;
        double radius = 0.0;
    };
    std::array<Sphere, 2> part_bounds_{};  ///< around the dipper's and the door's plates, in their frames
    std::unique_ptr<rigid::MotionCurves> motion_;  ///< the shovel's curves (the dig phase is read from them)
    double bulk_density_ = 1903.0;
    rigid::BodyId dipper_body_ = -1, door_body_ = -1;
    int dipper_wall_ = -1, door_wall_ = -1;
    std::vector<std::pair<std::string, rigid::BodyId>> static_meshes_;  ///< scenario mesh name, Bullet body
    std::vector<std::pair<rigid::BodyId, dem::PrescribedMotion>> moving_meshes_;  ///< kinematic in Bullet
    std::size_t scenario_walls_ = 0;  ///< DEM walls 0 .. n-1 are the scenario's planes and meshes
    std::vector<SceneWear> wear_;
    std::vector<PassRecord> passes_;
    // pass tracking
    bool door_open_ = false;
    double pass_start_s_ = 0.0, dig_start_s_ = -1.0, dig_end_s_ = -1.0, dig_force_sum_ = 0.0, dig_force_peak_ = 0.0;
    double interface_force_sum_ = 0.0, interface_force_peak_ = 0.0;
    double without_lip_sum_ = 0.0, without_lip_peak_ = 0.0;
    std::vector<std::uint8_t> lip_triangle_;  ///< per triangle of dipper_.body.surface: on the lip or a tooth
    std::unique_ptr<meshes::TriangleLocator> dipper_locator_;  ///< finds a rock's contact point's triangle
    std::uint64_t dig_samples_ = 0;
    // a built-in cycle's digs: [start + k period, start + k period + dig]; period 0: a motion file
    double cycle_start_s_ = 0.0, cycle_period_s_ = 0.0, cycle_dig_s_ = 0.0;
};

}  // namespace dipper::scenario
