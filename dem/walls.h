// Boundaries the spheres touch: analytic planes and triangle meshes that may move rigidly.
#pragma once

#include "core/vec3.h"
#include "dem/material.h"
#include "meshes/triangle_mesh.h"

#include <array>
#include <cstdint>
#include <algorithm>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace dipper::dem {

/// An infinite static plane; particles live on the side the normal points to.
struct PlaneWall {
    Vec3 point_m;
    Vec3 normal;  ///< unit
    MaterialIndex material = 0;
    std::string name;
};

/// Rigid motion prescribed in time: body-frame point `pivot_m` (which coincides with the world point
/// pivot_m at t = 0) moves as c(t) = pivot + v t + A sin(2 pi f t), and the body turns about it at a
/// constant angular velocity. World position of body point x_b: c(t) + R(t) (x_b - pivot).
struct PrescribedMotion {
    Vec3 velocity_m_per_s;
    Vec3 angular_velocity_rad_per_s;
    Vec3 pivot_m;
    Vec3 oscillation_amplitude_m;
    double oscillation_frequency_Hz = 0.0;
    /// The motion runs from start_s to end_s: before, the mesh rests where it is at t = 0; after, where the
    /// motion brought it (a gate that opens at a chosen time and stays open).
    double start_s = 0.0;
    double end_s = std::numeric_limits<double>::infinity();

    /// How long the motion has run by time t: 0 before start_s, end_s - start_s after end_s.
    double moving_s(double t_s) const { return std::min(std::max(t_s, start_s), end_s) - start_s; }
    bool moving_at(double t_s) const { return t_s >= start_s && t_s < end_s; }
    /// Pose at time t: rotation and translation so that x_world = R x_body + T.
    void pose(double t_s, Mat3& rotation, Vec3& translation_m) const;
    /// Velocity of the pivot and angular velocity at time t (zero outside [start_s, end_s)).
    Vec3 pivot_velocity_m_per_s(double t_s) const;
    Vec3 angular_velocity_at(double t_s) const { return moving_at(t_s) ? angular_velocity_rad_per_s : Vec3{}; }
    Vec3 pivot_position_m(double t_s) const;
};

/// A triangle's vertices and unit normal in one place, in its mesh's body frame: the contact search
/// copies them into each sphere's candidate list and tests the sphere in that frame.
struct PackedTriangle {
    Vec3 a, b, c, normal;
};

/// The mesh's ids of a triangle's vertices and edges: a sphere touching an edge or vertex is matched by id.
struct TriangleIds {
    std::array<std::uint32_t, 3> vertices, edges;
};

/// A triangle mesh wall. The mesh is kept in its body frame; its world pose and velocity are set each
/// step, either from a PrescribedMotion or from outside (the coupling module moves machine parts).
class MeshWall {
public:
    MeshWall(meshes::TriangleMesh mesh, MaterialIndex material, std::string name,
             std::optional<PrescribedMotion> motion = std::nullopt);

    /// Sets the pose (x_world = R x_body + T) and the rigid velocity field v(p) = v_ref + w x (p - ref).
    void set_pose(const Mat3& rotation, const Vec3& translation_m, const Vec3& reference_point_world_m,
                  const Vec3& reference_velocity_m_per_s, const Vec3& angular_velocity_rad_per_s);
    /// Velocity of the wall material at a world point.
    Vec3 velocity_at(const Vec3& point_world_m) const
    {
        return reference_velocity_ + cross(angular_velocity_, point_world_m - reference_point_);
    }

