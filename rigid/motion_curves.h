// Prescribed motion of the rope shovel: time curves of hoist rope length, crowd extension, swing angle
// and door angle, read from CSV and interpolated linearly.
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
    /// Linear interpolation; before the first sample the first, after the last the last.
    MotionSample at(double time_s) const;
    double duration_s() const { return samples_.back().time_s; }
    const std::vector<MotionSample>& samples() const { return samples_; }
    const std::string& source() const { return source_; }
    void write_csv(const std::string& path) const;

private:
    std::vector<MotionSample> samples_;
    std::string source_;
};

}  // namespace dipper::rigid
