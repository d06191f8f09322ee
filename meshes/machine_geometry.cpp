#include "meshes/machine_geometry.h"

#include "core/errors.h"
#include "meshes/mesh_builder.h"

#include <algorithm>
#include <cmath>

namespace dipper::meshes {

namespace {

constexpr double kDeg = M_PI / 180.0;

/// Adds a planar quadrilateral (corners in order) as a bilinear grid of cells no longer than `size`.
void add_quad4(MeshBuilder& b, const std::array<Vec3, 4>& c, double size)
{
    const double lu = std::max(norm(c[1] - c[0]), norm(c[2] - c[3]));
    const double lv = std::max(norm(c[3] - c[0]), norm(c[2] - c[1]));
    const int nu = std::max(1, static_cast<int>(std::ceil(lu / size - 1e-9)));
    const int nv = std::max(1, static_cast<int>(std::ceil(lv / size - 1e-9)));
    const auto at = [&](int i, int j) {
        const double u = static_cast<double>(i) / nu, v = static_cast<double>(j) / nv;
        return c[0] * ((1 - u) * (1 - v)) + c[1] * (u * (1 - v)) + c[2] * (u * v) + c[3] * ((1 - u) * v);
    };
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const Vec3 p00 = at(i, j), p10 = at(i + 1, j), p11 = at(i + 1, j + 1), p01 = at(i, j + 1);
            b.add_triangle(p00, p10, p11);
            b.add_triangle(p00, p11, p01);
        }
}

}  // namespace

Vec3 Plate::normal() const
{
    return normalized(cross(corners_m[1] - corners_m[0], corners_m[3] - corners_m[0]));
}

bool Plate::contains(const Vec3& x) const
{
    const Vec3 n = normal();
    const double depth = dot(x - corners_m[0], n);
    if (depth > 0.0 || depth < -thickness_m) return false;
    for (std::size_t k = 0; k < 4; ++k) {
        const Vec3& a = corners_m[k];
        const Vec3& b = corners_m[(k + 1) % 4];
        if (dot(cross(b - a, x - a), n) < 0.0) return false;
    }
    return true;
}

std::vector<Vec3> Plate::solid_corners_m() const
{
    const Vec3 back = normal() * (-thickness_m);
    std::vector<Vec3> p(corners_m.begin(), corners_m.end());
    for (const Vec3& c : corners_m) p.push_back(c + back);
    return p;
}

Plate box_plate(const Vec3& lo, const Vec3& hi)
{
    return {{Vec3{lo.x, lo.y, hi.z}, Vec3{hi.x, lo.y, hi.z}, Vec3{hi.x, hi.y, hi.z}, Vec3{lo.x, hi.y, hi.z}}, hi.z - lo.z};
}

Plate oriented_plate(const std::array<Vec3, 4>& c, double thickness, const Vec3& towards)
{
    Plate p{c, thickness};
    if (dot(p.normal(), towards - c[0]) < 0.0) p.corners_m = {c[0], c[3], c[2], c[1]};
    return p;
}

