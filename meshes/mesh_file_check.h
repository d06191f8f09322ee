// Checks a mesh file's structure before assimp reads it: assimp trusts the counts a file claims, so a
// truncated PLY aborted the process in its triangulation, a header claiming 10^11 vertices spun for ever,
// and an ASCII STL cut in the middle loaded half its triangles without a word.
#pragma once

#include <cstdint>
#include <string>

namespace dipper::meshes {

/// The most a mesh file may hold: larger is a mistake for a machine part or a wall (the generated dipper
/// has about 10^4 triangles) and would take minutes and gigabytes to read.
inline constexpr std::uint64_t kMaxMeshFileBytes = 1ull << 30;
inline constexpr std::uint64_t kMaxMeshTriangles = 20'000'000;

/// What a checked file holds.
struct MeshFileSummary {
    std::string format;  ///< "binary STL", "ASCII STL", "ASCII PLY", "binary PLY", "OBJ"
    std::uint64_t vertices = 0, faces = 0;
};

/// Reads the whole file and checks that it is a complete STL (binary or ASCII), PLY (ASCII or binary) or
/// OBJ file: every count it claims is met by its body, every face names vertices that exist, every number
/// is finite, and it ends where its format says it ends. Throws an InputError naming the file, the line
/// (or byte) and what was expected otherwise.
MeshFileSummary check_mesh_file(const std::string& path);

}  // namespace dipper::meshes
