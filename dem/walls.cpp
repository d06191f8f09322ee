#include "dem/walls.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace dipper::dem {

Vec3 PrescribedMotion::pivot_position_m(double t_s) const
{
    const double tau = moving_s(t_s);
    return pivot_m + velocity_m_per_s * tau + oscillation_amplitude_m * std::sin(2.0 * M_PI * oscillation_frequency_Hz * tau);
}

Vec3 PrescribedMotion::pivot_velocity_m_per_s(double t_s) const
{
    if (!moving_at(t_s)) return {};
    const double w = 2.0 * M_PI * oscillation_frequency_Hz;
    return velocity_m_per_s + oscillation_amplitude_m * (w * std::cos(w * moving_s(t_s)));
}

void PrescribedMotion::pose(double t_s, Mat3& rotation, Vec3& translation_m) const
{
    const double speed = norm(angular_velocity_rad_per_s);
    rotation = speed > 0.0 ? rotation_about_axis(angular_velocity_rad_per_s * (1.0 / speed), speed * moving_s(t_s))
                           : Mat3::identity();
    // x_world = c(t) + R (x_b - pivot) = R x_b + (c(t) - R pivot)
    translation_m = pivot_position_m(t_s) - rotation * pivot_m;
}

MeshWall::MeshWall(meshes::TriangleMesh mesh, MaterialIndex material, std::string name,
                   std::optional<PrescribedMotion> motion)
    : mesh_(std::move(mesh)), material_(material), name_(std::move(name)), motion_(motion)
{
    packed_body_.resize(mesh_.triangle_count());
    const auto& v = mesh_.vertices_m();
    for (std::size_t t = 0; t < mesh_.triangle_count(); ++t) {
        const auto& tri = mesh_.triangles()[t];
        packed_body_[t] = {v[tri[0]], v[tri[1]], v[tri[2]], mesh_.triangle_normal(t)};
    }
    constexpr double kHuge = std::numeric_limits<double>::max();
    bounds_lo_m_ = {kHuge, kHuge, kHuge};  // an empty mesh: every sphere is clear of it
    bounds_hi_m_ = {-kHuge, -kHuge, -kHuge};
    if (!v.empty()) {
        Vec3 lo = v[0], hi = v[0];
        for (const Vec3& x : v) {
            lo = {std::min(lo.x, x.x), std::min(lo.y, x.y), std::min(lo.z, x.z)};
            hi = {std::max(hi.x, x.x), std::max(hi.y, x.y), std::max(hi.z, x.z)};
        }
        bound_centre_ = (lo + hi) * 0.5;
        bounds_lo_m_ = lo;
        bounds_hi_m_ = hi;
        for (const Vec3& x : v) bound_radius_m_ = std::max(bound_radius_m_, norm(x - bound_centre_));
    }
    // a closed convex solid: every edge shared by exactly two triangles (an open plate or shell is a two-sided
    // surface, not a solid), and every vertex on or behind every face plane, to round-off (most non-convex
    // meshes fail at once)
    convex_slack_m_ = 1e-9 * bound_radius_m_;
    convex_ = !packed_body_.empty() && packed_body_.size() <= kMaxConvexCheckTriangles;
    if (convex_) {
        std::vector<std::uint8_t> uses(mesh_.edge_count(), 0);
        for (std::size_t t = 0; t < packed_body_.size(); ++t)
            for (std::uint32_t e : mesh_.triangle_edges(t)) uses[e] = static_cast<std::uint8_t>(std::min(uses[e] + 1, 3));
        convex_ = std::all_of(uses.begin(), uses.end(), [](std::uint8_t u) { return u == 2; });
    }
    for (std::size_t t = 0; t < packed_body_.size() && convex_; ++t)
        for (const Vec3& x : v)
            if (dot(x - packed_body_[t].a, packed_body_[t].normal) > convex_slack_m_) {
                convex_ = false;
                break;
            }
    if (motion_) {
        Mat3 r;
        Vec3 t;
        motion_->pose(0.0, r, t);
        set_pose(r, t, motion_->pivot_position_m(0.0), motion_->pivot_velocity_m_per_s(0.0),
                 motion_->angular_velocity_rad_per_s);
    } else {
        set_pose(Mat3::identity(), Vec3{}, Vec3{}, Vec3{}, Vec3{});
    }
}

bool MeshWall::sphere_clear(const Vec3& centre_world_m, double r) const
{
    const Vec3 b = to_body(centre_world_m);
    const Vec3& lo = bounds_lo_m_;
    const Vec3& hi = bounds_hi_m_;
    if (b.x < lo.x - r || b.y < lo.y - r || b.z < lo.z - r || b.x > hi.x + r || b.y > hi.y + r || b.z > hi.z + r) return true;
    return mesh_.distance_m(b) >= r;
}

void MeshWall::set_mass_kg(double mass_kg)
{
    if (!(mass_kg >= 0.0) || !std::isfinite(mass_kg))
        throw InputError(concat("mesh wall '", name_, "': mass_kg = ", mass_kg, "; expected a finite value >= 0 (0: immovable)"));
    mass_kg_ = mass_kg;
}

void MeshWall::set_pose(const Mat3& rotation, const Vec3& translation_m, const Vec3& reference_point_world_m,
                        const Vec3& reference_velocity_m_per_s, const Vec3& angular_velocity_rad_per_s)
{
    ++pose_version_;
    rotation_ = rotation;
    rotation_transposed_ = rotation.transposed();
    translation_ = translation_m;
    reference_point_ = reference_point_world_m;
    reference_velocity_ = reference_velocity_m_per_s;
    angular_velocity_ = angular_velocity_rad_per_s;
    vertices_current_ = false;
}

const std::vector<Vec3>& MeshWall::vertices_world_m() const
{
    if (!vertices_current_) {
        const auto& body = mesh_.vertices_m();
        vertices_world_.resize(body.size());
        for (std::size_t v = 0; v < body.size(); ++v) vertices_world_[v] = rotation_ * body[v] + translation_;
        vertices_current_ = true;
    }
    return vertices_world_;
}

double MeshWall::max_vertex_move_m(const Mat3& rotation0, const Vec3& translation0_m) const
{
    // for rotations, |R - R0|_2 = |R0^T R - I|_2 = 2 sin(theta / 2) = sqrt(3 - trace(R0^T R))
    double trace = 0.0;
    Mat3 d;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            d.m[i][j] = rotation_.m[i][j] - rotation0.m[i][j];
            trace += rotation_.m[i][j] * rotation0.m[i][j];
        }
    return norm(d * bound_centre_ + translation_ - translation0_m) + std::sqrt(std::max(0.0, 3.0 - trace)) * bound_radius_m_;
}

void MeshWall::restore_pose(const Mat3& rotation, const Vec3& translation_m, const Vec3& reference_point_world_m,
                            const Vec3& reference_velocity_m_per_s, const Vec3& angular_velocity_rad_per_s,
                            std::uint64_t pose_version)
{
    set_pose(rotation, translation_m, reference_point_world_m, reference_velocity_m_per_s, angular_velocity_rad_per_s);
    pose_version_ = pose_version;
}

}  // namespace dipper::dem
