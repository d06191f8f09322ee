#include "meshes/mesh_io.h"

#include "core/errors.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <filesystem>
#include <fstream>

namespace dipper::meshes {

TriangleMesh load_triangle_mesh(const std::string& path, double scale)
{
    require_positive(scale, "mesh scale", path);
    if (!std::filesystem::is_regular_file(path))
        throw InputError(concat("mesh file '", path, "' does not exist or is not a regular file"));

    Assimp::Importer importer;
    // Identical vertices are merged so that shared edges are found; no other processing that would
    // move or drop geometry silently.
    const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
    if (scene == nullptr)
        throw InputError(concat("mesh file '", path, "' could not be read: ", importer.GetErrorString()));
    if (scene->mNumMeshes == 0) throw InputError(concat("mesh file '", path, "' contains no mesh"));

    std::vector<Vec3> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* mesh = scene->mMeshes[m];
        const auto base = static_cast<std::uint32_t>(vertices.size());
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            const aiVector3D& p = mesh->mVertices[v];
            vertices.push_back({p.x * scale, p.y * scale, p.z * scale});
        }
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices != 3) continue;  // points and lines carry no surface
            triangles.push_back({base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
        }
    }
    if (triangles.empty()) throw InputError(concat("mesh file '", path, "' contains no triangles"));
    return TriangleMesh(std::move(vertices), std::move(triangles), "file '" + path + "'");
}

void write_stl(const TriangleMesh& mesh, const std::string& path, const std::string& solid_name)
{
    std::ofstream out(path);
    if (!out) throw InputError(concat("cannot write STL file '", path, "'"));
    out.precision(12);
    out << "solid " << solid_name << "\n";
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const Vec3& n = mesh.triangle_normal(t);
        out << "  facet normal " << n.x << ' ' << n.y << ' ' << n.z << "\n    outer loop\n";
        for (std::uint32_t v : mesh.triangles()[t]) {
            const Vec3& p = mesh.vertices_m()[v];
            out << "      vertex " << p.x << ' ' << p.y << ' ' << p.z << "\n";
        }
        out << "    endloop\n  endfacet\n";
    }
    out << "endsolid " << solid_name << "\n";
    if (!out) throw InputError(concat("failed while writing STL file '", path, "'"));
}

}  // namespace dipper::meshes
