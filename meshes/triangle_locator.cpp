#include "meshes/triangle_locator.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dipper::meshes {

TriangleLocator::TriangleLocator(const TriangleMesh& mesh, double cell_m) : mesh_(&mesh), cell_m_(cell_m)
{
    if (mesh.triangle_count() == 0) throw InputError(concat("triangle locator: mesh '", mesh.source(), "' is empty"));
    const auto& x = mesh.vertices_m();
    if (!(cell_m_ > 0.0)) {
        double sum = 0.0;
        for (std::size_t e = 0; e < mesh.edge_count(); ++e)
            sum += norm(x[mesh.edge_vertices(e)[0]] - x[mesh.edge_vertices(e)[1]]);
        cell_m_ = 2.0 * sum / static_cast<double>(std::max<std::size_t>(1, mesh.edge_count()));
    }
    const Vec3 lo = mesh.bounds_min_m(), hi = mesh.bounds_max_m();
    origin_ = lo;
    const auto count = [&](double extent) { return std::max(1, std::min(512, static_cast<int>(std::ceil(extent / cell_m_)) + 1)); };
    nx_ = count(hi.x - lo.x);
    ny_ = count(hi.y - lo.y);
    nz_ = count(hi.z - lo.z);
    // bucket the triangles by their bounding boxes (two passes: count, fill)
    const std::size_t cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_) * static_cast<std::size_t>(nz_);
    std::vector<std::uint32_t> counts(cells + 1, 0);
    const auto clampi = [](int v, int n) { return std::max(0, std::min(n - 1, v)); };
    const auto for_cells = [&](std::size_t t, auto&& f) {
        const auto& tri = mesh.triangles()[t];
        Vec3 a = x[tri[0]], b = x[tri[0]];
        for (const std::uint32_t v : tri) {
            a = {std::min(a.x, x[v].x), std::min(a.y, x[v].y), std::min(a.z, x[v].z)};
            b = {std::max(b.x, x[v].x), std::max(b.y, x[v].y), std::max(b.z, x[v].z)};
        }
        const int i0 = clampi(static_cast<int>(std::floor((a.x - origin_.x) / cell_m_)), nx_),
                  i1 = clampi(static_cast<int>(std::floor((b.x - origin_.x) / cell_m_)), nx_);
        const int j0 = clampi(static_cast<int>(std::floor((a.y - origin_.y) / cell_m_)), ny_),
                  j1 = clampi(static_cast<int>(std::floor((b.y - origin_.y) / cell_m_)), ny_);
        const int k0 = clampi(static_cast<int>(std::floor((a.z - origin_.z) / cell_m_)), nz_),
                  k1 = clampi(static_cast<int>(std::floor((b.z - origin_.z) / cell_m_)), nz_);
        for (int k = k0; k <= k1; ++k)
            for (int j = j0; j <= j1; ++j)
                for (int i = i0; i <= i1; ++i) f(static_cast<std::size_t>(cell_index(i, j, k)));
    };
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) for_cells(t, [&](std::size_t c) { ++counts[c + 1]; });
    for (std::size_t c = 0; c < cells; ++c) counts[c + 1] += counts[c];
    start_ = counts;
    items_.resize(counts[cells]);
    std::vector<std::uint32_t> fill(counts.begin(), counts.end() - 1);
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t)
        for_cells(t, [&](std::size_t c) { items_[fill[c]++] = static_cast<std::uint32_t>(t); });
}

std::int64_t TriangleLocator::cell_index(int i, int j, int k) const
{
    return (static_cast<std::int64_t>(k) * ny_ + j) * nx_ + i;
}

TriangleLocator::Hit TriangleLocator::nearest(const Vec3& p) const
{
    const auto& x = mesh_->vertices_m();
    Hit best;
    double best_d2 = std::numeric_limits<double>::infinity();
    const int ci = static_cast<int>(std::floor((p.x - origin_.x) / cell_m_));
    const int cj = static_cast<int>(std::floor((p.y - origin_.y) / cell_m_));
    const int ck = static_cast<int>(std::floor((p.z - origin_.z) / cell_m_));
    const int max_ring = std::max({nx_, ny_, nz_}) + std::max({std::abs(ci), std::abs(cj), std::abs(ck)}) + 1;
    for (int ring = 0; ring <= max_ring; ++ring) {
        // a triangle in ring r lies at least (r - 1) cells away: stop once that exceeds the best distance
        const double reach = (ring - 1) * cell_m_;
        if (ring > 0 && reach > 0.0 && reach * reach > best_d2) break;
        for (int k = ck - ring; k <= ck + ring; ++k)
            for (int j = cj - ring; j <= cj + ring; ++j)
                for (int i = ci - ring; i <= ci + ring; ++i) {
                    if (std::max({std::abs(i - ci), std::abs(j - cj), std::abs(k - ck)}) != ring) continue;
                    if (i < 0 || j < 0 || k < 0 || i >= nx_ || j >= ny_ || k >= nz_) continue;
                    const auto c = static_cast<std::size_t>(cell_index(i, j, k));
                    for (std::uint32_t q = start_[c]; q < start_[c + 1]; ++q) {
                        const auto& tri = mesh_->triangles()[items_[q]];
                        const ClosestPoint cp = closest_point_on_triangle(p, x[tri[0]], x[tri[1]], x[tri[2]]);
                        if (cp.distance_squared < best_d2) {
                            best_d2 = cp.distance_squared;
                            best.triangle = static_cast<std::int32_t>(items_[q]);
                            best.point_m = cp.point;
                        }
                    }
                }
    }
    best.distance_m = std::sqrt(best_d2);
    return best;
}

}  // namespace dipper::meshes
