// The rope shovel (thesis Paper A §3.2, Table 3; a Bucyrus 495-class machine): what it is made of, where
// its joints are, how it is driven, and what it reports. RigidWorld::add_rope_shovel builds it in Bullet.
// Dimensions and their sources: docs/machine.md.
#pragma once

#include "core/vec3.h"
#include "meshes/machine_geometry.h"
#include "rigid/motion_curves.h"

namespace dipper::rigid {

/// Machine frame: origin on the ground on the swing axis, x forward towards the bank, z up; the boom lies
/// in the x-z plane when the swing angle is 0.
struct ShovelGeometry {
    Vec3 boom_foot_m{3.5, 0.0, 4.5};
    double boom_length_m = 20.4;         ///< foot pin to boom-point sheave
    double boom_angle_deg = 45.0;        ///< above the horizontal
    double shipper_shaft_fraction = 0.5; ///< position of the saddle-block pivot along the boom
    double handle_length_m = 9.0;        ///< dipper handle (crowd arm), from its dipper pin backwards
    double handle_section_m = 0.9;       ///< square section of the handle, for collisions and inertia
    double upper_body_mass_kg = 5.0e5;   ///< upper body with boom and counterweight
    Vec3 upper_body_centre_m{-2.0, 0.0, 4.0};
    double saddle_mass_kg = 8.0e3;
    double handle_mass_kg = 2.5e4;
    double dipper_mass_kg = 4.5e4;       ///< dipper body with lip and teeth, without the door
    double door_mass_kg = 1.0e4;
    double payload_kg = 0.0;             ///< material held in the dipper, at the struck volume's centroid
    double rope_axial_stiffness_N = 2.4e8;  ///< EA of one hoist rope (75 mm wire rope)
    double rope_damping_ratio = 0.2;     ///< of critical, for the hoisted mass on its ropes
    double force_filter_window_s = 0.25; ///< moving average for the reported drive forces
    double max_crowd_force_N = 2.0e7;    ///< what the crowd drive can push or pull
};

/// Where everything is for a handle angle and crowd extension, in the machine frame at swing 0 (pure
/// geometry, no dynamics): used to build the default cycle and by the statics test.
struct ShovelPose {
    Vec3 shipper_shaft_m;
    Vec3 sheave_m;
    Vec3 handle_pin_m;
    Vec3 handle_axis;           ///< unit, from the shipper shaft towards the dipper
    Mat3 dipper_rotation;       ///< dipper frame to machine frame
    Vec3 dipper_origin_m;       ///< the heel
    Vec3 bail_m[2];
    double rope_length_m = 0.0; ///< sheave to bail (both ropes have the same length)
};
/// `handle_angle_deg`: the handle's angle below the horizontal (positive points the dipper down).
ShovelPose pose_shovel(const ShovelGeometry& geometry, const meshes::Dipper& dipper, double handle_angle_deg,
                       double crowd_extension_m);

/// Three passes shaped like thesis Paper A Fig. 9 for this geometry: each a dig of 15 s (hoist in, handle
/// from as steep as the ground allows, at most 75 deg below horizontal, to level), swing 90 deg to the truck while raising to the dump pose, 3 s
/// dump with the door opening 60 deg, swing back high (the dipper's lowest point 8 m up) while closing
/// the door, crowd drawn in and the dipper lowered to hang in front of the bank, crowd out into the toe:
/// 46 s per pass, 138 s in all. The key poses are joined by smooth curves (each drive accelerates and
/// brakes; it rests where it turns back and at the dig's end), sampled every 0.05 s. With `advance_per_pass_m` > 0 the crawlers carry the machine that far forward while it swings
/// back after each dump (28 s to 41 s of the pass), so that the next dig reaches the bank the last one
/// cut back.
MotionCurves default_loading_cycle(const ShovelGeometry& geometry, const meshes::Dipper& dipper, double advance_per_pass_m = 0.0);

/// Repeated bucket fillings for wear (thesis Paper B §3.5: the bucket is emptied back into the pile it
/// dug, so the pile keeps its material): `cycles` of 30 s, each the default cycle's 15 s dig, then with no
/// swing the crowd drawn in to 3 m (handle 20 deg down: the heel 8 m above the toe, the door facing
/// down), the door opened 60 deg for 4 s so that the load falls where the next dig begins, shut, and the
/// dipper back at the toe.
MotionCurves dig_and_return_cycle(const ShovelGeometry& geometry, const meshes::Dipper& dipper, int cycles);
/// The length of one pass of the two built-in cycles, and of its dig.
inline constexpr double kDefaultCyclePass_s = 46.0, kDigAndReturnPass_s = 30.0, kBuiltInDig_s = 15.0;

/// What the shovel reports each step.
struct ShovelReading {
    double time_s = 0.0;
    double crowd_force_N = 0.0;      ///< along the handle; positive pushes the dipper out
    double hoist_force_N = 0.0;      ///< both ropes together (tension only, >= 0)
    double dig_force_N = 0.0;        ///< sqrt(F_crowd^2 + F_hoist^2), thesis eq. 11
    double crowd_force_filtered_N = 0.0;  ///< the same, averaged over force_filter_window_s
    double hoist_force_filtered_N = 0.0;
    double dig_force_filtered_N = 0.0;
    double rope_tension_N[2] = {0.0, 0.0};
    double rope_length_m[2] = {0.0, 0.0};  ///< sheave to bail, as the model stands
    double crowd_extension_m = 0.0;  ///< as the model stands
    double handle_angle_deg = 0.0;   ///< below the horizontal, as the model stands
    double swing_deg = 0.0;
    double door_deg = 0.0;
    double rake_angle_deg = 0.0;     ///< handle centre line to heel-tooth-tip line, from the posed model
    Vec3 tooth_tip_m;                ///< world frame
    Vec3 heel_m;                     ///< world frame
};

}  // namespace dipper::rigid
