// The rigid-body tests' worlds of rock and another material.
#pragma once

#include "rigid/rigid_world.h"

#include <string>

namespace dipper::test {

/// A world of `s` with the materials rock (0) and `other` (1), and the friction and restitution of rock on rock
/// and of rock on the other.
inline rigid::RigidWorld rock_world(const rigid::RigidSettings& s, const std::string& other, double rock_friction, double rock_restitution,
                                     double other_friction, double other_restitution)
{
    rigid::RigidWorld w(s);
    w.add_material("rock");
    w.add_material(other);
    w.set_pair("rock", "rock", rock_friction, rock_restitution);
    w.set_pair("rock", other, other_friction, other_restitution);
    return w;
}

/// A world with materials rock and ground and their pairs.
inline rigid::RigidWorld rock_world(double friction = 0.6, int iterations = 10)
{
    rigid::RigidSettings s;
    s.solver_iterations = iterations;
    return rock_world(s, "ground", friction, 0.2, friction, 0.2);
}

}  // namespace dipper::test