MachinePart make_part(const std::string& name, std::vector<Plate> plates, double element_size_m)
{
    require_positive(element_size_m, "element_size_m", concat("part '", name, "'"));
    MeshBuilder b;
    MachinePart part;
    part.name = name;
    std::vector<std::size_t> triangle_count_after;
    for (std::size_t k = 0; k < plates.size(); ++k) {
        const Plate& p = plates[k];
        const std::string where = concat("part '", name, "', plate ", k);
        require_positive(p.thickness_m, "thickness_m", where);
        for (const Vec3& c : p.corners_m)
            if (!is_finite(c)) throw InputError(concat(where, ": a corner is not finite"));
        const Vec3 n0 = cross(p.corners_m[1] - p.corners_m[0], p.corners_m[3] - p.corners_m[0]);
        const double size = norm(p.corners_m[2] - p.corners_m[0]);
        if (!(norm(n0) > 1e-9 * size * size)) throw InputError(concat(where, ": the face has no area"));
        const Vec3 n = p.normal();
        for (int i = 0; i < 4; ++i) {
            const Vec3 e1 = p.corners_m[static_cast<std::size_t>((i + 1) % 4)] - p.corners_m[static_cast<std::size_t>(i)];
            const Vec3 e2 = p.corners_m[static_cast<std::size_t>((i + 2) % 4)] - p.corners_m[static_cast<std::size_t>((i + 1) % 4)];
            if (dot(cross(e1, e2), n) < -1e-12 * size * size)
                throw InputError(concat(where, ": the face is not convex or its corners are not in order"));
            if (std::abs(dot(p.corners_m[static_cast<std::size_t>(i)] - p.corners_m[0], n)) > 1e-9 * size)
                throw InputError(concat(where, ": the face's corners are not in one plane"));
        }
        const auto& c = p.corners_m;
        const Vec3 back = n * (-p.thickness_m);
        const std::array<Vec3, 4> d{c[0] + back, c[1] + back, c[2] + back, c[3] + back};
        const std::size_t before = b.triangle_count();
        add_quad4(b, c, element_size_m);  // the working face first
        const std::size_t face_end = b.triangle_count();
        add_quad4(b, {d[0], d[3], d[2], d[1]}, element_size_m);  // back face, normal -n
        for (int i = 0; i < 4; ++i) {
            const auto j = static_cast<std::size_t>((i + 1) % 4), ii = static_cast<std::size_t>(i);
            add_quad4(b, {c[ii], d[ii], d[j], c[j]}, element_size_m);  // side, normal outwards
        }
        for (std::size_t t = before; t < b.triangle_count(); ++t) {
            part.triangle_plate.push_back(static_cast<std::uint32_t>(k));
            part.triangle_on_face.push_back(t < face_end);
        }
    }
    part.plates = std::move(plates);
    part.surface = b.build(name, 1e-7);
    return part;
}

double enclosed_volume_m3(const TriangleMesh& m)
{
    double v = 0.0;
    const auto& x = m.vertices_m();
    for (const auto& t : m.triangles()) v += dot(x[t[0]], cross(x[t[1]], x[t[2]])) / 6.0;
    return v;
}

// ---- the dipper ---------------------------------------------------------------------------------

double Dipper::measured_rake_angle_deg() const
{
    const Vec3 heel_to_tip = normalized(tooth_tip_m);  // the heel is the origin
    const double c = std::abs(dot(heel_to_tip, handle_direction));
    return std::acos(std::clamp(c, 0.0, 1.0)) / kDeg;
}

