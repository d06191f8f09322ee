// The machine's path checked against the scenario's steel: the shovel's parts posed along their whole cycle
// from the motion curves alone, and each place where a part would pass into a wall found with FCL's
// collision queries. The scenario's walls hold material but do not stop the machine (docs/limits.md), so a
// cycle that crosses the truck's body or the ground would run on silently; this is what finds it before the
// run starts (`dipper check`, and every run).
#pragma once

#include "core/vec3.h"
#include "meshes/machine_geometry.h"
#include "meshes/triangle_mesh.h"
#include "rigid/motion_curves.h"
#include "rigid/rope_shovel.h"

#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace dipper::rigid {

/// One part of the machine along its cycle: its surface in its own frame and its pose (x_world = R x + o) at
/// each sampled time.
struct PartPath {
    std::string name;
    meshes::TriangleMesh surface;
    std::vector<double> times_s;
    std::vector<Mat3> rotations;
    std::vector<Vec3> origins_m;
};

/// The shovel's crawlers, upper body, handle, dipper and door (the boxes and plates of
/// RigidWorld::add_rope_shovel) posed by the curves alone: each handle angle is the one at which the ropes are
/// just taut at the paid-out length (no stretch under load, which moves the dipper by centimetres), the
/// crawlers carried along their heading by `propel_m`. Sampled from the first to the last curve sample at times
/// close enough that no point of a part moves more than `max_move_m` between two (and at most 0.05 s apart).
std::vector<PartPath> shovel_path(const ShovelGeometry& geometry, const meshes::Dipper& dipper, const MotionCurves& motion,
                                  const Vec3& position_m, double heading_deg, double max_move_m = 0.05);

/// A wall a part may cross: a plane (steel behind it, against its normal) or a triangle surface, with the time
/// it is removed and, for a moving mesh, its pose at a time.
struct PathObstacle {
    std::string name;
    bool is_plane = false;
    Vec3 point_m, normal;            ///< of a plane: a point on it and its unit normal (towards the material)
    meshes::TriangleMesh surface;    ///< of a mesh, in its own frame
    std::function<void(double, Mat3&, Vec3&)> pose;  ///< of a moving mesh at a time; empty: where it stands
    Mat3 rotation = Mat3::identity();                ///< of a mesh that does not move
    Vec3 translation_m;
    double removed_at_s = std::numeric_limits<double>::infinity();
};

/// A stretch of the cycle over which a part is in a wall.
struct PathCrossing {
    std::string part, obstacle;
    double from_s = 0.0, to_s = 0.0;  ///< first and last sampled time in the wall
    double deepest_s = 0.0;           ///< when it is deepest
    /// How far it reaches into the wall then: behind a plane, its deepest point's distance from it; through a
    /// mesh (a surface), FCL's penetration depth of the crossing triangles: how far a triangle of the part pokes
    /// through one of the wall, which cannot exceed the two triangles' size.
    double depth_m = 0.0;
    Vec3 point_m;                     ///< where, then
};

/// Every stretch over which a part reaches more than `min_depth_m` into an obstacle, in the order of the
/// parts and then the obstacles; a crawler box standing on the ground plane touches it without reaching in.
/// A mesh is a surface, as the spheres see it: a part wholly inside a closed mesh, touching none of its
/// triangles, does not cross it.
std::vector<PathCrossing> find_crossings(const std::vector<PartPath>& parts, const std::vector<PathObstacle>& obstacles,
                                         double min_depth_m = 0.02);

/// "dipper passes 0.42 m into wall 'truck' from 22.35 s to 24.10 s (deepest at 23.20 s, at (x, y, z) m)".
std::string describe(const PathCrossing& crossing);

}  // namespace dipper::rigid
