#include "rigid/rock_generator.h"

#include "core/errors.h"

#include <cmath>
#include <random>

namespace dipper::rigid {

ConvexPolyhedron generate_rock(const RockShape& s, std::uint64_t seed, const std::string& where)
{
    require_positive(s.size_m, "size_m", where);
    require_in_range(s.elongation_min, 1.0, 5.0, "elongation_min", where);
    require_in_range(s.elongation_max, s.elongation_min, 5.0, "elongation_max (>= elongation_min)", where);
    if (s.point_count < 8 || s.point_count > 500)
        throw InputError(concat(where, ": point_count is ", s.point_count, "; expected 8..500"));

    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double long_axis = s.elongation_min + (s.elongation_max - s.elongation_min) * unit(rng);
    const double middle_axis = 1.0 + (long_axis - 1.0) * unit(rng);
    std::normal_distribution<double> gauss(0.0, 1.0);
    std::vector<Vec3> points;
    points.reserve(static_cast<std::size_t>(s.point_count));
    for (int k = 0; k < s.point_count; ++k) {
        Vec3 d{gauss(rng), gauss(rng), gauss(rng)};
        d = normalized(d);
        const double r = 0.85 + 0.3 * unit(rng);
        points.push_back({d.x * long_axis * r, d.y * middle_axis * r, d.z * r});
    }
    const ConvexPolyhedron hull = ConvexPolyhedron::hull_of(points, where).in_principal_frame();
    return hull.scaled(s.size_m / hull.equivalent_diameter_m());
}

}  // namespace dipper::rigid
