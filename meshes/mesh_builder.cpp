#include "meshes/mesh_builder.h"

#include "core/errors.h"

#include <cmath>
#include <map>
#include <tuple>

namespace dipper::meshes {

void MeshBuilder::add_quad(const Vec3& o, const Vec3& eu, const Vec3& ev, int nu, int nv)
{
    if (nu < 1 || nv < 1) throw InputError(concat("mesh quad: cell counts must be >= 1; got ", nu, " x ", nv));
    const auto base = static_cast<std::uint32_t>(vertices_.size());
    for (int j = 0; j <= nv; ++j)
        for (int i = 0; i <= nu; ++i) vertices_.push_back(o + eu * (static_cast<double>(i) / nu) + ev * (static_cast<double>(j) / nv));
    const auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(j * (nu + 1) + i); };
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            triangles_.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            triangles_.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
}

void MeshBuilder::add_quad_sized(const Vec3& o, const Vec3& eu, const Vec3& ev, double element_size_m)
{
    require_positive(element_size_m, "element_size_m", "mesh quad");
    add_quad(o, eu, ev, std::max(1, static_cast<int>(std::ceil(norm(eu) / element_size_m - 1e-9))),
             std::max(1, static_cast<int>(std::ceil(norm(ev) / element_size_m - 1e-9))));
}

void MeshBuilder::add_triangle(const Vec3& a, const Vec3& b, const Vec3& c)
{
    const auto base = static_cast<std::uint32_t>(vertices_.size());
    vertices_.insert(vertices_.end(), {a, b, c});
    triangles_.push_back({base, base + 1, base + 2});
}

void MeshBuilder::add_mesh(const TriangleMesh& mesh, const Mat3& rotation, const Vec3& translation_m)
{
    const auto base = static_cast<std::uint32_t>(vertices_.size());
    for (const Vec3& v : mesh.vertices_m()) vertices_.push_back(rotation * v + translation_m);
    for (const auto& t : mesh.triangles()) triangles_.push_back({base + t[0], base + t[1], base + t[2]});
}

TriangleMesh MeshBuilder::build(const std::string& source, double weld_m) const
{
    // weld by a grid of cell weld_m: candidates in the 27 neighbouring cells
    std::map<std::tuple<long long, long long, long long>, std::vector<std::uint32_t>> grid;
    std::vector<std::uint32_t> remap(vertices_.size());
    std::vector<Vec3> kept;
    const auto cell = [&](double x) { return static_cast<long long>(std::floor(x / weld_m)); };
    for (std::size_t k = 0; k < vertices_.size(); ++k) {
        const Vec3& v = vertices_[k];
        const long long cx = cell(v.x), cy = cell(v.y), cz = cell(v.z);
        std::uint32_t found = UINT32_MAX;
        for (long long dx = -1; dx <= 1 && found == UINT32_MAX; ++dx)
            for (long long dy = -1; dy <= 1 && found == UINT32_MAX; ++dy)
                for (long long dz = -1; dz <= 1 && found == UINT32_MAX; ++dz) {
                    const auto it = grid.find({cx + dx, cy + dy, cz + dz});
                    if (it == grid.end()) continue;
                    for (const std::uint32_t q : it->second)
                        if (norm(kept[q] - v) <= weld_m) { found = q; break; }
                }
        if (found == UINT32_MAX) {
            found = static_cast<std::uint32_t>(kept.size());
            kept.push_back(v);
            grid[{cx, cy, cz}].push_back(found);
        }
        remap[k] = found;
    }
    std::vector<std::array<std::uint32_t, 3>> tris;
    tris.reserve(triangles_.size());
    for (const auto& t : triangles_) tris.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
    return TriangleMesh(std::move(kept), std::move(tris), source);
}

TriangleMesh make_open_box_mesh(double sx, double sy, double h, double element_size_m)
{
    require_positive(sx, "size_x_m", "open box");
    require_positive(sy, "size_y_m", "open box");
    require_positive(h, "height_m", "open box");
    MeshBuilder b;
    b.add_quad_sized({0, 0, 0}, {sx, 0, 0}, {0, sy, 0}, element_size_m);     // floor, normal +z
    b.add_quad_sized({0, 0, 0}, {0, 0, h}, {sx, 0, 0}, element_size_m);      // wall y = 0, normal +y
    b.add_quad_sized({0, sy, 0}, {sx, 0, 0}, {0, 0, h}, element_size_m);     // wall y = sy, normal -y
    b.add_quad_sized({0, 0, 0}, {0, sy, 0}, {0, 0, h}, element_size_m);      // wall x = 0, normal +x
    b.add_quad_sized({sx, 0, 0}, {0, 0, h}, {0, sy, 0}, element_size_m);     // wall x = sx, normal -x
    return b.build("open box");
}

}  // namespace dipper::meshes
