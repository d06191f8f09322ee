// Triangle surface meshes: storage, topology (shared edges and vertices), validation, and the exact
// point-to-triangle query that sphere contacts use.
#pragma once

#include "core/vec3.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace dipper::meshes {

/// Which feature of a triangle holds the closest point: its interior, one edge, or one vertex.
enum class Feature : std::uint8_t { Face, Edge, Vertex };

/// Closest point on one triangle to a query point, with the feature it lies on.
struct ClosestPoint {
    Vec3 point;
    double distance_squared = 0.0;
    Feature feature = Feature::Face;
    int local_index = 0;  ///< edge 0..2 (v0v1, v1v2, v2v0) or vertex 0..2 of the triangle; unused for Face
};

/// Exact closest point on triangle (a, b, c) to p, by Voronoi regions of the vertices, edges and face
/// (Ericson, Real-Time Collision Detection (2005), §5.1.5). Inline: the sphere-wall search calls it in its
/// inner loop.
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline ClosestPoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c)
{
    ClosestPoint out;
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    auto finish = [&](const Vec3& q, Feature f, int index) {
        out.point = q;
        out.distance_squared = norm_squared(p - q);
        out.feature = f;
        out.local_index = index;
        return out;
    };
    if (d1 <= 0.0 && d2 <= 0.0) return finish(a, Feature::Vertex, 0);

    const Vec3 bp = p - b;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return finish(b, Feature::Vertex, 1);

    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        const double v = d1 / (d1 - d3);
        return finish(a + ab * v, Feature::Edge, 0);
    }

    const Vec3 cp = p - c;
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return finish(c, Feature::Vertex, 2);

    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        const double w = d2 / (d2 - d6);
        return finish(a + ac * w, Feature::Edge, 2);
    }

    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return finish(b + (c - b) * w, Feature::Edge, 1);
    }

    const double denom = 1.0 / (va + vb + vc);
    const double v = vb * denom, w = vc * denom;
    return finish(a + ab * v + ac * w, Feature::Face, 0);
}

/// A triangle surface mesh in its own (body) frame. Vertices are shared between triangles; edges are
/// numbered once however many triangles share them, so that contacts can be made unique per feature.
class TriangleMesh {
public:
    TriangleMesh() = default;
    /// Builds topology and validates: indices in range, finite coordinates, no triangle with area below
    /// `min_area_m2` (degenerate). `source` names where the data came from, for error messages.
    TriangleMesh(std::vector<Vec3> vertices_m, std::vector<std::array<std::uint32_t, 3>> triangles,
                 const std::string& source, double min_area_m2 = 1e-14);

    std::size_t vertex_count() const { return vertices_m_.size(); }
    std::size_t triangle_count() const { return triangles_.size(); }
    std::size_t edge_count() const { return edge_vertices_.size(); }
    const std::vector<Vec3>& vertices_m() const { return vertices_m_; }
    const std::vector<std::array<std::uint32_t, 3>>& triangles() const { return triangles_; }
    /// Global edge ids of triangle t's edges (v0v1, v1v2, v2v0).
    const std::array<std::uint32_t, 3>& triangle_edges(std::size_t t) const { return triangle_edges_[t]; }
    /// The two vertex ids of edge e.
    const std::array<std::uint32_t, 2>& edge_vertices(std::size_t e) const { return edge_vertices_[e]; }
    /// Unit normal of triangle t (right-hand rule on its vertex order), body frame.
    const Vec3& triangle_normal(std::size_t t) const { return normals_[t]; }
    double triangle_area_m2(std::size_t t) const { return areas_m2_[t]; }
    double total_area_m2() const;
    const std::string& source() const { return source_; }

    /// Minimum and maximum corner of the axis-aligned bounding box, body frame.
    Vec3 bounds_min_m() const;
    Vec3 bounds_max_m() const;

    /// True if the point lies inside the closed surface (ray parity along +x, with a tie-breaking
    /// perturbation). Only meaningful for closed meshes.
    bool contains(const Vec3& point_m) const;
    /// Smallest distance from the point to the surface.
    double distance_m(const Vec3& point_m) const;

private:
    std::vector<Vec3> vertices_m_;
    std::vector<std::array<std::uint32_t, 3>> triangles_;
    std::vector<std::array<std::uint32_t, 3>> triangle_edges_;
    std::vector<std::array<std::uint32_t, 2>> edge_vertices_;
    std::vector<Vec3> normals_;
    std::vector<double> areas_m2_;
    std::string source_;
};

/// Axis-aligned box as a closed mesh of 12 outward-facing triangles.
TriangleMesh make_box_mesh(const Vec3& min_corner_m, const Vec3& max_corner_m);
/// Flat rectangle in the z = 0 plane of its frame, [0, size_x] x [0, size_y], split into nx x ny cells
/// of two triangles each, normal +z.
TriangleMesh make_plate_mesh(double size_x_m, double size_y_m, int nx, int ny);

}  // namespace dipper::meshes
