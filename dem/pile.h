// Measurements on a pile of spheres: the angle of repose from a straight-line fit to its free surface.
#pragma once

#include "core/vec3.h"
#include "dem/particle_store.h"

#include <string>
#include <vector>

namespace dipper::dem {

/// Where and how the surface of a pile is read: the particles whose centres lie in the box [min_m,
/// max_m] count; the box is cut into bins of bin_m along `along` (x or y, the downhill direction or its
/// reverse); the surface height of a bin is the highest sphere top (z + r) in it.
struct ReposeWindow {
    Vec3 min_m, max_m;
    char along = 'x';
    double bin_m = 0.2;
    /// Only bins whose surface lies between these fractions of the span from the lowest to the highest
    /// bin enter the fit: the flat top and the toe's run-out are left out.
    double low_fraction = 0.15, high_fraction = 0.85;
    void validate(const std::string& where) const;
};

struct ReposeFit {
    double angle_deg = 0.0;       ///< atan of the fitted slope's magnitude
    double slope = 0.0;           ///< dz / d(along), signed
    double intercept_m = 0.0;     ///< the fitted line is z = intercept_m + slope * along
    double rms_residual_m = 0.0;  ///< of the fitted bins about the line
    int bins_fitted = 0;
    std::vector<double> bin_centre_m, surface_m;  ///< every non-empty bin: its centre and surface height
    std::vector<bool> fitted;                     ///< beside them: whether the bin is on the slope, in the fit
};

/// The method (docs/results.md): bin, take each bin's top, keep the bins on the slope, least-squares line
/// z = a + b s, angle = atan |b|. Throws InputError naming `where` if fewer than 3 bins are on the slope.
/// `surface_points` are points on the surfaces of other bodies of the pile, such as the hull vertices of
/// rocks in world coordinates. Each one inside the window raises its bin's top to its height. A rock's
/// highest point over a bin is one of its vertices, or lies on an edge that crosses the bin's border.
ReposeFit fit_repose_angle(const ParticleStore& particles, const ReposeWindow& window, const std::string& where,
                           const std::vector<Vec3>& surface_points = {});

}  // namespace dipper::dem
