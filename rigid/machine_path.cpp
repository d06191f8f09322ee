#include "rigid/machine_path.h"

#include "core/errors.h"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace dipper::rigid {

namespace {

constexpr double kDeg = M_PI / 180.0;
Mat3 rot_y(double angle_rad) { return rotation_about_axis({0.0, 1.0, 0.0}, angle_rad); }
Mat3 rot_z(double angle_rad) { return rotation_about_axis({0.0, 0.0, 1.0}, angle_rad); }

/// A pose x_world = r x + o.
struct Pose {
    Mat3 r = Mat3::identity();
    Vec3 o;
};
Pose operator*(const Pose& a, const Pose& b) { return {a.r * b.r, a.r * b.o + a.o}; }

/// The handle angle (deg below the horizontal) at which the ropes are just taut at `hoist_m` and crowd `crowd_m`,
/// as RigidWorld::add_rope_shovel finds the first one: paid out beyond reach, the dipper hangs as low as it goes.
double taut_handle_angle_deg(const ShovelGeometry& g, const meshes::Dipper& d, double hoist_m, double crowd_m)
{
    double lo = -60.0, hi = 89.0;  // the rope shortens as the handle rises
    const double length_lo = pose_shovel(g, d, lo, crowd_m).rope_length_m;
    const double length_hi = pose_shovel(g, d, hi, crowd_m).rope_length_m;
    if (hoist_m >= std::max(length_lo, length_hi)) return length_lo > length_hi ? lo : hi;
    if (hoist_m <= std::min(length_lo, length_hi)) return length_lo < length_hi ? lo : hi;
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        const double length = pose_shovel(g, d, mid, crowd_m).rope_length_m;
        if ((length - hoist_m) * (length_lo - hoist_m) > 0.0) lo = mid;
        else hi = mid;
    }
    return 0.5 * (lo + hi);
}

/// Where the five parts are at one sample of the curves. The multibody's joints (rope_shovel.cpp): the upper
/// body turns about z at the swing axis, the saddle about y at the shipper shaft (the handle angle), the handle
/// slides along its axis (the crowd), the door turns about y at its hinge; at joint positions 0 every link has
/// the machine's axes.
struct ShovelPoser {
    const ShovelGeometry& g;
    const meshes::Dipper& d;
    Vec3 position_m;
    double heading_deg;
    ShovelPose zero = pose_shovel(g, d, 0.0, 0.0);

    std::vector<Pose> at(const MotionSample& m) const
    {
        const Pose base{rot_z(heading_deg * kDeg), position_m + Vec3{std::cos(heading_deg * kDeg), std::sin(heading_deg * kDeg), 0.0} * m.propel_m};
        const Pose upper = base * Pose{rot_z(m.swing_deg * kDeg), {}};
        const double angle = taut_handle_angle_deg(g, d, m.hoist_length_m, m.crowd_extension_m) * kDeg;
        // a point at p in the machine frame at the zero pose, on the handle's link: shaft + R_y(angle)(p - shaft + s x)
        const Mat3 r_handle = rot_y(angle);
        const Vec3 shaft = zero.shipper_shaft_m;
        const auto on_handle = [&](const Vec3& p) { return shaft + r_handle * (p - shaft + Vec3{m.crowd_extension_m, 0.0, 0.0}); };
        const Pose handle{r_handle, on_handle(shaft - zero.handle_axis * (g.handle_length_m / 2.0))};
        const Pose dipper{r_handle * zero.dipper_rotation, on_handle(zero.dipper_origin_m)};
        const Vec3 hinge = zero.dipper_origin_m + zero.dipper_rotation * d.door_hinge_m;
        const Pose door{r_handle * rot_y(m.door_deg * kDeg) * zero.dipper_rotation, on_handle(hinge)};
        return {base, upper, upper * handle, upper * dipper, upper * door};
    }
};

