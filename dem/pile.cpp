#include "dem/pile.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dipper::dem {

void ReposeWindow::validate(const std::string& where) const
{
    if (along != 'x' && along != 'y') throw InputError(concat(where, ": along = '", along, "'; expected x or y"));
    require_positive(bin_m, "bin_m", where);
    for (int a = 0; a < 3; ++a)
        if (!(max_m[a] > min_m[a])) throw InputError(concat(where, ": the window's max_m must exceed min_m in x, y and z"));
    require_in_range(low_fraction, 0.0, 1.0, "low_fraction", where);
    require_in_range(high_fraction, 0.0, 1.0, "high_fraction", where);
    if (!(high_fraction > low_fraction)) throw InputError(concat(where, ": high_fraction must exceed low_fraction"));
    const int axis = along == 'x' ? 0 : 1;
    if ((max_m[axis] - min_m[axis]) / bin_m > 1e6) throw InputError(concat(where, ": more than a million bins; use a larger bin_m"));
}

ReposeFit fit_repose_angle(const ParticleStore& p, const ReposeWindow& w, const std::string& where,
                           const std::vector<Vec3>& surface_points)
{
    w.validate(where);
    const int axis = w.along == 'x' ? 0 : 1;
    const double lo = w.min_m[axis];
    const auto bins = static_cast<std::size_t>(std::ceil((w.max_m[axis] - lo) / w.bin_m));
    std::vector<double> top(bins, -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec3& x = p.position_m[i];
        if (x.x < w.min_m.x || x.y < w.min_m.y || x.z < w.min_m.z || x.x > w.max_m.x || x.y > w.max_m.y || x.z > w.max_m.z) continue;
        const auto b = std::min(bins - 1, static_cast<std::size_t>((x[axis] - lo) / w.bin_m));
        top[b] = std::max(top[b], x.z + p.radius_m[i]);
    }
    for (const Vec3& x : surface_points) {
        if (x.x < w.min_m.x || x.y < w.min_m.y || x.z < w.min_m.z || x.x > w.max_m.x || x.y > w.max_m.y || x.z > w.max_m.z) continue;
        const auto b = std::min(bins - 1, static_cast<std::size_t>((x[axis] - lo) / w.bin_m));
        top[b] = std::max(top[b], x.z);
    }
    ReposeFit fit;
    double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
    for (std::size_t b = 0; b < bins; ++b) {
        if (!std::isfinite(top[b])) continue;
        fit.bin_centre_m.push_back(lo + (static_cast<double>(b) + 0.5) * w.bin_m);
        fit.surface_m.push_back(top[b]);
        zmin = std::min(zmin, top[b]);
        zmax = std::max(zmax, top[b]);
    }
    if (!(zmax - zmin >= w.bin_m))
        throw InputError(concat(where, ": the surface in the window spans ", std::isfinite(zmax - zmin) ? zmax - zmin : 0.0,
                                " m in height, less than one bin (", w.bin_m, " m): no bins lie on the slope of a pile"));
    // The slope: the longest run of neighbouring bins whose tops lie in the band between the flat top and
    // the toe. A bin in the band but cut off from that run by one outside it is not on the slope, such as a
    // rock rolled out past the toe.
    const double z_lo = zmin + w.low_fraction * (zmax - zmin), z_hi = zmin + w.high_fraction * (zmax - zmin);
    std::size_t best_first = 0, best_count = 0;
    for (std::size_t k = 0; k < fit.surface_m.size();) {
        std::size_t end = k;
        while (end < fit.surface_m.size() && fit.surface_m[end] >= z_lo && fit.surface_m[end] <= z_hi &&
               (end == k || fit.bin_centre_m[end] - fit.bin_centre_m[end - 1] < 1.5 * w.bin_m))
            ++end;
        if (end - k > best_count) {
            best_first = k;
            best_count = end - k;
        }
        k = end > k ? end : k + 1;
    }
    // least squares over the bins on the slope
    double n = 0, ss = 0, sz = 0, sss = 0, ssz = 0;
    fit.fitted.assign(fit.surface_m.size(), false);
    for (std::size_t k = best_first; k < best_first + best_count; ++k) {
        const double s = fit.bin_centre_m[k], z = fit.surface_m[k];
        fit.fitted[k] = true;
        n += 1;
        ss += s;
        sz += z;
        sss += s * s;
        ssz += s * z;
    }
    fit.bins_fitted = static_cast<int>(n);
    if (n < 3 || !(n * sss - ss * ss > 0.0))
        throw InputError(concat(where, ": only ", fit.bins_fitted, " bins lie on the slope (of ", fit.surface_m.size(),
                                " with particles or surface points); the window holds no pile slope to fit"));
    fit.slope = (n * ssz - ss * sz) / (n * sss - ss * ss);
    const double a = (sz - fit.slope * ss) / n;
    fit.intercept_m = a;
    double r2 = 0.0;
    for (std::size_t k = 0; k < fit.surface_m.size(); ++k) {
        const double z = fit.surface_m[k];
        if (!fit.fitted[k]) continue;
        const double e = z - (a + fit.slope * fit.bin_centre_m[k]);
        r2 += e * e;
    }
    fit.rms_residual_m = std::sqrt(r2 / n);
    fit.angle_deg = std::atan(std::abs(fit.slope)) * 180.0 / M_PI;
    return fit;
}

}  // namespace dipper::dem
