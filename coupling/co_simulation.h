// The coupled run of an excavator digging: the DEM's spheres, Bullet's rocks and walls, the rope shovel, the
// wear surfaces and the passes, stepped together (DESIGN 1.3 and 3). What a scenario file describes, a
// program can build here directly; the scenario layer only reads a file into these settings and calls.
#pragma once

#include "coupling/coupled_world.h"
#include "coupling/dynamic_domain.h"
#include "dem/world.h"
#include "meshes/machine_geometry.h"
#include "meshes/triangle_locator.h"
#include "rigid/motion_curves.h"
#include "rigid/machine_path.h"
#include "rigid/rigid_world.h"
#include "wear/wear_surface.h"

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace dipper::coupling {

/// Friction and restitution of rocks against rocks or a rigid wall material (Bullet), over the preset's.
struct RockPair {
    std::string a, b;
    double friction = 0.0, restitution = 0.0;
};

/// The materials of the rigid world a wall or part may have: what rocks meet there. The DEM's surface
/// materials that are not here touch spheres only.
const std::vector<std::string>& rigid_material_names();

struct CoSimulationSettings {
    CouplingSettings coupling;
    std::vector<RockPair> rock_pairs;  ///< applied in this order after the Aitik preset
    /// Rocks will be added: every DEM wall must then have a rigid material (rigid_material_names); without
    /// rocks a wall of another material touches spheres only.
    bool rocks = false;
    /// Spheres and rocks at rest away from moving things frozen (coupling/dynamic_domain.h); off by default.
    DynamicDomainSettings dynamic_domain;
};

/// The rope shovel's motion: the thesis' loading cycle, a dig followed by a return to the start, or curves.
enum class ShovelCycle { loading, dig_and_return, curves };

struct ShovelSettings {
    meshes::DipperParameters dipper;              ///< rake angle, wear bars, element size
    ShovelCycle cycle = ShovelCycle::loading;
    std::optional<rigid::MotionCurves> curves;    ///< with ShovelCycle::curves
    int passes = 3;                               ///< dig_and_return: passes of the cycle
    double advance_per_pass_m = 0.0;              ///< loading: the propel after each dump
    double dig_speed_factor = 1.0;                ///< built-in cycles: each dig this many times faster
    double start_s = 0.0;                         ///< the motion starts at this time
    Vec3 position_m;
    double heading_deg = 0.0;
    std::string material = "bucket";             ///< DEM surface material of dipper and door
    double bulk_density_kg_per_m3 = 1903.0;       ///< the fill factor's divisor (with the struck volume)
};

/// A built-in cycle (passes of `pass_s` that each start with a dig of rigid::kBuiltInDig_s) with each dig
/// done `factor` times faster; what follows a dig keeps its duration, so a pass lasts
/// pass_s - 15 s + 15 s / factor. The positions the curves pass through do not change.
rigid::MotionCurves dig_speed_scaled(const rigid::MotionCurves& cycle, double factor, double pass_s = rigid::kDefaultCyclePass_s);

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

/// A wear surface: a machine part or a DEM mesh wall, with where its contacts come from.
struct WearPart {
    std::string part;                           ///< "dipper", "door" or the DEM mesh wall's name
    std::unique_ptr<wear::WearSurface> surface;
    int wall = -1;                              ///< DEM wall whose sphere contacts it sums
    rigid::BodyId body = -1;                    ///< Bullet body whose rock contacts it sums (-1: none)
};

class CoSimulation {
public:
    /// Takes the DEM world with its planes and meshes (its walls) and builds Bullet's side around it: each
    /// wall as a Bullet wall for rocks (a moving mesh as a kinematic body that follows its motion), the Aitik
    /// rock materials with `settings.rock_pairs` over them, and the coupling.
    explicit CoSimulation(std::unique_ptr<dem::World> dem, CoSimulationSettings settings = {});
    ~CoSimulation();
    CoSimulation(const CoSimulation&) = delete;
    CoSimulation& operator=(const CoSimulation&) = delete;

    /// The rope shovel with its dipper and door coupled to the spheres. At most one; before any wear surface.
    void add_shovel(const ShovelSettings& shovel);
    /// A wear surface on "dipper", "door" or a DEM mesh wall of that name; returns its index in wear().
    std::size_t add_wear(const std::string& part, const wear::WearLaw& law);

    /// One coupling step: coupling().settings().substeps DEM steps, wear and passes included.
    void step();
    /// Steps until time_s() reaches t_s (within a millionth of a DEM step).
    void run_until(double t_s);

    double time_s() const { return coupled_->time_s(); }
    dem::World& dem() { return *dem_; }
    const dem::World& dem() const { return *dem_; }
    rigid::RigidWorld& rigid() { return *rigid_; }
    const rigid::RigidWorld& rigid() const { return *rigid_; }
    coupling::CoupledWorld& coupled() { return *coupled_; }
    const coupling::CoupledWorld& coupled() const { return *coupled_; }
    /// Which bodies are frozen now (all awake unless CoSimulationSettings::dynamic_domain is enabled or some are held).
    const DynamicDomain& dynamic_domain() const { return domain_; }
    /// Holds spheres (dense indices) and rocks (indices in coupled().rocks()) fixed for the rest of the run
    /// (DynamicDomain::hold): the boundary layer of a pile cut to the region the dipper works in.
    void hold(const std::vector<std::size_t>& spheres, const std::vector<std::size_t>& rocks) { domain_.hold(*coupled_, spheres, rocks); }

    // ---- the machine
    bool has_shovel() const { return dipper_body_ >= 0; }
    /// The shovel's dipper and door in the rigid world (-1 without a shovel).
    rigid::BodyId dipper_body() const { return dipper_body_; }
    rigid::BodyId door_body() const { return door_body_; }
    const meshes::Dipper& dipper() const { return dipper_; }
    /// The shovel's crawlers, upper body, handle, dipper and door posed along its whole cycle by its curves alone
    /// (rigid::shovel_path: no point moves more than max_move_m between two samples); empty without a shovel.
    std::vector<rigid::PartPath> shovel_path(double max_move_m = 0.05) const;
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
    /// Whether a sphere of radius r at c is clear of the dipper's and the door's surfaces in their present
    /// pose (true without a shovel): a saved pile, built without the machine, loses what the dipper
    /// occupies where a run starts (thesis Paper A §3.3 moved or removed those rocks by hand).
    bool clear_of_machine(const Vec3& c, double r) const;
    /// Throws SimulationError naming the rock, where and when, if a rock's centre lies inside the steel
    /// of the dipper or door (it went through a plate). Called after every step.
    void check_tunnelling() const;

    // ---- wear
    const std::vector<WearPart>& wear() const { return wear_; }
    /// The dipper's wear volume by part of it (bottom, lip, sides, top, teeth, bars), m^3; empty for other
    /// parts.
    std::vector<std::pair<std::string, double>> wear_by_region(const WearPart& w) const;
    /// The names of the plates of the dipper or the door, indexed as meshes::MachinePart::triangle_plate: bottom,
    /// lip, side_minus_y, side_plus_y, top, tooth_1 .., bar_1 ..; door. Empty for other parts.
    std::vector<std::string> plate_names(const WearPart& w) const;
    /// Which plate each triangle of the dipper's or the door's wear surface belongs to (indexes plate_names);
    /// empty for other parts.
    const std::vector<std::uint32_t>& triangle_plates(const WearPart& w) const;
    /// Pose of a wear surface's mesh frame in the world now.
    void wear_pose(const WearPart& w, Mat3& rotation, Vec3& origin_m) const;

    // ---- outputs
    /// The DEM walls that are walls of the DEM world as given or machine parts (not rock hulls).
    std::vector<int> listed_walls() const;
    bool is_rock_wall(int wall) const;
    /// Every rock as one ParaView surface: triangles of each hull with cell fields rock (index),
    /// speed_m_per_s and size_m.
    void write_rocks_vtp(const std::string& path) const;
    /// Every rock's hull vertices where the rock is now (world frame): the rocks' part of a pile's surface.
    std::vector<Vec3> rock_surface_points() const;

    // ---- checkpoints, after the DEM world's state: Bullet's bodies and shovel, the coupling, the wear
    // sums and the passes. The rocks themselves go first, with coupled().write_rocks.
    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

private:
    /// The checkpoint's fields, listed once for writing and reading (core/state_io.h).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& s);
    void place_moving_walls(double t_s);
    void add_rock_wear();
    void track_passes();
    /// 0 bottom, 1 lip, 2 sides, 3 top, 4 teeth, 5 wear bars: the dipper's regions by plate.
    std::size_t dipper_region(std::uint32_t plate) const;

    std::unique_ptr<dem::World> dem_;
    std::unique_ptr<rigid::RigidWorld> rigid_;
    std::unique_ptr<coupling::CoupledWorld> coupled_;
    DynamicDomain domain_;
    std::size_t given_walls_ = 0;  ///< DEM walls 0 .. n-1 came with the DEM world
    std::vector<std::pair<std::string, rigid::BodyId>> mesh_bodies_;  ///< DEM mesh wall name, Bullet body
    std::vector<std::pair<rigid::BodyId, dem::PrescribedMotion>> moving_meshes_;  ///< kinematic in Bullet

    // the machine
    meshes::Dipper dipper_;
    struct Sphere {
        Vec3 centre;
        double radius = 0.0;
    };
    std::array<Sphere, 2> part_bounds_{};  ///< around the dipper's and the door's plates, in their frames
    std::unique_ptr<rigid::MotionCurves> motion_;  ///< the shovel's curves (the dig phase is read from them)
    Vec3 shovel_position_m_;
    double shovel_heading_deg_ = 0.0;
    double bulk_density_ = 1903.0;
    rigid::BodyId dipper_body_ = -1, door_body_ = -1;
    int dipper_wall_ = -1, door_wall_ = -1;
    std::vector<std::uint8_t> lip_triangle_;  ///< per triangle of dipper_.body.surface: on the lip or a tooth
    std::unique_ptr<meshes::TriangleLocator> dipper_locator_;  ///< finds a rock's contact point's triangle
    // a built-in cycle's digs: [start + k period, start + k period + dig]; period 0: curves
    double cycle_start_s_ = 0.0, cycle_period_s_ = 0.0, cycle_dig_s_ = 0.0;

    std::vector<WearPart> wear_;

    // the passes
    std::vector<PassRecord> passes_;
    bool door_open_ = false;
    double pass_start_s_ = 0.0, dig_start_s_ = -1.0, dig_end_s_ = -1.0, dig_force_sum_ = 0.0, dig_force_peak_ = 0.0;
    double interface_force_sum_ = 0.0, interface_force_peak_ = 0.0;
    double without_lip_sum_ = 0.0, without_lip_peak_ = 0.0;
    std::uint64_t dig_samples_ = 0;
};

}  // namespace dipper::coupling
