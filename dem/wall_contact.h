// What the sphere-wall phases of dem::World share: a wall's motion as a contact's force reads it, the contact
// of a sphere with a wall (plane, open mesh or convex body) and a wall within reach of a sphere.
#pragma once

#include "core/vec3.h"
#include "dem/contact_law.h"
#include "dem/material.h"

#include <cstddef>
#include <cstdint>

namespace dipper::dem {

/// What a wall contact's force needs of its wall, copied at the start of each wall phase into one small record
/// per wall (a mesh's own object is large and spread over many cache lines).
struct WallMotion {
    Vec3 reference_point_m, reference_velocity_m_per_s, angular_velocity_rad_per_s;  ///< zero for a plane
    double mass_kg;                                                                  ///< 0: immovable
    MaterialIndex material;
    Vec3 velocity_at(const Vec3& point_m) const
    {
        return reference_velocity_m_per_s + cross(angular_velocity_rad_per_s, point_m - reference_point_m);
    }
};

/// A sphere touching a wall in one step.
struct WallContact {
    std::uint32_t particle;
    std::int32_t wall, triangle;
    Vec3 normal, point, relative_displacement_m;
    double overlap_m;
    bool first_step;  ///< no contact of last step continues into this one
    ContactHistory history;
    ContactForces forces;
};

/// A wall within reach of a particle: triangle of a mesh, or plane `mesh` when triangle == kPlaneCandidate.
struct MeshCandidate {
    std::uint32_t mesh, triangle;
};
inline constexpr std::uint32_t kPlaneCandidate = 0xffffffffu;

/// No contact: past the end of every contact list.
inline constexpr std::size_t kNoContact = static_cast<std::size_t>(-1);

/// What the sphere pairs of a convex body read of it, in four cache lines (the geometry in the first two): the
/// pairs meet their bodies in no order, so each is fetched ahead of its pair (ConvexPairs::compute).
struct alignas(64) ConvexFrame {
    Mat3 to_body;  ///< the transposed rotation
    Vec3 translation_m;
    double slack_m;
    std::int32_t wall;
    std::uint8_t frozen;  ///< World::set_wall_frozen: its pairs with frozen particles are left as they were
    WallMotion motion;
};

}  // namespace dipper::dem
