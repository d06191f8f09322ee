// What a run's wear surfaces give at its end: each surface in its part's own frame, the comparison with the
// measured points and the constant that makes them agree, the rate along the sections, and their part of
// summary.json.
#pragma once

#include "scenario/scenario.h"
#include "wear/calibration.h"

#include <ostream>
#include <string>
#include <vector>

namespace dipper::coupling {
class CoSimulation;
}

namespace dipper::scenario {

class WearResults {
public:
    /// Writes into dir, for each wear surface: wear_<part>_final.vtp (the part's frame, with its plates), and
    /// with a measurement file wear_<part>_points.csv and the sections' wear_<part>_section_<name>.csv. A
    /// measured point that the run has not worn is, for a completed run, an error kept for error() (the
    /// caller writes its summary first); for a run stopped early, a note added to `message`.
    void finish(const Scenario& scenario, const coupling::CoSimulation& sim, const std::string& dir, bool completed,
                std::string& message);
    /// The "wear" member of summary.json: per part its tonnage, law, volume, deepest point, plates, volume by
    /// region, and, where finish() made them, the calibration and the sections.
    void write_json(std::ostream& out, const Scenario& scenario, const coupling::CoSimulation& sim) const;
    /// Why a completed run's wear could not be calibrated; empty when it could.
    const std::string& error() const { return error_; }

private:
    struct Section {
        std::string name;
        std::vector<wear::SectionSample> profile;
        std::vector<wear::SectionPoint> measured;
    };
    void calibrate(const Scenario& scenario, const coupling::CoSimulation& sim, const std::string& dir);
    void write_sections(const Scenario& scenario, const coupling::CoSimulation& sim, const std::string& dir);

    std::vector<wear::CalibrationResult> calibrations_;  ///< per wear surface (scale 0: none)
    std::vector<std::vector<Section>> sections_;         ///< per wear surface
    std::string error_;
};

}  // namespace dipper::scenario
