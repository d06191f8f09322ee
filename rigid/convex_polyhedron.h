// Convex polyhedra for rocks: the hull of a point set or a checked convex mesh, with exact mass properties
// (volume, centre of mass, inertia tensor) from the polyhedron itself, and the principal frame.
#pragma once

#include "core/vec3.h"
#include "meshes/triangle_mesh.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace dipper::rigid {

/// Principal frame of a body: `axes` has the principal axes as columns (a proper rotation), `moments` the
/// principal moments of inertia about the centre of mass, kg m^2.
struct PrincipalFrame {
    Vec3 centre_m;
    Mat3 axes;
    Vec3 moments_kg_m2;
};

class ConvexPolyhedron {
public:
    /// The convex hull of the points. Fewer than 4 points, non-finite coordinates, or a hull with
    /// (nearly) no volume are InputErrors naming `source`.
    static ConvexPolyhedron hull_of(const std::vector<Vec3>& points_m, const std::string& source);
    /// A closed triangle mesh that must already be convex (every vertex on or behind every face plane,
    /// within 1e-6 of the mesh size) with outward normals: a non-convex, open or degenerate mesh is an
    /// InputError naming `source`, the face and the distance.
    static ConvexPolyhedron from_mesh(const meshes::TriangleMesh& mesh);

    const std::vector<Vec3>& vertices_m() const { return vertices_m_; }
    /// Outward triangles over the vertices (polygon faces of the hull split into fans).
    const std::vector<std::array<std::uint32_t, 3>>& triangles() const { return triangles_; }
    const std::string& source() const { return source_; }

    double volume_m3() const { return volume_m3_; }
    double surface_area_m2() const;
    Vec3 centroid_m() const { return centroid_m_; }
    /// Inertia tensor about the centroid, in the polyhedron's frame, for a uniform density.
    Mat3 inertia_about_centroid(double density_kg_per_m3) const;
    PrincipalFrame principal_frame(double density_kg_per_m3) const;
    /// Diameter of the sphere of equal volume, m: the size measure of rock classes.
    double equivalent_diameter_m() const;
    /// Largest extent along a unit direction: max over vertices of dot(x, direction).
    double support_m(const Vec3& direction) const;
    /// Smallest distance from the centroid to a face plane (inradius about the centroid).
    double inner_radius_m() const;

    /// The same solid, rigidly moved: x -> rotation * x + translation.
    ConvexPolyhedron transformed(const Mat3& rotation, const Vec3& translation_m) const;
    /// The same solid scaled about its centroid.
    ConvexPolyhedron scaled(double factor) const;
    /// The hull moved inwards by `margin_m` on every face, keeping its vertices and triangles: each vertex
    /// goes where the planes of its faces, shifted inwards, meet (least squares where more than three
    /// faces meet). With a ball of radius margin_m added (Bullet's collision margin) it is the rock again,
    /// with slightly rounded edges.
    ConvexPolyhedron shrunk(double margin_m) const;
    /// Volume of this polyhedron plus a ball of radius r (the Minkowski sum), by Steiner's formula:
    /// V + A r + (r^2 / 2) sum over edges of length x exterior dihedral angle + 4/3 pi r^3.
    double rounded_volume_m3(double r) const;
    /// The polyhedron expressed in its principal frame: centroid at the origin, principal axes along x, y, z.
    ConvexPolyhedron in_principal_frame() const;

    meshes::TriangleMesh to_mesh() const;

private:
    ConvexPolyhedron() = default;
    void compute_properties();
    std::vector<Vec3> vertices_m_;
    std::vector<std::array<std::uint32_t, 3>> triangles_;
    std::string source_;
    double volume_m3_ = 0.0;
    Vec3 centroid_m_;
    Mat3 covariance_;  ///< second moment about the centroid, per unit density: integral of x x^T dV
};

}  // namespace dipper::rigid
