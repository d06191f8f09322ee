// One contact between a particle (or rock) and a machine surface during one step, as the wear module
// and other consumers see it. Lives in core/ so that dem/, rigid/ and wear/ share it without seeing
// each other.
#pragma once

#include "core/vec3.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace dipper {

/// A surface contact in world coordinates at the end of the force evaluation of one step.
struct ContactRecord {
    Vec3 point_world;                    ///< contact point on the surface, m
    Vec3 normal_world;                   ///< unit normal, from the surface towards the particle
    double normal_force_N = 0.0;         ///< magnitude of the normal force on the particle (>= 0)
    Vec3 tangential_force_N;             ///< tangential force on the particle, world frame
    Vec3 relative_displacement_m;        ///< particle-minus-surface displacement of the contact point over the step
    double overlap_m = 0.0;              ///< normal overlap
    std::int32_t surface_id = -1;        ///< which wall or mesh (index into the world's wall list)
    std::int32_t triangle_id = -1;       ///< triangle of that mesh; -1 for analytic planes
    std::int32_t particle_index = -1;    ///< dense index of the particle in its store during this step
    double particle_mass_kg = 0.0;       ///< mass of the particle (impact-energy wear laws use it)
    bool first_step = false;             ///< true on the first step of this contact: an impact
};

/// Receives the surface contacts of one step, in a deterministic order (by particle, then surface).
using ContactConsumer = std::function<void(const std::vector<ContactRecord>&, double time_s, double step_s)>;

}  // namespace dipper
