// Builds machine surfaces from flat pieces: quads split into cells, triangles, and other meshes, with
// coincident vertices welded so that neighbouring pieces share their edges.
#pragma once

#include "meshes/triangle_mesh.h"

#include <string>
#include <vector>

namespace dipper::meshes {

class MeshBuilder {
public:
    /// The parallelogram origin + s edge_u + t edge_v (s, t in [0, 1]) as nu x nv cells of two triangles;
    /// its normal is edge_u x edge_v (normalised).
    void add_quad(const Vec3& origin_m, const Vec3& edge_u_m, const Vec3& edge_v_m, int nu, int nv);
    /// The same with cells of at most `element_size_m` along each edge.
    void add_quad_sized(const Vec3& origin_m, const Vec3& edge_u_m, const Vec3& edge_v_m, double element_size_m);
    void add_triangle(const Vec3& a, const Vec3& b, const Vec3& c);
    void add_mesh(const TriangleMesh& mesh, const Mat3& rotation = Mat3::identity(), const Vec3& translation_m = {});
    std::size_t triangle_count() const { return triangles_.size(); }
    /// The mesh, with vertices closer than `weld_m` merged.
    TriangleMesh build(const std::string& source, double weld_m = 1e-9) const;

private:
    std::vector<Vec3> vertices_;
    std::vector<std::array<std::uint32_t, 3>> triangles_;
};

/// An open box (a tray): floor [0, size_x] x [0, size_y] at z = 0 and four walls up to `height`, normals
/// pointing into the box, cells of at most element_size_m.
TriangleMesh make_open_box_mesh(double size_x_m, double size_y_m, double height_m, double element_size_m);

}  // namespace dipper::meshes
