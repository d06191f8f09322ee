// What an engineer looks at: the wear surface as a ParaView file with its fields, and a PNG wear map of
// one face of the part in mm/t with a labelled colour bar.
#pragma once

#include "wear/wear_surface.h"

#include <limits>
#include <string>

namespace dipper::wear {

/// Writes the surface (.vtp) with per-triangle wear_volume_m3, depth_mm, mean_normal_force_N,
/// mean_tangential_force_N, contact_steps, impacts, and per-node depth_mm after `smoothing_iterations`.
/// With tonnage_t > 0 the wear rate (rate_mm_per_t) is added per triangle and per node; tonnage_t == 0
/// means no tonnage is known yet; a negative tonnage is an InputError. The vertices are written as
/// rotation * x + translation (the part's pose; identity by default).
void write_wear_vtp(const WearSurface& surface, const std::string& path, double tonnage_t, int smoothing_iterations,
                    const Mat3& rotation = Mat3::identity(), const Vec3& translation_m = {});

/// Which face of the part a wear map shows, and how: the triangles whose normal is within max_angle_deg of
/// `toward_viewer` are drawn, projected along it; `right` is the direction that points right in the picture.
struct MapView {
    Vec3 toward_viewer{0.0, 0.0, 1.0};
    Vec3 right{1.0, 0.0, 0.0};
    double max_angle_deg = 30.0;
    int width_px = 900;
    /// Triangles whose centroid lies farther towards the viewer than this (dot(centroid, toward_viewer),
    /// toward_viewer normalised) are left out: the outside of a top plate hides the bottom under it.
    double max_along_view_m = std::numeric_limits<double>::infinity();
};

struct MapPicture {
    std::size_t triangles_drawn = 0;
    double rate_max_mm_per_t = 0.0;  ///< top of the colour bar
};

/// Writes a PNG of the nodal wear rate (mm/t, after smoothing) on the chosen face, with a colour bar
/// labelled "wear rate (mm/t)" from 0 to the largest rate shown. Throws InputError if tonnage_t <= 0 or if
/// no triangle faces the viewer.
MapPicture write_wear_map_png(const WearSurface& surface, const std::string& path, double tonnage_t,
                              int smoothing_iterations, const MapView& view = {});

}  // namespace dipper::wear