Dipper make_dipper(const DipperParameters& p)
{
    const std::string where = "dipper";
    require_positive(p.width_m, "width_m", where);
    require_positive(p.height_m, "height_m", where);
    require_positive(p.bottom_length_m, "bottom_length_m", where);
    require_in_range(p.top_length_m, 0.1 * p.bottom_length_m, 2.0 * p.bottom_length_m, "top_length_m", where);
    require_in_range(p.plate_thickness_m, 1e-3, 0.5, "plate_thickness_m", where);
    require_in_range(p.lip_thickness_m, p.plate_thickness_m, 1.0, "lip_thickness_m (>= plate_thickness_m)", where);
    require_in_range(p.lip_length_m, 0.05, 0.5 * p.bottom_length_m, "lip_length_m", where);
    if (p.tooth_count < 0 || p.tooth_count > 20)
        throw InputError(concat(where, ": tooth_count is ", p.tooth_count, "; expected 0..20"));
    require_positive(p.tooth_length_m, "tooth_length_m", where);
    require_in_range(p.tooth_width_m, 0.01, p.width_m / std::max(1, p.tooth_count), "tooth_width_m", where);
    require_in_range(p.tooth_thickness_m, 0.01, 1.0, "tooth_thickness_m", where);
    require_in_range(p.rake_angle_deg, 30.0, 90.0, "rake_angle_deg", where);
    require_in_range(p.element_size_m, 0.01, 1.0, "element_size_m", where);
    require_in_range(p.bar_width_m, 0.01, 1.0, "bar_width_m", where);
    require_in_range(p.bar_height_m, 0.01, 0.5, "bar_height_m", where);
    require_in_range(p.bar_pitch_m, 2.0 * p.bar_width_m, p.bottom_length_m, "bar_pitch_m (>= 2 bar widths)", where);

    const double w = p.width_m, h = p.height_m, lb = p.bottom_length_m, lt = p.top_length_m, t = p.plate_thickness_m;
    const double y0 = -w / 2, y1 = w / 2;
    const Vec3 inside{lb / 3, 0.0, h / 2};
    std::vector<Plate> plates;
    // bottom (behind the lip) and the lip, full width including the side plates
    plates.push_back(box_plate({0.0, y0 - t, -t}, {lb - p.lip_length_m, y1 + t, 0.0}));
    plates.push_back(box_plate({lb - p.lip_length_m, y0 - t, -p.lip_thickness_m}, {lb, y1 + t, 0.0}));
    // sides: trapezoids from the heel to the lip and up to the top plate's front edge
    for (const double y : {y0, y1})
        plates.push_back(oriented_plate({Vec3{0, y, 0}, Vec3{lb, y, 0}, Vec3{lt, y, h}, Vec3{0, y, h}}, t, {inside.x, 0.0, inside.z}));
    // top plate, its face at z = h looking down into the dipper
    plates.push_back(oriented_plate({Vec3{0, y0 - t, h}, Vec3{lt, y0 - t, h}, Vec3{lt, y1 + t, h}, Vec3{0, y1 + t, h}}, t, inside));
    // teeth: forward of the lip, centred on its thickness
    const double tooth_z = -p.lip_thickness_m / 2;
    for (int k = 0; k < p.tooth_count; ++k) {
        const double yc = y0 + w * (k + 0.5) / p.tooth_count;
        plates.push_back(box_plate({lb, yc - p.tooth_width_m / 2, tooth_z - p.tooth_thickness_m / 2},
                                   {lb + p.tooth_length_m, yc + p.tooth_width_m / 2, tooth_z + p.tooth_thickness_m / 2}));
    }
    // wear bars on the bottom's inside face
    const double floor_end = lb - p.lip_length_m, bw = p.bar_width_m;
    if (p.wear_bars == WearBars::Transverse) {
        for (double xc = p.bar_pitch_m / 2; xc + bw / 2 <= floor_end; xc += p.bar_pitch_m)
            plates.push_back(box_plate({xc - bw / 2, y0, 0.0}, {xc + bw / 2, y1, p.bar_height_m}));
    } else if (p.wear_bars == WearBars::Diagonal) {
        // bars along (1, 1)/sqrt 2, i.e. 45 deg to the flow (x); each is the line x - y = c clipped to the
        // floor, shortened by half a bar width at each end so that the bar stays on the floor
        const Vec3 along = normalized(Vec3{1, 1, 0}), across = normalized(Vec3{-1, 1, 0});
        for (double c = -w / 2 - w; c <= floor_end + w / 2; c += p.bar_pitch_m) {
            // x = y + c with 0 <= x <= floor_end and y0 <= y <= y1
            const double ya = std::max(y0, -c), yb = std::min(y1, floor_end - c);
            if (yb - ya < 2.0 * bw) continue;
            const Vec3 a{ya + c, ya, 0.0}, b{yb + c, yb, 0.0};
            const Vec3 a2 = a + along * (bw / 2 * std::sqrt(2.0)), b2 = b - along * (bw / 2 * std::sqrt(2.0));
            if (dot(b2 - a2, along) <= bw) continue;
            const Vec3 lift{0, 0, p.bar_height_m}, half = across * (bw / 2);
            plates.push_back(oriented_plate({a2 - half + lift, b2 - half + lift, b2 + half + lift, a2 + half + lift},
                                            p.bar_height_m, a2 + Vec3{0, 0, 1.0}));
        }
    }

    Dipper d;
    d.parameters = p;
    const char* variant = p.wear_bars == WearBars::None ? "dipper" : (p.wear_bars == WearBars::Transverse ? "dipper_bars90" : "dipper_bars45");
    d.body = make_part(variant, std::move(plates), p.element_size_m);
    // the door: hinged on its top edge at (0, 0, h); in its own frame it hangs down from the hinge line
    d.door_hinge_m = {0.0, 0.0, h};
    d.door = make_part("door", {oriented_plate({Vec3{0, y0, -h}, Vec3{0, y1, -h}, Vec3{0, y1, 0}, Vec3{0, y0, 0}}, t, {1.0, 0.0, -h / 2})},
                       p.element_size_m);
    d.bail_pins_m[0] = {0.55 * lb, y0 - t, 0.6 * h};
    d.bail_pins_m[1] = {0.55 * lb, y1 + t, 0.6 * h};
    d.handle_pin_m = {0.15 * lt, 0.0, h + t};
    d.tooth_tip_m = {lb + p.tooth_length_m, 0.0, tooth_z};
    // the handle leaves the dipper through its top-rear: rotate the heel-tip direction about y so that the
    // lines meet at the rake angle, on the side of the top plate
    const Vec3 tip = normalized(d.tooth_tip_m);
    const double turn = (180.0 - p.rake_angle_deg) * kDeg;
    Vec3 handle = rotation_about_axis({0, 1, 0}, turn) * tip;
    if (handle.z < 0.0) handle = rotation_about_axis({0, 1, 0}, -turn) * tip;
    d.handle_direction = handle;

    // struck volume: the inside closed by the door plane (x = 0) and the strike plane from the lip to the
    // top plate's front edge, as a closed surface
    MeshBuilder inside_surface;
    const Vec3 a{0, y0, 0}, b{lb, y0, 0}, c{lt, y0, h}, e{0, y0, h};
    const Vec3 a1{0, y1, 0}, b1{lb, y1, 0}, c1{lt, y1, h}, e1{0, y1, h};
    inside_surface.add_triangle(a, b, c);  // side y0, outward -y
    inside_surface.add_triangle(a, c, e);
    inside_surface.add_triangle(a1, c1, b1);  // side y1, outward +y
    inside_surface.add_triangle(a1, e1, c1);
    inside_surface.add_quad(a, a1 - a, b - a, 1, 1);   // bottom, outward -z: (a1 - a) x (b - a) = -z
    inside_surface.add_quad(e, c - e, e1 - e, 1, 1);   // top, outward +z
    inside_surface.add_quad(a, e - a, a1 - a, 1, 1);   // door plane, outward -x
    inside_surface.add_quad(b, b1 - b, c - b, 1, 1);   // strike plane, outward
    d.struck_volume_m3 = enclosed_volume_m3(inside_surface.build("dipper inside", 1e-9));
    return d;
}

