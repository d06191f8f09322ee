// ParaView (VTK XML PolyData) files of triangle surfaces with fields on their nodes and triangles.
#pragma once

#include "core/vec3.h"

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace dipper::meshes {

/// A named scalar field, one value per node or per triangle.
using ScalarField = std::pair<std::string, std::vector<double>>;

/// Writes a .vtp surface. Every point field must have one value per vertex, every cell field one per
/// triangle (checked).
void write_surface_vtp(const std::string& path, const std::vector<Vec3>& vertices_m,
                       const std::vector<std::array<std::uint32_t, 3>>& triangles,
                       const std::vector<ScalarField>& point_fields = {},
                       const std::vector<ScalarField>& cell_fields = {});

}  // namespace dipper::meshes
