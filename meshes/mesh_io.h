// Reading triangle meshes from STL, OBJ and PLY files, checked (meshes/mesh_file_check.h) before assimp reads them.
#pragma once

#include "meshes/triangle_mesh.h"

#include <string>

namespace dipper::meshes {

/// Loads every triangle of every mesh in the file into one TriangleMesh, identical vertices merged,
/// coordinates multiplied by `scale` (1 for files in metres, 0.001 for millimetres).
/// Throws InputError naming the file for a missing, unreadable or empty file and for degenerate triangles.
TriangleMesh load_triangle_mesh(const std::string& path, double scale = 1.0);

/// Writes a binary STL file (float32 coordinates: about 0.5 micrometre at 4 m), as CAD tools and ParaView read it.
void write_stl(const TriangleMesh& mesh, const std::string& path, const std::string& solid_name = "dipper");

}  // namespace dipper::meshes