// ---- feeder, truck, ground ------------------------------------------------------------------------

Feeder make_feeder(const FeederParameters& p)
{
    const std::string where = "feeder";
    require_positive(p.pan_length_m, "pan_length_m", where);
    require_positive(p.pan_width_m, "pan_width_m", where);
    require_positive(p.side_height_m, "side_height_m", where);
    require_positive(p.bin_height_m, "bin_height_m", where);
    require_in_range(p.bin_flare_deg, 0.0, 60.0, "bin_flare_deg", where);
    require_in_range(p.bin_length_m, 0.5, p.pan_length_m, "bin_length_m", where);
    require_in_range(p.plate_thickness_m, 1e-3, 0.5, "plate_thickness_m", where);
    const double l = p.pan_length_m, w = p.pan_width_m, hs = p.side_height_m, t = p.plate_thickness_m;
    std::vector<Plate> pan;
    for (int k = 0; k < 3; ++k)  // three floor plates of equal length; the first two are measured for wear
        pan.push_back(box_plate({l * k / 3.0, -w / 2, -t}, {l * (k + 1) / 3.0, w / 2, 0.0}));
    for (const double y : {-w / 2, w / 2})
        pan.push_back(oriented_plate({Vec3{0, y, 0}, Vec3{l, y, 0}, Vec3{l, y, hs}, Vec3{0, y, hs}}, t, {l / 2, 0, hs / 2}));
    pan.push_back(oriented_plate({Vec3{0, -w / 2, 0}, Vec3{0, w / 2, 0}, Vec3{0, w / 2, hs}, Vec3{0, -w / 2, hs}}, t, {l / 2, 0, hs / 2}));

    // the bin: a rear wall and two side walls leaning outwards from the top of the pan's sides
    const double out = p.bin_height_m * std::tan(p.bin_flare_deg * kDeg), lb = p.bin_length_m, z0 = hs, z1 = hs + p.bin_height_m;
    std::vector<Plate> bin;
    const Vec3 centre{lb / 2, 0, z0 + p.bin_height_m / 2};
    bin.push_back(oriented_plate({Vec3{0, -w / 2, z0}, Vec3{lb, -w / 2, z0}, Vec3{lb, -w / 2 - out, z1}, Vec3{0, -w / 2 - out, z1}}, t, centre));
    bin.push_back(oriented_plate({Vec3{0, w / 2, z0}, Vec3{lb, w / 2, z0}, Vec3{lb, w / 2 + out, z1}, Vec3{0, w / 2 + out, z1}}, t, centre));
    bin.push_back(oriented_plate({Vec3{0, -w / 2, z0}, Vec3{0, w / 2, z0}, Vec3{-out, w / 2 + out, z1}, Vec3{-out, -w / 2 - out, z1}}, t, centre));
    return {make_part("feeder_pan", std::move(pan), p.element_size_m), make_part("feeder_bin", std::move(bin), p.element_size_m)};
}

