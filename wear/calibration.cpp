#include "wear/calibration.h"

#include "core/csv.h"
#include "core/errors.h"
#include "core/files.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

namespace dipper::wear {

namespace {

/// Closest point on a polyline: arc length there and the distance.
std::pair<double, double> project_on_polyline(const std::vector<Vec3>& line, const Vec3& p)
{
    double best_d = std::numeric_limits<double>::infinity(), best_s = 0.0, s0 = 0.0;
    for (std::size_t k = 0; k + 1 < line.size(); ++k) {
        const Vec3 a = line[k], ab = line[k + 1] - line[k];
        const double len2 = dot(ab, ab);
        const double u = len2 > 0.0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
        const double d = norm(p - (a + ab * u));
        if (d < best_d) { best_d = d; best_s = s0 + u * std::sqrt(len2); }
        s0 += std::sqrt(len2);
    }
    return {best_s, best_d};
}

}  // namespace

std::vector<MeasuredPoint> read_measured_points(const std::string& path)
{
    std::ifstream in(path);
    if (!in) throw InputError(concat("cannot open measurement file '", path, "'"));
    static const std::vector<std::string> expected{"id", "x_m", "y_m", "z_m", "depth_mm", "tonnage_t"};
    std::string line;
    int line_number = 0;
    std::map<std::string, std::size_t> column;
    std::vector<MeasuredPoint> points;
    std::set<std::string> ids;
    while (std::getline(in, line)) {
        ++line_number;
        const std::string text = trim(line);
        if (text.empty() || text[0] == '#') continue;
        const std::string where = concat(path, ":", line_number);
        const std::vector<std::string> cells = split_csv_line(text);
        if (column.empty()) {  // the header
            for (std::size_t c = 0; c < cells.size(); ++c) {
                if (std::find(expected.begin(), expected.end(), cells[c]) == expected.end())
                    throw InputError(concat(where, ": unknown column '", cells[c],
                                            "'; expected the header id,x_m,y_m,z_m,depth_mm,tonnage_t"));
                if (!column.emplace(cells[c], c).second)
                    throw InputError(concat(where, ": column '", cells[c], "' appears twice"));
            }
            for (const auto& name : expected)
                if (!column.count(name))
                    throw InputError(concat(where, ": header lacks column '", name,
                                            "'; expected id,x_m,y_m,z_m,depth_mm,tonnage_t"));
            continue;
        }
        if (cells.size() != column.size())
            throw InputError(concat(where, ": ", cells.size(), " values; the header has ", column.size(), " columns"));
        MeasuredPoint p;
        p.source = where;
        p.id = cells[column["id"]];
        if (p.id.empty()) throw InputError(concat(where, ": empty id"));
        if (!ids.insert(p.id).second) throw InputError(concat(where, ": id '", p.id, "' appears twice"));
        const auto number = [&](const char* name) { return parse_csv_number(cells[column[name]], where, name); };
        p.position_m = {number("x_m"), number("y_m"), number("z_m")};
        p.depth_mm = number("depth_mm");
        p.tonnage_t = number("tonnage_t");
        if (!(p.tonnage_t > 0.0))
            throw InputError(concat(where, ": tonnage_t is ", p.tonnage_t, "; expected > 0 (the tonnage that passed)"));
        points.push_back(p);
    }
    if (column.empty()) throw InputError(concat("measurement file '", path, "' is empty; expected a header and points"));
    if (points.empty()) throw InputError(concat("measurement file '", path, "' has a header but no measured points"));
    return points;
}

RateMap::RateMap(const WearSurface& s, double simulated_tonnage_t, int smoothing_iterations)
    : surface(&s), tonnage_t(simulated_tonnage_t), smoothing(smoothing_iterations)
{
    if (!(simulated_tonnage_t > 0.0))
        throw InputError(concat("wear surface '", s.name(), "': simulated tonnage is ", simulated_tonnage_t,
                                " t; expected > 0 (the material that passed in the run)"));
    node_rate_mm_per_t = s.node_depth_m(smoothing_iterations);
    for (double& r : node_rate_mm_per_t) r *= 1000.0 / simulated_tonnage_t;
}

double RateMap::at(const Vec3& point_m, double tolerance_m, const std::string& what) const
{
    return interpolate_node_field(surface->mesh(), node_rate_mm_per_t, point_m, tolerance_m,
                                  concat(what, " on wear surface '", surface->name(), "'"));
}

double PointComparison::relative_error() const
{
    if (measured_rate == 0.0) return error() == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
    return error() / measured_rate;
}

std::vector<PointComparison> compare_points(const RateMap& map, const std::vector<MeasuredPoint>& points,
                                            const MeasurementUncertainty& u, double tolerance_m)
{
    require_non_negative(u.gauge_mm, "gauge uncertainty (mm)", "wear comparison");
    require_non_negative(u.position_m, "position uncertainty (m)", "wear comparison");
    const meshes::TriangleMesh& mesh = map.surface->mesh();
    std::vector<PointComparison> out;
    for (const MeasuredPoint& p : points) {
        PointComparison c;
        c.id = p.id;
        c.position_m = p.position_m;
        c.measured_rate = p.rate_mm_per_t();
        c.measured_sigma = u.gauge_mm / p.tonnage_t;
        c.simulated_rate = map.at(p.position_m, tolerance_m, concat("measured point '", p.id, "' (", p.source, ")"));
        c.simulated_min = c.simulated_max = c.simulated_rate;
        if (u.position_m > 0.0) {
            // eight points on a circle of the position uncertainty in the local tangent plane
            const SurfacePoint s = locate_on_surface(mesh, p.position_m);
            const Vec3 n = mesh.triangle_normal(s.triangle);
            const Vec3 helper = std::abs(n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
            const Vec3 t1 = normalized(cross(n, helper)), t2 = cross(n, t1);
            for (int k = 0; k < 8; ++k) {
                const double a = 2.0 * M_PI * k / 8.0;
                const Vec3 q = s.point_m + (t1 * std::cos(a) + t2 * std::sin(a)) * u.position_m;
                const double r = map.at(q, std::numeric_limits<double>::infinity(), "position sample");
                c.simulated_min = std::min(c.simulated_min, r);
                c.simulated_max = std::max(c.simulated_max, r);
            }
        }
        out.push_back(c);
    }
    return out;
}

ComparisonSummary summarize(const std::vector<PointComparison>& cs)
{
    ComparisonSummary s;
    s.count = cs.size();
    if (cs.empty()) return s;
    std::size_t relative_count = 0;
    for (const auto& c : cs) {
        s.mean_measured += c.measured_rate;
        s.mean_simulated += c.simulated_rate;
        s.mean_absolute_error += std::abs(c.error());
        s.rms_error += c.error() * c.error();
        if (c.measured_rate != 0.0) {
            s.mean_absolute_relative_error += std::abs(c.relative_error());
            ++relative_count;
        }
    }
    const double n = static_cast<double>(cs.size());
    s.mean_measured /= n;
    s.mean_simulated /= n;
    s.mean_absolute_error /= n;
    s.rms_error = std::sqrt(s.rms_error / n);
    if (relative_count > 0) s.mean_absolute_relative_error /= static_cast<double>(relative_count);
    double sxy = 0.0, sxx = 0.0, syy = 0.0;
    for (const auto& c : cs) {
        const double dx = c.measured_rate - s.mean_measured, dy = c.simulated_rate - s.mean_simulated;
        sxy += dx * dy;
        sxx += dx * dx;
        syy += dy * dy;
    }
    s.correlation = (sxx > 0.0 && syy > 0.0) ? sxy / std::sqrt(sxx * syy) : 0.0;
    return s;
}

CalibrationResult calibrate(const WearSurface& trial, double simulated_tonnage_t, int smoothing_iterations,
                            const std::vector<MeasuredPoint>& points, const MeasurementUncertainty& u,
                            double tolerance_m)
{
    if (points.empty()) throw InputError("wear calibration needs at least one measured point; got none");
    CalibrationResult r;
    r.trial_constant = trial.law().kind == WearLaw::Kind::Finnie ? trial.law().flow_stress_Pa : trial.law().constant;
    const RateMap map(trial, simulated_tonnage_t, smoothing_iterations);
    r.before = compare_points(map, points, u, tolerance_m);
    r.summary_before = summarize(r.before);
    if (!(r.summary_before.mean_simulated > 0.0))
        throw InputError(concat("wear calibration of '", trial.name(), "': the simulated wear rate at the ", points.size(),
                                " measured points is ", r.summary_before.mean_simulated,
                                " mm/t on average; the trial run must wear those points (more contacts or "
                                "tonnage, or points on the worn area)"));
    if (!(r.summary_before.mean_measured > 0.0))
        throw InputError(concat("wear calibration of '", trial.name(), "': the measured mean wear rate is ",
                                r.summary_before.mean_measured, " mm/t; expected > 0"));
    r.scale = r.summary_before.mean_measured / r.summary_before.mean_simulated;
    const WearSurface calibrated = trial.scaled(r.scale);
    r.calibrated_constant = trial.law().kind == WearLaw::Kind::Finnie ? calibrated.law().flow_stress_Pa
                                                                      : calibrated.law().constant;
    r.after = compare_points(RateMap(calibrated, simulated_tonnage_t, smoothing_iterations), points, u, tolerance_m);
    r.summary_after = summarize(r.after);

    // spread of the constant: gauge error of the measured mean, position bounds of the simulated mean
    double variance = 0.0, sim_min = 0.0, sim_max = 0.0;
    for (const auto& c : r.before) {
        variance += c.measured_sigma * c.measured_sigma;
        sim_min += c.simulated_min;
        sim_max += c.simulated_max;
    }
    const double n = static_cast<double>(r.before.size());
    const double sigma_mean = std::sqrt(variance) / n;
    sim_min /= n;
    sim_max /= n;
    const double m = r.summary_before.mean_measured;
    const double k = r.trial_constant;
    const bool inverse = trial.law().kind == WearLaw::Kind::Finnie;  // the flow stress divides the wear
    const double low = std::max(0.0, m - sigma_mean) / sim_max;
    const double high = sim_min > 0.0 ? (m + sigma_mean) / sim_min : std::numeric_limits<double>::infinity();
    r.constant_low = inverse ? k / high : k * low;
    r.constant_high = inverse ? (low > 0.0 ? k / low : std::numeric_limits<double>::infinity()) : k * high;
    return r;
}

std::vector<std::pair<double, Vec3>> section_points(const std::vector<Vec3>& line, double spacing_m)
{
    std::vector<std::pair<double, Vec3>> out;
    double s0 = 0.0;
    for (std::size_t k = 0; k + 1 < line.size(); ++k) {
        const Vec3 a = line[k], ab = line[k + 1] - line[k];
        const double length = norm(ab);
        const int pieces = std::max(1, static_cast<int>(std::ceil(length / spacing_m - 1e-9)));
        for (int i = (k == 0 ? 0 : 1); i <= pieces; ++i) {
            const double u = static_cast<double>(i) / pieces;
            out.emplace_back(s0 + u * length, a + ab * u);
        }
        s0 += length;
    }
    return out;
}

std::vector<SectionSample> sample_section(const RateMap& map, const std::vector<Vec3>& line, double spacing_m,
                                          double tolerance_m, const std::string& name)
{
    if (line.size() < 2) throw InputError(concat("section '", name, "': needs at least 2 points; got ", line.size()));
    require_positive(spacing_m, "section spacing (m)", concat("section '", name, "'"));
    std::vector<SectionSample> out;
    for (const auto& [arc, q] : section_points(line, spacing_m)) {
        SectionSample s;
        s.arc_length_m = arc;
        s.point_m = locate_on_surface(map.surface->mesh(), q).point_m;
        s.simulated_rate = map.at(q, tolerance_m, concat("section '", name, "' at ", arc, " m"));
        out.push_back(s);
    }
    return out;
}

std::vector<SectionPoint> points_on_section(const std::vector<Vec3>& line, const std::vector<PointComparison>& cs,
                                            double distance_m)
{
    std::vector<SectionPoint> out;
    if (line.size() < 2) return out;
    for (const auto& c : cs) {
        const auto [s, d] = project_on_polyline(line, c.position_m);
        if (d <= distance_m) out.push_back({s, c});
    }
    std::sort(out.begin(), out.end(), [](const SectionPoint& a, const SectionPoint& b) { return a.arc_length_m < b.arc_length_m; });
    return out;
}

void write_points_csv(const std::string& path, const std::vector<PointComparison>& cs)
{
    std::ofstream out = open_for_writing(path);
    out << "id,x_m,y_m,z_m,measured_mm_per_t,measured_sigma_mm_per_t,simulated_mm_per_t,simulated_min_mm_per_t,"
           "simulated_max_mm_per_t,error_mm_per_t,relative_error\n";
    for (const auto& c : cs)
        out << c.id << ',' << c.position_m.x << ',' << c.position_m.y << ',' << c.position_m.z << ',' << c.measured_rate
            << ',' << c.measured_sigma << ',' << c.simulated_rate << ',' << c.simulated_min << ',' << c.simulated_max
            << ',' << c.error() << ',' << c.relative_error() << '\n';
    finish_writing(out, path);
}

void write_section_csv(const std::string& path, const std::vector<SectionSample>& profile,
                       const std::vector<SectionPoint>& measured)
{
    std::ofstream out = open_for_writing(path);
    out << "kind,arc_length_m,x_m,y_m,z_m,simulated_mm_per_t,measured_mm_per_t,id\n";
    for (const auto& s : profile)
        out << "simulated," << s.arc_length_m << ',' << s.point_m.x << ',' << s.point_m.y << ',' << s.point_m.z << ','
            << s.simulated_rate << ",,\n";
    for (const auto& m : measured)
        out << "measured," << m.arc_length_m << ',' << m.comparison.position_m.x << ',' << m.comparison.position_m.y << ','
            << m.comparison.position_m.z << ',' << m.comparison.simulated_rate << ',' << m.comparison.measured_rate << ','
            << m.comparison.id << '\n';
    finish_writing(out, path);
}

}  // namespace dipper::wear
