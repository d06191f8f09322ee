// What an engineer looks at: the wear surface as a ParaView file with its fields. The pictures of it (shaded
// 3-D views coloured by wear) are drawn from these files by the report (app/render.py).
#pragma once

#include "wear/wear_surface.h"

#include <cstdint>
#include <string>
#include <vector>

namespace dipper::wear {

/// Writes the surface (.vtp) with per-triangle wear_volume_m3, depth_mm, mean_normal_force_N,
/// mean_tangential_force_N, contact_steps, impacts, and per-node depth_mm after `smoothing_iterations`.
/// With tonnage_t > 0 the wear rate (rate_mm_per_t) is added per triangle and per node; tonnage_t == 0
/// means no tonnage is known yet; a negative tonnage is an InputError. The vertices are written as
/// rotation * x + translation (the part's pose; identity by default). With `triangle_plate` (one entry per
/// triangle) a cell field `plate` says which plate of the part each triangle belongs to.
void write_wear_vtp(const WearSurface& surface, const std::string& path, double tonnage_t, int smoothing_iterations,
                    const Mat3& rotation = Mat3::identity(), const Vec3& translation_m = {},
                    const std::vector<std::uint32_t>& triangle_plate = {});

}  // namespace dipper::wear