/// The largest distance any point of a box [lo, hi] moves from pose a to pose b (at a corner: the motion of a
/// point is affine in it, so its length is convex).
double largest_move(const Vec3& lo, const Vec3& hi, const Pose& a, const Pose& b)
{
    double most = 0.0;
    for (int k = 0; k < 8; ++k) {
        const Vec3 c{(k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z};
        most = std::max(most, norm((b.r * c + b.o) - (a.r * c + a.o)));
    }
    return most;
}

using Bvh = fcl::BVHModel<fcl::OBBRSSd>;

std::shared_ptr<Bvh> make_bvh(const meshes::TriangleMesh& mesh)
{
    std::vector<fcl::Vector3d> points;
    points.reserve(mesh.vertex_count());
    for (const Vec3& v : mesh.vertices_m()) points.emplace_back(v.x, v.y, v.z);
    std::vector<fcl::Triangle> triangles;
    triangles.reserve(mesh.triangle_count());
    for (const auto& t : mesh.triangles()) triangles.emplace_back(t[0], t[1], t[2]);
    auto model = std::make_shared<Bvh>();
    model->beginModel(static_cast<int>(triangles.size()), static_cast<int>(points.size()));
    model->addSubModel(points, triangles);
    model->endModel();
    return model;
}

fcl::Transform3d to_fcl(const Mat3& r, const Vec3& o)
{
    fcl::Transform3d t = fcl::Transform3d::Identity();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) t.linear()(i, j) = r.m[i][j];
    t.translation() = fcl::Vector3d(o.x, o.y, o.z);
    return t;
}

}  // namespace

std::vector<PartPath> shovel_path(const ShovelGeometry& geometry, const meshes::Dipper& dipper, const MotionCurves& motion,
                                  const Vec3& position_m, double heading_deg, double max_move_m)
{
    if (!(max_move_m > 0.0) || !std::isfinite(max_move_m)) throw InputError(concat("shovel_path: max_move_m is ", max_move_m, "; expected > 0"));
    const ShovelPoser poser{geometry, dipper, position_m, heading_deg};
    const double half = geometry.handle_section_m / 2.0;
    std::vector<PartPath> parts(5);
    parts[0].name = "crawlers";
    parts[0].surface = meshes::make_box_mesh({-4.5, -4.0, 0.0}, {4.5, 4.0, 2.0});  // RigidWorld::add_rope_shovel's boxes
    parts[1].name = "upper body";
    parts[1].surface = meshes::make_box_mesh({-5.0, -4.0, 2.0}, {5.0, 4.0, 7.0});
    parts[2].name = "handle";
    parts[2].surface = meshes::make_box_mesh({-geometry.handle_length_m / 2.0, -half, -half}, {geometry.handle_length_m / 2.0, half, half});
    parts[3].name = "dipper";
    parts[3].surface = dipper.body.surface;
    parts[4].name = "door";
    parts[4].surface = dipper.door.surface;

    const double t0 = motion.samples().front().time_s, t1 = motion.duration_s();
    constexpr double kLongest_s = 0.05, kShortest_s = 1e-4;
    double t = t0;
    std::vector<Pose> now = poser.at(motion.at(t));
    for (;;) {
        for (std::size_t k = 0; k < parts.size(); ++k) {
            parts[k].times_s.push_back(t);
            parts[k].rotations.push_back(now[k].r);
            parts[k].origins_m.push_back(now[k].o);
        }
        if (t >= t1) break;
        double dt = std::min(kLongest_s, t1 - t);
        std::vector<Pose> next = poser.at(motion.at(t + dt));
        for (;;) {
            double most = 0.0;
            for (std::size_t k = 0; k < parts.size(); ++k)
                most = std::max(most, largest_move(parts[k].surface.bounds_min_m(), parts[k].surface.bounds_max_m(), now[k], next[k]));
            if (most <= max_move_m || dt <= kShortest_s) break;
            dt = std::max(kShortest_s, dt * std::max(0.1, 0.9 * max_move_m / most));
            next = poser.at(motion.at(t + dt));
        }
        t = t + dt >= t1 - 1e-12 ? t1 : t + dt;
        now = std::move(next);
    }
    return parts;
}

