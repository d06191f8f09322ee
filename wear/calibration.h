// Measured wear: reading thickness measurements, comparing them with a simulated wear-rate map at points
// and along sections, and the one-step linear calibration of the wear constant (thesis Paper B §3.4).
#pragma once

#include "wear/wear_surface.h"

#include <string>
#include <utility>
#include <vector>

namespace dipper::wear {

/// One thickness measurement: wear depth at a point of the part after a known tonnage passed.
struct MeasuredPoint {
    std::string id;
    Vec3 position_m;         ///< in the part's (body) frame
    double depth_mm = 0.0;   ///< measured thickness loss
    double tonnage_t = 0.0;  ///< material that passed between the two thickness measurements
    std::string source;      ///< file:line, for messages
    double rate_mm_per_t() const { return depth_mm / tonnage_t; }
};

/// Reads a measurement CSV with the header `id,x_m,y_m,z_m,depth_mm,tonnage_t` (columns in any order).
/// Empty files, missing columns, unknown columns, values that are not finite numbers, tonnage <= 0 and
/// repeated ids are InputErrors naming the file, line, column and value.
std::vector<MeasuredPoint> read_measured_points(const std::string& path);

/// How uncertain a measurement is: the gauge's depth error (one standard deviation, independent per
/// point) and how far the measured position may be from the stated one (a bound).
struct MeasurementUncertainty {
    double gauge_mm = 0.1;
    double position_m = 0.02;
};

/// A simulated wear-rate map: nodal wear rate of a surface, mm/t, after smoothing.
struct RateMap {
    RateMap(const WearSurface& surface, double simulated_tonnage_t, int smoothing_iterations);
    const WearSurface* surface;
    double tonnage_t;
    int smoothing;
    std::vector<double> node_rate_mm_per_t;
    /// Rate at a point on the surface; `what` names the point for the error if it is off the surface.
    double at(const Vec3& point_m, double tolerance_m, const std::string& what) const;
};

struct PointComparison {
    std::string id;
    Vec3 position_m;
    double measured_rate = 0.0;        ///< mm/t
    double measured_sigma = 0.0;       ///< mm/t, from the gauge error
    double simulated_rate = 0.0;       ///< mm/t, at the stated position
    double simulated_min = 0.0;        ///< mm/t, lowest within the position uncertainty
    double simulated_max = 0.0;        ///< mm/t, highest within the position uncertainty
    double error() const { return simulated_rate - measured_rate; }
    /// (simulated - measured) / measured; infinite if nothing was measured there.
    double relative_error() const;
};

struct ComparisonSummary {
    std::size_t count = 0;
    double mean_measured = 0.0, mean_simulated = 0.0;  ///< mm/t
    double mean_absolute_error = 0.0, rms_error = 0.0; ///< mm/t
    double mean_absolute_relative_error = 0.0;         ///< over points with a non-zero measured rate
    double correlation = 0.0;                          ///< Pearson r; 0 if either side has no variance
};

/// Compares a map with measured points. Points farther than `tolerance_m` from the surface are errors.
std::vector<PointComparison> compare_points(const RateMap& map, const std::vector<MeasuredPoint>& points,
                                            const MeasurementUncertainty& uncertainty, double tolerance_m);
ComparisonSummary summarize(const std::vector<PointComparison>& comparisons);

/// The one-step calibration: the trial constant scaled so that the mean simulated rate at the points equals
/// the measured mean. The spread combines the gauge error of the mean (independent per point) with the
/// position bounds: constant_low = K (m - sigma_m) / mean(sim_max), constant_high = K (m + sigma_m) / mean(sim_min).
struct CalibrationResult {
    double trial_constant = 0.0;
    double scale = 0.0;
    double calibrated_constant = 0.0;
    double constant_low = 0.0, constant_high = 0.0;
    std::vector<PointComparison> before, after;  ///< per point, with the trial and the calibrated constant
    ComparisonSummary summary_before, summary_after;
};
CalibrationResult calibrate(const WearSurface& trial, double simulated_tonnage_t, int smoothing_iterations,
                            const std::vector<MeasuredPoint>& points, const MeasurementUncertainty& uncertainty,
                            double tolerance_m);

/// A section: a polyline across the surface (thesis Paper B Fig. 16), sampled every `spacing_m` of arc
/// length; each sample is projected onto the surface.
struct SectionSample {
    double arc_length_m = 0.0;
    Vec3 point_m;             ///< on the surface
    double simulated_rate = 0.0;
};
std::vector<SectionSample> sample_section(const RateMap& map, const std::vector<Vec3>& polyline_m, double spacing_m,
                                          double tolerance_m, const std::string& section_name);
/// Where sample_section samples: points along the polyline at most `spacing_m` apart, each piece split
/// evenly, with their arc length (first: 0 at the first point).
std::vector<std::pair<double, Vec3>> section_points(const std::vector<Vec3>& polyline_m, double spacing_m);
/// The measured points within `distance_m` of the polyline, with their arc length along it.
struct SectionPoint {
    double arc_length_m;
    PointComparison comparison;
};
std::vector<SectionPoint> points_on_section(const std::vector<Vec3>& polyline_m,
                                            const std::vector<PointComparison>& comparisons, double distance_m);

/// CSV outputs: per-point comparison; a section's simulated profile and its measured points.
void write_points_csv(const std::string& path, const std::vector<PointComparison>& comparisons);
void write_section_csv(const std::string& path, const std::vector<SectionSample>& profile,
                       const std::vector<SectionPoint>& measured);

}  // namespace dipper::wear
