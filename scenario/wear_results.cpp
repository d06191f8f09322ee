#include "scenario/wear_results.h"

#include "core/errors.h"
#include "coupling/co_simulation.h"
#include "scenario/detail/json.h"
#include "wear/wear_output.h"

#include <algorithm>

namespace dipper::scenario {

using detail::json_escape;
using detail::json_number;

void WearResults::finish(const Scenario& scenario, const coupling::CoSimulation& sim, const std::string& dir, bool completed,
                         std::string& message)
{
    // each surface in its part's own frame (the dipper's: x from the heel to the lip, z up from the bottom),
    // with the plate of each triangle: what the report draws its 3-D wear views from
    for (std::size_t k = 0; k < sim.wear().size(); ++k) {
        const coupling::WearPart& w = sim.wear()[k];
        wear::write_wear_vtp(*w.surface, dir + "/wear_" + w.part + "_final.vtp", wear_tonnage_t(scenario, sim, k),
                             scenario.wear[k].smoothing_iterations, Mat3::identity(), {}, sim.triangle_plates(w));
    }
    try {
        calibrate(scenario, sim, dir);  // the points were checked against the surfaces before the run
    } catch (const InputError& e) {
        // a run stopped before it wore the measured points keeps its summary (resume it to the end); a
        // finished one that did not wear them is the user's error, reported after the summary is written
        if (completed) error_ = e.what();
        else message = concat(message, "; no wear calibration yet: ", e.what());
        calibrations_.resize(sim.wear().size());
    }
    write_sections(scenario, sim, dir);
}

/// With a measurement file: the measured against the simulated rates at the points, and the wear constant
/// that makes their means agree (wear/calibration.h); written to wear_<part>_points.csv.
void WearResults::calibrate(const Scenario& scenario, const coupling::CoSimulation& sim, const std::string& dir)
{
    calibrations_.clear();
    for (std::size_t k = 0; k < sim.wear().size(); ++k) {
        const WearSpec& spec = scenario.wear[k];
        const double tonnage = wear_tonnage_t(scenario, sim, k);
        if (spec.measured_file.empty() || !(tonnage > 0.0)) {
            calibrations_.emplace_back();
            continue;
        }
        const auto points = wear::read_measured_points(spec.measured_file);
        const wear::CalibrationResult c = wear::calibrate(*sim.wear()[k].surface, tonnage, spec.smoothing_iterations, points,
                                                          wear::MeasurementUncertainty{}, kMeasuredPointTolerance_m);
        wear::write_points_csv(dir + "/wear_" + spec.part + "_points.csv", c.before);
        calibrations_.push_back(c);
    }
}

/// Each section's simulated rate profile with the measured points near it, in wear_<part>_section_<name>.csv
/// (the run's constant; the calibrated one scales it by `scale`).
void WearResults::write_sections(const Scenario& scenario, const coupling::CoSimulation& sim, const std::string& dir)
{
    sections_.clear();
    for (std::size_t k = 0; k < sim.wear().size(); ++k) {
        const WearSpec& spec = scenario.wear[k];
        const double tonnage = wear_tonnage_t(scenario, sim, k);
        sections_.emplace_back();
        if (spec.sections.empty() || !(tonnage > 0.0)) continue;
        const wear::RateMap map(*sim.wear()[k].surface, tonnage, spec.smoothing_iterations);
        const std::vector<wear::PointComparison> none;
        const auto& measured = k < calibrations_.size() && calibrations_[k].scale > 0.0 ? calibrations_[k].before : none;
        for (const WearSectionSpec& section : spec.sections) {
            Section r;
            r.name = section.name;
            r.profile = wear::sample_section(map, section.points_m, section.spacing_m, kMeasuredPointTolerance_m, section.name);
            r.measured = wear::points_on_section(section.points_m, measured, kMeasuredPointTolerance_m);
            wear::write_section_csv(dir + "/wear_" + spec.part + "_section_" + section.name + ".csv", r.profile, r.measured);
            sections_.back().push_back(std::move(r));
        }
    }
}

void WearResults::write_json(std::ostream& out, const Scenario& scenario, const coupling::CoSimulation& r) const
{
    out << "{";
    for (std::size_t k = 0; k < r.wear().size(); ++k) {
        const coupling::WearPart& w = r.wear()[k];
        const WearSpec& spec = scenario.wear[k];
        const std::vector<double> depth = w.surface->node_depth_m(spec.smoothing_iterations);
        const double max_depth = depth.empty() ? 0.0 : *std::max_element(depth.begin(), depth.end());
        out << (k ? ", " : "") << "\"" << json_escape(spec.part) << "\": {\"tonnage_t\": " << json_number(wear_tonnage_t(scenario, r, k))
            << ", \"law\": \"" << spec.law
            << "\", \"constant\": " << json_number(spec.constant) << ", \"volume_m3\": " << json_number(w.surface->total_volume_m3())
            << ", \"max_depth_mm\": " << json_number(1000.0 * max_depth);
        const std::vector<std::string> plates = r.plate_names(w);
        if (!plates.empty()) {
            out << ", \"plates\": [";
            for (std::size_t g = 0; g < plates.size(); ++g) out << (g ? ", " : "") << "\"" << json_escape(plates[g]) << "\"";
            out << "]";
        }
        const auto regions = r.wear_by_region(w);
        if (!regions.empty()) {
            out << ", \"volume_by_region_m3\": {";
            for (std::size_t g = 0; g < regions.size(); ++g)
                out << (g ? ", " : "") << "\"" << regions[g].first << "\": " << json_number(regions[g].second);
            out << "}";
        }
        if (k < calibrations_.size() && calibrations_[k].scale > 0.0) {
            const wear::CalibrationResult& c = calibrations_[k];
            out << ", \"measured\": {\"points\": " << c.before.size() << ", \"mean_measured_mm_per_t\": "
                << json_number(c.summary_before.mean_measured) << ", \"mean_simulated_mm_per_t\": "
                << json_number(c.summary_before.mean_simulated) << ", \"correlation\": " << json_number(c.summary_before.correlation)
                << ", \"scale\": " << json_number(c.scale) << ", \"calibrated_constant\": " << json_number(c.calibrated_constant)
                << ", \"calibrated_constant_low\": " << json_number(c.constant_low)
                << ", \"calibrated_constant_high\": " << json_number(c.constant_high) << "}";
        }
        if (k < sections_.size() && !sections_[k].empty()) {
            out << ", \"sections\": {";
            for (std::size_t q = 0; q < sections_[k].size(); ++q) {
                const Section& sr = sections_[k][q];
                double sum = 0.0, peak = 0.0, measured_sum = 0.0, simulated_at_points = 0.0;
                for (const wear::SectionSample& x : sr.profile) {
                    sum += x.simulated_rate;
                    peak = std::max(peak, x.simulated_rate);
                }
                for (const wear::SectionPoint& m : sr.measured) {
                    measured_sum += m.comparison.measured_rate;
                    simulated_at_points += m.comparison.simulated_rate;
                }
                const double n = static_cast<double>(sr.measured.size());
                out << (q ? ", " : "") << "\"" << json_escape(sr.name) << "\": {\"samples\": " << sr.profile.size()
                    << ", \"mean_simulated_mm_per_t\": " << json_number(sum / static_cast<double>(sr.profile.size()))
                    << ", \"max_simulated_mm_per_t\": " << json_number(peak) << ", \"measured_points\": " << sr.measured.size();
                if (n > 0)
                    out << ", \"mean_measured_mm_per_t\": " << json_number(measured_sum / n)
                        << ", \"mean_simulated_at_points_mm_per_t\": " << json_number(simulated_at_points / n);
                out << "}";
            }
            out << "}";
        }
        out << "}";
    }
    out << "}";
}

}  // namespace dipper::scenario
