#include "meshes/mesh_io.h"

#include "core/errors.h"
#include "meshes/mesh_file_check.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <array>
#include <filesystem>
#include <map>
#include <algorithm>
#include <cstring>
#include <fstream>

namespace dipper::meshes {

TriangleMesh load_triangle_mesh(const std::string& path, double scale)
{
    require_positive(scale, "mesh scale", path);
    if (!std::filesystem::is_regular_file(path))
        throw InputError(concat("mesh file '", path, "' does not exist or is not a regular file"));

    check_mesh_file(path);  // assimp trusts the counts a file claims

    Assimp::Importer importer;
    // Identical vertices are merged so that shared edges are found; no other processing that would
    // move or drop geometry silently.
    const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
    if (scene == nullptr)
        throw InputError(concat("mesh file '", path, "' could not be read: ", importer.GetErrorString()));
    if (scene->mNumMeshes == 0) throw InputError(concat("mesh file '", path, "' contains no mesh"));

    // Vertices at exactly the same position are welded: formats such as STL store every facet's corners
    // separately (and assimp keeps them apart when their normals differ), but contacts need the shared
    // edges and vertices.
    std::vector<Vec3> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::map<std::array<double, 3>, std::uint32_t> welded;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* mesh = scene->mMeshes[m];
        std::vector<std::uint32_t> index(mesh->mNumVertices);
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            const aiVector3D& p = mesh->mVertices[v];
            const std::array<double, 3> key{p.x * scale, p.y * scale, p.z * scale};
            auto [it, inserted] = welded.try_emplace(key, static_cast<std::uint32_t>(vertices.size()));
            if (inserted) vertices.push_back({key[0], key[1], key[2]});
            index[v] = it->second;
        }
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices != 3) continue;  // points and lines carry no surface
            triangles.push_back({index[face.mIndices[0]], index[face.mIndices[1]], index[face.mIndices[2]]});
        }
    }
    if (triangles.empty()) throw InputError(concat("mesh file '", path, "' contains no triangles"));
    return TriangleMesh(std::move(vertices), std::move(triangles), "file '" + path + "'");
}

void write_stl(const TriangleMesh& mesh, const std::string& path, const std::string& solid_name)
{
    // binary STL: 80-byte header, triangle count, then per triangle normal and corners as float32 and a
    // 2-byte attribute (little-endian, as the format defines)
    std::ofstream out(path, std::ios::binary);
    if (!out) throw InputError(concat("cannot write STL file '", path, "'"));
    char header[80] = {};
    const std::string title = "dipper binary STL: " + solid_name;
    std::copy_n(title.begin(), std::min<std::size_t>(title.size(), 79), header);
    out.write(header, 80);
    const auto put_u32 = [&](std::uint32_t v) {
        const unsigned char b[4] = {static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8),
                                    static_cast<unsigned char>(v >> 16), static_cast<unsigned char>(v >> 24)};
        out.write(reinterpret_cast<const char*>(b), 4);
    };
    const auto put_vec = [&](const Vec3& v) {
        for (const double c : {v.x, v.y, v.z}) {
            const float f = static_cast<float>(c);
            std::uint32_t bits;
            std::memcpy(&bits, &f, 4);
            put_u32(bits);
        }
    };
    put_u32(static_cast<std::uint32_t>(mesh.triangle_count()));
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        put_vec(mesh.triangle_normal(t));
        for (const std::uint32_t v : mesh.triangles()[t]) put_vec(mesh.vertices_m()[v]);
        out.write("\0\0", 2);
    }
    out.flush();
    if (!out) throw InputError(concat("failed while writing STL file '", path, "'"));
}

}  // namespace dipper::meshes
