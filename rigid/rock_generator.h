// Seeded random rocks: angular convex polyhedra of a size class and elongation, like blasted ore.
#pragma once

#include "rigid/convex_polyhedron.h"

#include <cstdint>

namespace dipper::rigid {

/// What a generated rock looks like. Its size is the diameter of the sphere of equal volume (so that a
/// size class holds a known mass per rock); its elongation is the ratio of the longest to the shortest of
/// the three axes the points are drawn on, uniformly in [min, max]; the middle axis lies between them.
struct RockShape {
    double size_m = 0.3;
    double elongation_min = 1.0;
    double elongation_max = 2.0;
    int point_count = 20;  ///< points drawn before the hull; the hull keeps those on its surface
};

/// A convex rock in its principal frame (centroid at the origin), scaled to the exact size. Points are
/// drawn on an ellipsoid of the chosen axes with +-15 % radial scatter, so that faces are flat and edges
/// sharp; the same seed gives the same rock. Bad parameters are InputErrors naming `where`.
ConvexPolyhedron generate_rock(const RockShape& shape, std::uint64_t seed, const std::string& where = "rock");

}  // namespace dipper::rigid