    const meshes::TriangleMesh& mesh() const { return mesh_; }
    /// The vertices at the current pose, computed on the first call after a pose change (so that a wall
    /// moved every step costs nothing until someone asks). Not thread-safe: call from one thread.
    const std::vector<Vec3>& vertices_world_m() const;
    /// Triangle t in the body frame.
    const PackedTriangle& packed_body(std::size_t t) const { return packed_body_[t]; }
    TriangleIds triangle_ids(std::size_t t) const { return {mesh_.triangles()[t], mesh_.triangle_edges(t)}; }
    Vec3 to_body(const Vec3& x_world_m) const { return rotation_transposed_ * (x_world_m - translation_); }
    Vec3 to_world(const Vec3& x_body_m) const { return rotation_ * x_body_m + translation_; }
    /// Whether a sphere (world centre, radius) is clear of the surface in its present pose: no point of the
    /// mesh closer than the radius. A bounding-box test first, then the exact distance.
    bool sphere_clear(const Vec3& centre_world_m, double radius_m) const;
    /// An upper bound on how far any vertex has moved from where the pose (rotation0, translation0) put it:
    /// |(R - R0) c + T - T0| + |R - R0|_2 rho, with c and rho a body-frame bounding sphere.
    double max_vertex_move_m(const Mat3& rotation0, const Vec3& translation0_m) const;
    /// A sphere that holds the mesh: its centre in the body frame and at the current pose, and its radius.
    const Vec3& bound_centre_body_m() const { return bound_centre_; }
    Vec3 bound_centre_world_m() const { return to_world(bound_centre_); }
    double bound_radius_m() const { return bound_radius_m_; }
    const Vec3& angular_velocity_rad_per_s() const { return angular_velocity_; }
    /// The point whose velocity set_pose gave (a rigid body's centre of mass), world frame.
    const Vec3& reference_point_m() const { return reference_point_; }
    /// Mass of the body behind the wall; 0 (the default) is immovable. A finite mass makes the contact
    /// damping use the pair's effective mass m1 m2 / (m1 + m2) (DESIGN 1.1).
    double mass_kg() const { return mass_kg_; }
    void set_mass_kg(double mass_kg);
    const std::optional<PrescribedMotion>& motion() const { return motion_; }
    MaterialIndex material() const { return material_; }
    const std::string& name() const { return name_; }
    const Mat3& rotation() const { return rotation_; }
    const Vec3& translation_m() const { return translation_; }
    /// Counts pose changes, so that neighbour lists notice a wall moved from outside.
    std::uint64_t pose_version() const { return pose_version_; }
    /// Sets a saved pose and pose count back (checkpoints).
    void restore_pose(const Mat3& rotation, const Vec3& translation_m, const Vec3& reference_point_world_m,
                      const Vec3& reference_velocity_m_per_s, const Vec3& angular_velocity_rad_per_s,
                      std::uint64_t pose_version);
    const Vec3& reference_velocity_m_per_s() const { return reference_velocity_; }
    /// True for a closed convex solid with outward normals, such as a rock's hull: every edge shared by two
    /// triangles and no vertex in front of any triangle's plane by more than convex_slack_m() (checked for
    /// meshes of up to kMaxConvexCheckTriangles). Such a body lies behind each of its face planes, so a
    /// sphere whose centre is r + convex_slack_m() or more in front of any one of them touches none of its
    /// triangles, and a centre outside it has its closest point on a face whose plane it is in front of.
    /// An open plate or shell is not one: it is a two-sided surface.
    bool convex() const { return convex_; }
    double convex_slack_m() const { return convex_slack_m_; }
    static constexpr std::size_t kMaxConvexCheckTriangles = 2000;

private:
    meshes::TriangleMesh mesh_;
    MaterialIndex material_;
    std::string name_;
    std::optional<PrescribedMotion> motion_;
    Mat3 rotation_, rotation_transposed_;
    Vec3 translation_;
    Vec3 reference_point_, reference_velocity_, angular_velocity_;
    std::vector<PackedTriangle> packed_body_;
    Vec3 bound_centre_;        ///< body frame
    double bound_radius_m_ = 0.0;
    Vec3 bounds_lo_m_, bounds_hi_m_;  ///< the body-frame box of the vertices (sphere_clear)
    mutable std::vector<Vec3> vertices_world_;
    mutable bool vertices_current_ = false;
    std::uint64_t pose_version_ = 0;
    double mass_kg_ = 0.0;
    bool convex_ = false;
    double convex_slack_m_ = 0.0;
};

}  // namespace dipper::dem
