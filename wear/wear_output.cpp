#include "wear/wear_output.h"

#include "core/errors.h"
#include "meshes/vtk_surface.h"
#include "wear/image.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dipper::wear {

void write_wear_vtp(const WearSurface& s, const std::string& path, double tonnage_t, int smoothing_iterations,
                    const Mat3& rotation, const Vec3& translation_m)
{
    if (!(tonnage_t >= 0.0))
        throw InputError(concat("wear output '", path, "': tonnage is ", tonnage_t, " t; expected >= 0"));
    std::vector<Vec3> x = s.mesh().vertices_m();
    for (Vec3& v : x) v = rotation * v + translation_m;

    std::vector<double> cell_depth_mm = s.triangle_depth_m();
    for (double& d : cell_depth_mm) d *= 1000.0;
    std::vector<double> node_depth_mm = s.node_depth_m(smoothing_iterations);
    for (double& d : node_depth_mm) d *= 1000.0;
    const auto as_double = [](const std::vector<std::uint64_t>& v) { return std::vector<double>(v.begin(), v.end()); };

    std::vector<meshes::ScalarField> cells{{"depth_mm", cell_depth_mm},
                                           {"wear_volume_m3", s.triangle_volume_m3()},
                                           {"mean_normal_force_N", s.mean_normal_force_N()},
                                           {"mean_tangential_force_N", s.mean_tangential_force_N()},
                                           {"contact_steps", as_double(s.contact_steps())},
                                           {"impacts", as_double(s.impacts())}};
    std::vector<meshes::ScalarField> nodes{{"depth_mm", node_depth_mm}};
    if (tonnage_t > 0.0) {
        std::vector<double> cell_rate = cell_depth_mm, node_rate = node_depth_mm;
        for (double& r : cell_rate) r /= tonnage_t;
        for (double& r : node_rate) r /= tonnage_t;
        cells.emplace_back("rate_mm_per_t", std::move(cell_rate));
        nodes.emplace_back("rate_mm_per_t", std::move(node_rate));
    }
    meshes::write_surface_vtp(path, x, s.mesh().triangles(), nodes, cells);
}

namespace {

std::string tick_label(double value)
{
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.3g", value);
    return buffer;
}

}  // namespace

MapPicture write_wear_map_png(const WearSurface& s, const std::string& path, double tonnage_t,
                              int smoothing_iterations, const MapView& view)
{
    if (!(tonnage_t > 0.0))
        throw InputError(concat("wear map '", path, "': tonnage is ", tonnage_t, " t; expected > 0"));
    if (!(norm(view.toward_viewer) > 0.0) || !(norm(view.right) > 0.0))
        throw InputError(concat("wear map '", path, "': toward_viewer and right must be non-zero vectors"));
    require_in_range(view.max_angle_deg, 0.0, 90.0, "max_angle_deg", concat("wear map '", path, "'"));
    if (view.width_px < 200 || view.width_px > 8000)
        throw InputError(concat("wear map '", path, "': width_px is ", view.width_px, "; expected 200..8000"));

    // picture axes: u to the right, v up, both perpendicular to the viewing direction
    const Vec3 d = normalized(view.toward_viewer);
    const Vec3 r = view.right - d * dot(view.right, d);
    if (!(norm(r) > 1e-9 * norm(view.right)))
        throw InputError(concat("wear map '", path, "': 'right' is parallel to the viewing direction"));
    const Vec3 u = normalized(r), v = cross(d, u);

    const auto& mesh = s.mesh();
    const double cos_max = std::cos(view.max_angle_deg * M_PI / 180.0);
    std::vector<std::size_t> shown;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const auto& tri = mesh.triangles()[t];
        const Vec3 centroid = (mesh.vertices_m()[tri[0]] + mesh.vertices_m()[tri[1]] + mesh.vertices_m()[tri[2]]) * (1.0 / 3.0);
        if (dot(mesh.triangle_normal(t), d) >= cos_max && dot(centroid, d) <= view.max_along_view_m) shown.push_back(t);
    }
    if (shown.empty())
        throw InputError(concat("wear map '", path, "': no triangle of '", s.name(), "' faces the viewer within ",
                                view.max_angle_deg, " deg"));

    std::vector<double> rate = s.node_depth_m(smoothing_iterations);
    for (double& x : rate) x *= 1000.0 / tonnage_t;
    double umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300, rmax = 0.0;
    for (const std::size_t t : shown)
        for (const std::uint32_t k : mesh.triangles()[t]) {
            const Vec3& x = mesh.vertices_m()[k];
            umin = std::min(umin, dot(x, u));
            umax = std::max(umax, dot(x, u));
            vmin = std::min(vmin, dot(x, v));
            vmax = std::max(vmax, dot(x, v));
            rmax = std::max(rmax, rate[k]);
        }

    // layout: the map on the left, the colour bar and its labels on the right
    const int margin = 20, bar_w = 30, label_w = 150, text_scale = 2;
    const int map_w = view.width_px - 2 * margin - bar_w - label_w;
    const double extent_u = std::max(umax - umin, 1e-9), extent_v = std::max(vmax - vmin, 1e-9);
    const double px_per_m = map_w / extent_u;
    const int map_h = std::max(60, std::min(4000, static_cast<int>(std::ceil(extent_v * px_per_m))));
    const int title_h = 7 * text_scale + 16;
    Image image(view.width_px, map_h + 2 * margin + title_h);
    const int top = margin + title_h;

    const double lo = 0.0, hi = rmax > 0.0 ? rmax : 1.0;
    for (const std::size_t t : shown) {
        double px[3], py[3], val[3];
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t k = mesh.triangles()[t][static_cast<std::size_t>(c)];
            const Vec3& x = mesh.vertices_m()[k];
            px[c] = margin + (dot(x, u) - umin) * px_per_m;
            py[c] = top + (vmax - dot(x, v)) * px_per_m;  // v up in the picture
            val[c] = rate[k];
        }
        image.fill_triangle(px, py, val, lo, hi);
    }

    // colour bar, ticks and labels
    const Rgb black{0, 0, 0};
    const int bar_x = margin + map_w + margin;
    for (int y = 0; y < map_h; ++y)
        image.fill_rect(bar_x, top + y, bar_x + bar_w, top + y + 1, colour_ramp(1.0 - (y + 0.5) / map_h));
    for (int k = 0; k <= 4; ++k) {
        const int y = top + static_cast<int>(std::lround((1.0 - k / 4.0) * (map_h - 1)));
        image.fill_rect(bar_x + bar_w, y, bar_x + bar_w + 6, y + 1, black);
        image.draw_text(bar_x + bar_w + 10, std::max(0, y - 7), tick_label(hi * k / 4.0), text_scale, black);
    }
    image.draw_text(margin, margin / 2, "wear rate (mm/t)", text_scale, black);
    image.write_png(path);
    return {shown.size(), hi};
}

}  // namespace dipper::wear