namespace {

/// How far a part at pose (r, o) reaches behind a plane (into the steel against its normal), and its deepest
/// vertex. The 8 corners of the part's box bound it from below: most samples end there.
double depth_behind_plane(const meshes::TriangleMesh& surface, const Mat3& r, const Vec3& o, const Vec3& n, double d, Vec3& deepest)
{
    const Vec3 lo = surface.bounds_min_m(), hi = surface.bounds_max_m();
    double bound = 0.0;
    for (int k = 0; k < 8; ++k) {
        const Vec3 c{(k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z};
        bound = std::max(bound, d - dot(n, r * c + o));
    }
    if (bound <= 0.0) return 0.0;
    double depth = 0.0;
    for (const Vec3& v : surface.vertices_m()) {
        const Vec3 x = r * v + o;
        const double behind = d - dot(n, x);
        if (behind > depth) {
            depth = behind;
            deepest = x;
        }
    }
    return depth;
}

}  // namespace

std::vector<PathCrossing> find_crossings(const std::vector<PartPath>& parts, const std::vector<PathObstacle>& obstacles, double min_depth_m)
{
    // A plane is checked by the part's vertices: FCL's half-space bounds every node of a part's tree by an
    // unbounded box, so its query visits all of a part's triangles at every sample (98 s for the default cycle's
    // dipper against the ground, against 0.1 s here). A mesh wall is a surface, as the DEM sees it: FCL's
    // query of the two triangle trees finds where a part's surface cuts through it.
    std::vector<std::shared_ptr<Bvh>> walls;
    for (const PathObstacle& o : obstacles) walls.push_back(o.is_plane ? nullptr : make_bvh(o.surface));
    std::vector<PathCrossing> crossings;
    fcl::CollisionRequestd request(64, true);
    for (const PartPath& part : parts) {
        fcl::CollisionObjectd moving(make_bvh(part.surface));
        for (std::size_t w = 0; w < obstacles.size(); ++w) {
            const PathObstacle& o = obstacles[w];
            std::unique_ptr<fcl::CollisionObjectd> wall;
            if (!o.is_plane) wall = std::make_unique<fcl::CollisionObjectd>(walls[w], to_fcl(o.rotation, o.translation_m));
            const Vec3 n = o.is_plane ? normalized(o.normal) : Vec3{};
            const double d = dot(n, o.point_m);
            bool inside = false;
            PathCrossing c;
            for (std::size_t s = 0; s < part.times_s.size(); ++s) {
                const double t = part.times_s[s];
                double depth = 0.0;
                Vec3 point;
                if (t < o.removed_at_s && o.is_plane) {
                    depth = depth_behind_plane(part.surface, part.rotations[s], part.origins_m[s], n, d, point);
                } else if (t < o.removed_at_s) {
                    if (o.pose) {
                        Mat3 r;
                        Vec3 p;
                        o.pose(t, r, p);
                        wall->setTransform(to_fcl(r, p));
                    }
                    moving.setTransform(to_fcl(part.rotations[s], part.origins_m[s]));
                    fcl::CollisionResultd result;
                    if (fcl::collide(&moving, wall.get(), request, result) > 0)
                        for (std::size_t k = 0; k < result.numContacts(); ++k) {
                            const fcl::Contactd& contact = result.getContact(k);
                            if (contact.penetration_depth > depth) {
                                depth = contact.penetration_depth;
                                point = {contact.pos.x(), contact.pos.y(), contact.pos.z()};
                            }
                        }
                }
                if (depth > min_depth_m) {
                    if (!inside) c = PathCrossing{part.name, o.name, t, t, t, 0.0, {}};
                    inside = true;
                    c.to_s = t;
                    if (depth > c.depth_m) {
                        c.depth_m = depth;
                        c.deepest_s = t;
                        c.point_m = point;
                    }
                } else if (inside) {
                    crossings.push_back(c);
                    inside = false;
                }
            }
            if (inside) crossings.push_back(c);
        }
    }
    return crossings;
}

std::string describe(const PathCrossing& c)
{
    char text[400];
    std::snprintf(text, sizeof text, "%s passes %.2f m into wall '%s' from %.2f s to %.2f s (deepest at %.2f s, at (%.2f, %.2f, %.2f) m)",
                  c.part.c_str(), c.depth_m, c.obstacle.c_str(), c.from_s, c.to_s, c.deepest_s, c.point_m.x, c.point_m.y, c.point_m.z);
    return text;
}

}  // namespace dipper::rigid
