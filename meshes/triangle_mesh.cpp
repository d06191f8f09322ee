#include "meshes/triangle_mesh.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace dipper::meshes {

TriangleMesh::TriangleMesh(std::vector<Vec3> vertices_m, std::vector<std::array<std::uint32_t, 3>> triangles,
                           const std::string& source, double min_area_m2)
    : vertices_m_(std::move(vertices_m)), triangles_(std::move(triangles)), source_(source)
{
    if (triangles_.empty()) throw InputError(concat("mesh ", source_, " has no triangles"));
    for (std::size_t v = 0; v < vertices_m_.size(); ++v)
        if (!is_finite(vertices_m_[v]))
            throw InputError(concat("mesh ", source_, ": vertex ", v, " has a non-finite coordinate"));

    // edges numbered once, keyed by their sorted vertex pair
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> edge_ids;
    triangle_edges_.resize(triangles_.size());
    normals_.resize(triangles_.size());
    areas_m2_.resize(triangles_.size());
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
        const auto& tri = triangles_[t];
        for (int k = 0; k < 3; ++k)
            if (tri[k] >= vertices_m_.size())
                throw InputError(concat("mesh ", source_, ": triangle ", t, " refers to vertex ", tri[k],
                                        " but the mesh has ", vertices_m_.size(), " vertices"));
        const Vec3 n = cross(vertices_m_[tri[1]] - vertices_m_[tri[0]], vertices_m_[tri[2]] - vertices_m_[tri[0]]);
        const double area = 0.5 * norm(n);
        if (!(area > min_area_m2))
            throw InputError(concat("mesh ", source_, ": triangle ", t, " (vertices ", tri[0], ", ", tri[1], ", ",
                                    tri[2], ") is degenerate: area ", area, " m2, expected > ", min_area_m2, " m2"));
        areas_m2_[t] = area;
        normals_[t] = n * (0.5 / area);
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = tri[k], b = tri[(k + 1) % 3];
            const auto key = std::make_pair(std::min(a, b), std::max(a, b));
            auto [it, inserted] = edge_ids.try_emplace(key, static_cast<std::uint32_t>(edge_vertices_.size()));
            if (inserted) edge_vertices_.push_back({key.first, key.second});
            triangle_edges_[t][k] = it->second;
        }
    }
}

double TriangleMesh::total_area_m2() const
{
    double sum = 0.0;
    for (double a : areas_m2_) sum += a;
    return sum;
}

Vec3 TriangleMesh::bounds_min_m() const
{
    Vec3 lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};
    for (const Vec3& v : vertices_m_) lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
    return lo;
}

Vec3 TriangleMesh::bounds_max_m() const
{
    Vec3 hi{-std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(), -std::numeric_limits<double>::max()};
    for (const Vec3& v : vertices_m_) hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
    return hi;
}

bool TriangleMesh::contains(const Vec3& point_m) const
{
    // Ray from the point along a slightly skewed +x direction; count crossings (Moller-Trumbore).
    const Vec3 dir = normalized(Vec3{1.0, 1.234567e-4, 2.345678e-4});
    int crossings = 0;
    for (const auto& tri : triangles_) {
        const Vec3& a = vertices_m_[tri[0]];
        const Vec3 e1 = vertices_m_[tri[1]] - a, e2 = vertices_m_[tri[2]] - a;
        const Vec3 h = cross(dir, e2);
        const double det = dot(e1, h);
        if (std::abs(det) < 1e-300) continue;
        const double inv = 1.0 / det;
        const Vec3 s = point_m - a;
        const double u = dot(s, h) * inv;
        if (u < 0.0 || u > 1.0) continue;
        const Vec3 q = cross(s, e1);
        const double v = dot(dir, q) * inv;
        if (v < 0.0 || u + v > 1.0) continue;
        if (dot(e2, q) * inv > 0.0) ++crossings;
    }
    return (crossings % 2) == 1;
}

double TriangleMesh::distance_m(const Vec3& point_m) const
{
    double best = std::numeric_limits<double>::max();
    for (const auto& tri : triangles_)
        best = std::min(best, closest_point_on_triangle(point_m, vertices_m_[tri[0]], vertices_m_[tri[1]],
                                                        vertices_m_[tri[2]]).distance_squared);
    return std::sqrt(best);
}

TriangleMesh make_box_mesh(const Vec3& lo, const Vec3& hi)
{
    std::vector<Vec3> v = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                           {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    std::vector<std::array<std::uint32_t, 3>> t = {
        {0, 2, 1}, {0, 3, 2},  // bottom, normal -z
        {4, 5, 6}, {4, 6, 7},  // top, +z
        {0, 1, 5}, {0, 5, 4},  // front, -y
        {3, 7, 6}, {3, 6, 2},  // back, +y
        {0, 4, 7}, {0, 7, 3},  // left, -x
        {1, 2, 6}, {1, 6, 5},  // right, +x
    };
    return TriangleMesh(std::move(v), std::move(t), "generated box");
}

TriangleMesh make_plate_mesh(double size_x_m, double size_y_m, int nx, int ny)
{
    if (nx < 1 || ny < 1) throw InputError(concat("plate mesh needs nx, ny >= 1; got ", nx, ", ", ny));
    std::vector<Vec3> v;
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) v.push_back({size_x_m * i / nx, size_y_m * j / ny, 0.0});
    std::vector<std::array<std::uint32_t, 3>> t;
    auto id = [&](int i, int j) { return static_cast<std::uint32_t>(j * (nx + 1) + i); };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            t.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            t.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    return TriangleMesh(std::move(v), std::move(t), "generated plate");
}

}  // namespace dipper::meshes
