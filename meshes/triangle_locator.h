// Finds the triangle of a mesh nearest to a point quickly: a uniform grid of triangle bounding boxes.
#pragma once

#include "meshes/triangle_mesh.h"

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace dipper::meshes {

class TriangleLocator {
public:
    /// `mesh` must outlive the locator. cell_m defaults to twice the mean triangle edge.
    explicit TriangleLocator(const TriangleMesh& mesh, double cell_m = 0.0);
    struct Hit {
        std::int32_t triangle = -1;
        double distance_m = 0.0;
        Vec3 point_m;
    };
    /// The nearest triangle to p (exact): searches the grid outwards until no closer triangle can exist.
    Hit nearest(const Vec3& p) const;

private:
    const TriangleMesh* mesh_;
    double cell_m_;
    Vec3 origin_;
    int nx_, ny_, nz_;
    std::vector<std::uint32_t> start_, items_;  // cell -> triangles (CSR)
    std::int64_t cell_index(int i, int j, int k) const;
};

}  // namespace dipper::meshes
