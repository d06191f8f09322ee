#include "rigid/motion_curves.h"

#include "core/csv.h"
#include "core/errors.h"
#include "core/files.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace dipper::rigid {

namespace {

const std::vector<std::string>& columns()
{
    static const std::vector<std::string> c{"time_s", "hoist_length_m", "crowd_extension_m", "swing_deg", "door_deg"};
    return c;
}
const char* const kOptional = "propel_m";
const char* const kExpected = "time_s,hoist_length_m,crowd_extension_m,swing_deg,door_deg and optionally propel_m";

}  // namespace

MotionCurves MotionCurves::from_samples(std::vector<MotionSample> samples, const std::string& source)
{
    if (samples.size() < 2) throw InputError(concat(source, ": motion needs at least 2 samples; got ", samples.size()));
    for (std::size_t k = 0; k < samples.size(); ++k) {
        const MotionSample& s = samples[k];
        const std::string where = concat(source, ", sample ", k);
        for (const double v : {s.time_s, s.hoist_length_m, s.crowd_extension_m, s.swing_deg, s.door_deg, s.propel_m})
            if (!std::isfinite(v)) throw InputError(concat(where, ": a value is not finite"));
        if (k > 0 && !(s.time_s > samples[k - 1].time_s))
            throw InputError(concat(where, ": time_s ", s.time_s, " does not follow ", samples[k - 1].time_s,
                                    "; times must increase"));
        require_positive(s.hoist_length_m, "hoist_length_m", where);
        require_positive(s.crowd_extension_m, "crowd_extension_m", where);
    }
    MotionCurves m;
    m.samples_ = std::move(samples);
    m.source_ = source;
    const std::size_t n = m.samples_.size();
    std::vector<double> t(n);
    for (std::size_t k = 0; k < n; ++k) t[k] = m.samples_[k].time_s;
    m.slopes_.resize(n);
    const auto fill = [&](double MotionSample::*field) {
        std::vector<double> y(n);
        for (std::size_t k = 0; k < n; ++k) y[k] = m.samples_[k].*field;
        const std::vector<double> slope = monotone_slopes(t, y);
        for (std::size_t k = 0; k < n; ++k) m.slopes_[k].*field = slope[k];
    };
    for (double MotionSample::*field : {&MotionSample::hoist_length_m, &MotionSample::crowd_extension_m, &MotionSample::swing_deg,
                                        &MotionSample::door_deg, &MotionSample::propel_m})
        fill(field);
    return m;
}

std::vector<double> monotone_slopes(const std::vector<double>& t, const std::vector<double>& y, const std::vector<bool>& rest)
{
    const std::size_t n = t.size();
    std::vector<double> m(n, 0.0);
    for (std::size_t k = 1; k + 1 < n; ++k) {
        const double h0 = t[k] - t[k - 1], h1 = t[k + 1] - t[k];
        const double d0 = (y[k] - y[k - 1]) / h0, d1 = (y[k + 1] - y[k]) / h1;
        if ((k < rest.size() && rest[k]) || d0 * d1 <= 0.0) continue;
        const double w0 = 2.0 * h1 + h0, w1 = h1 + 2.0 * h0;
        m[k] = (w0 + w1) / (w0 / d0 + w1 / d1);
    }
    return m;
}

double hermite(double t0, double t1, double y0, double y1, double m0, double m1, double t)
{
    // written from y0 so that a drive that stands (y1 = y0, slopes 0) keeps its value to the last bit
    const double h = t1 - t0, u = (t - t0) / h, u2 = u * u, u3 = u2 * u;
    return y0 + (y1 - y0) * (3.0 * u2 - 2.0 * u3) + h * (m0 * (u3 - 2.0 * u2 + u) + m1 * (u3 - u2));
}

MotionCurves MotionCurves::from_csv(const std::string& path)
{
    std::ifstream in(path);
    if (!in) throw InputError(concat("cannot open motion file '", path, "'"));
    std::string line;
    int number = 0;
    std::map<std::string, std::size_t> column;
    std::vector<MotionSample> samples;
    double last_time = -1e300;
    while (std::getline(in, line)) {
        ++number;
        const std::string text = trim(line);
        if (text.empty() || text[0] == '#') continue;
        const std::vector<std::string> cells = split_csv_line(text);
        const std::string where = concat(path, ":", number);
        if (column.empty()) {
            for (std::size_t c = 0; c < cells.size(); ++c) {
                if (std::find(columns().begin(), columns().end(), cells[c]) == columns().end() && cells[c] != kOptional)
                    throw InputError(concat(where, ": unknown column '", cells[c], "'; expected ", kExpected));
                if (column.count(cells[c])) throw InputError(concat(where, ": column '", cells[c], "' appears twice"));
                column[cells[c]] = c;
            }
            for (const auto& name : columns())
                if (!column.count(name))
                    throw InputError(concat(where, ": the header lacks column '", name, "'; expected ", kExpected));
            continue;
        }
        if (cells.size() != column.size())
            throw InputError(concat(where, ": ", cells.size(), " values; the header has ", column.size(), " columns"));
        const auto value = [&](const std::string& name) { return parse_csv_number(cells[column[name]], where, name); };
        MotionSample s{value("time_s"), value("hoist_length_m"), value("crowd_extension_m"), value("swing_deg"), value("door_deg"),
                       column.count(kOptional) ? value(kOptional) : 0.0};
        if (!(s.time_s > last_time))
            throw InputError(concat(where, ": time_s ", s.time_s, " is not after the previous time ", last_time,
                                    "; times must increase"));
        if (!(s.hoist_length_m > 0.0)) throw InputError(concat(where, ": hoist_length_m is ", s.hoist_length_m, "; expected > 0"));
        if (!(s.crowd_extension_m > 0.0))
            throw InputError(concat(where, ": crowd_extension_m is ", s.crowd_extension_m, "; expected > 0"));
        last_time = s.time_s;
        samples.push_back(s);
    }
    if (column.empty()) throw InputError(concat("motion file '", path, "' is empty; expected a header and samples"));
    return from_samples(std::move(samples), path);
}

MotionSample MotionCurves::at(double t) const
{
    if (t <= samples_.front().time_s) return samples_.front();
    if (t >= samples_.back().time_s) return samples_.back();
    const auto it = std::upper_bound(samples_.begin(), samples_.end(), t,
                                     [](double time, const MotionSample& s) { return time < s.time_s; });
    const std::size_t k = static_cast<std::size_t>(it - samples_.begin()) - 1;
    const MotionSample &a = samples_[k], &b = samples_[k + 1], &ma = slopes_[k], &mb = slopes_[k + 1];
    const auto curve = [&](double MotionSample::*field) {
        return hermite(a.time_s, b.time_s, a.*field, b.*field, ma.*field, mb.*field, t);
    };
    return {t, curve(&MotionSample::hoist_length_m), curve(&MotionSample::crowd_extension_m), curve(&MotionSample::swing_deg),
            curve(&MotionSample::door_deg), curve(&MotionSample::propel_m)};
}

void MotionCurves::write_csv(const std::string& path) const
{
    std::ofstream out = open_for_writing(path);
    out << "time_s,hoist_length_m,crowd_extension_m,swing_deg,door_deg,propel_m\n";
    for (const MotionSample& s : samples_)
        out << s.time_s << ',' << s.hoist_length_m << ',' << s.crowd_extension_m << ',' << s.swing_deg << ',' << s.door_deg << ','
            << s.propel_m << '\n';
    finish_writing(out, path);
}

}  // namespace dipper::rigid
