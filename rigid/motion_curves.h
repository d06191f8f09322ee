// Prescribed motion of the rope shovel: time curves of hoist rope length, crowd extension, swing angle
// and door angle, read from CSV and joined by monotone cubic curves (continuous velocity, no overshoot).
#pragma once

#include <string>
#include <vector>

namespace dipper::rigid {

struct MotionSample {
    double time_s = 0.0;
    double hoist_length_m = 0.0;     ///< paid-out rope from the boom-point sheave to the bail
    double crowd_extension_m = 0.0;  ///< from the shipper shaft to the dipper-handle pin on the dipper
    double swing_deg = 0.0;          ///< upper body about the vertical, from the dig direction
    double door_deg = 0.0;           ///< 0 closed; positive opens
    double propel_m = 0.0;           ///< how far the crawlers have carried the machine forward (along its heading)
};

class MotionCurves {
public:
    /// Reads a CSV with the header `time_s,hoist_length_m,crowd_extension_m,swing_deg,door_deg` and
    /// optionally `propel_m` (any order; without it the machine stays where it stands). Times must
    /// increase strictly; every value must be a finite number; lengths positive. Errors name the file,
    /// line, column and value.
    static MotionCurves from_csv(const std::string& path);
    /// From samples already in memory; `source` names them in errors.
    static MotionCurves from_samples(std::vector<MotionSample> samples, const std::string& source);
    /// The curves at a time: between samples, each drive follows a monotone cubic through its samples
    /// (monotone_slopes), so its velocity is continuous and it never passes beyond a sample's value; it is at
    /// rest at the first and last samples and where it turns back or stands. Before the first sample the
    /// first, after the last the last. Samples on a straight line give that line.
    MotionSample at(double time_s) const;
    double duration_s() const { return samples_.back().time_s; }
    const std::vector<MotionSample>& samples() const { return samples_; }
    const std::string& source() const { return source_; }
    void write_csv(const std::string& path) const;

private:
    std::vector<MotionSample> samples_;
    std::vector<MotionSample> slopes_;  ///< per sample, each drive's slope (per second); time_s unused
    std::string source_;
};

/// Slopes for a monotone cubic Hermite curve through (t_k, y_k) (Fritsch and Carlson's condition with the
/// weighted harmonic mean of the neighbouring secants, as in PCHIP): the curve has a continuous velocity,
/// never overshoots the values, and rests (zero slope) where it turns back or stands still, at the first
/// and last points, and at the points marked in `rest` (empty: none).
std::vector<double> monotone_slopes(const std::vector<double>& t, const std::vector<double>& y, const std::vector<bool>& rest = {});
/// The cubic Hermite curve from (t0, y0) with slope m0 to (t1, y1) with slope m1, at t (exactly y0 at t0,
/// and exactly y0 throughout when y1 = y0 and both slopes are 0).
double hermite(double t0, double t1, double y0, double y1, double m0, double m1, double t);

}  // namespace dipper::rigid
