#include "dem/walls.h"

#include "core/errors.h"

#include <cmath>
#include <utility>

namespace dipper::dem {

Vec3 PrescribedMotion::pivot_position_m(double t_s) const
{
    return pivot_m + velocity_m_per_s * t_s + oscillation_amplitude_m * std::sin(2.0 * M_PI * oscillation_frequency_Hz * t_s);
}

Vec3 PrescribedMotion::pivot_velocity_m_per_s(double t_s) const
{
    const double w = 2.0 * M_PI * oscillation_frequency_Hz;
    return velocity_m_per_s + oscillation_amplitude_m * (w * std::cos(w * t_s));
}

void PrescribedMotion::pose(double t_s, Mat3& rotation, Vec3& translation_m) const
{
    const double speed = norm(angular_velocity_rad_per_s);
    rotation = speed > 0.0 ? rotation_about_axis(angular_velocity_rad_per_s * (1.0 / speed), speed * t_s)
                           : Mat3::identity();
    // x_world = c(t) + R (x_b - pivot) = R x_b + (c(t) - R pivot)
    translation_m = pivot_position_m(t_s) - rotation * pivot_m;
}

MeshWall::MeshWall(meshes::TriangleMesh mesh, MaterialIndex material, std::string name,
                   std::optional<PrescribedMotion> motion)
    : mesh_(std::move(mesh)), material_(material), name_(std::move(name)), motion_(motion)
{
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
    translation_ = translation_m;
    reference_point_ = reference_point_world_m;
    reference_velocity_ = reference_velocity_m_per_s;
    angular_velocity_ = angular_velocity_rad_per_s;
    const auto& body = mesh_.vertices_m();
    vertices_world_.resize(body.size());
    for (std::size_t v = 0; v < body.size(); ++v) vertices_world_[v] = rotation * body[v] + translation_m;
    normals_world_.resize(mesh_.triangle_count());
    packed_.resize(mesh_.triangle_count());
    for (std::size_t t = 0; t < mesh_.triangle_count(); ++t) {
        normals_world_[t] = rotation * mesh_.triangle_normal(t);
        const auto& tri = mesh_.triangles()[t];
        packed_[t] = {vertices_world_[tri[0]], vertices_world_[tri[1]], vertices_world_[tri[2]], normals_world_[t]};
    }
}

void MeshWall::restore_pose(const Mat3& rotation, const Vec3& translation_m, const Vec3& reference_point_world_m,
                            const Vec3& reference_velocity_m_per_s, const Vec3& angular_velocity_rad_per_s,
                            std::uint64_t pose_version)
{
    set_pose(rotation, translation_m, reference_point_world_m, reference_velocity_m_per_s, angular_velocity_rad_per_s);
    pose_version_ = pose_version;
}

}  // namespace dipper::dem