MachinePart make_truck_body(const TruckBodyParameters& p)
{
    const std::string where = "truck body";
    require_positive(p.length_m, "length_m", where);
    require_positive(p.width_m, "width_m", where);
    require_positive(p.depth_m, "depth_m", where);
    require_in_range(p.plate_thickness_m, 1e-3, 0.5, "plate_thickness_m", where);
    const double l = p.length_m, w = p.width_m, d = p.depth_m, t = p.plate_thickness_m;
    const Vec3 inside{l / 2, 0, d / 2};
    std::vector<Plate> plates;
    plates.push_back(box_plate({0, -w / 2 - t, -t}, {l, w / 2 + t, 0}));
    for (const double y : {-w / 2, w / 2})
        plates.push_back(oriented_plate({Vec3{0, y, 0}, Vec3{l, y, 0}, Vec3{l, y, d}, Vec3{0, y, d}}, t, inside));
    // the front wall leans forward 20 deg over the cab side (x = 0); the tail (x = l) stays open
    const double lean = d * std::tan(20.0 * kDeg);
    plates.push_back(oriented_plate({Vec3{0, -w / 2, 0}, Vec3{0, w / 2, 0}, Vec3{-lean, w / 2, d}, Vec3{-lean, -w / 2, d}}, t, inside));
    return make_part("truck_body", std::move(plates), p.element_size_m);
}

MachinePart make_ground(double size_x_m, double size_y_m, double element_size_m)
{
    require_positive(size_x_m, "size_x_m", "ground");
    require_positive(size_y_m, "size_y_m", "ground");
    return make_part("ground", {box_plate({-size_x_m / 2, -size_y_m / 2, -0.5}, {size_x_m / 2, size_y_m / 2, 0.0})}, element_size_m);
}

}  // namespace dipper::meshes
