#include "scenario/sweep.h"

#include "core/errors.h"
#include "core/files.h"
#include "scenario/keys.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

namespace dipper::scenario {

namespace fs = std::filesystem;

namespace {

std::string read_text(const std::string& path, const std::string& what)
{
    std::ifstream in(path);
    if (!in) throw InputError(concat("cannot open ", what, " '", path, "'"));
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string at(const std::string& source, const YAML::Node& n)
{
    return concat(source, ":", n.Mark().line + 1, ":", n.Mark().column + 1, ": ");
}

/// Splits `a.b[2].c` into segments; list indices as numbers, and the key-table path (`a.b[].c`).
struct KeyPath {
    std::vector<std::string> names;  ///< map keys
    std::vector<long> indices;       ///< after names[k]: list index, or -1
    std::string spec;
};

KeyPath split_key(const std::string& key, const std::string& where)
{
    KeyPath p;
    static const std::regex segment(R"(([A-Za-z_][A-Za-z0-9_]*)(\[([0-9]+)\])?)");
    std::stringstream in(key);
    std::string part;
    while (std::getline(in, part, '.')) {
        std::smatch m;
        if (!std::regex_match(part, m, segment))
            throw InputError(concat(where, "key '", key, "': '", part, "' is not a key name, optionally with a list index [n]"));
        p.names.push_back(m[1]);
        p.indices.push_back(m[3].matched ? std::stol(m[3]) : -1);
        p.spec += (p.spec.empty() ? "" : ".") + m[1].str() + (m[3].matched ? "[]" : "");
    }
    const KeySpec* spec = find_key(p.spec);
    if (spec == nullptr) throw InputError(concat(where, "key '", key, "' is not a scenario key (docs/scenario.md lists them)"));
    if (spec->type == "map" || spec->type == "list")
        throw InputError(concat(where, "key '", key, "' is a ", spec->type, "; sweep a value inside it"));
    return p;
}

std::string number_text(double v)
{
    char buffer[40];
    std::snprintf(buffer, sizeof buffer, "%.12g", v);
    return buffer;
}

/// Simple value of summary.json (numbers and strings at the top level or inside a one-level object).
std::string json_field(const std::string& text, const std::string& key)
{
    const std::regex re("\"" + key + "\": \"?([^\",}\n]*)");
    std::smatch m;
    return std::regex_search(text, m, re) ? m[1].str() : "";
}

}  // namespace

std::vector<std::vector<std::string>> Sweep::variants() const
{
    std::vector<std::vector<std::string>> out{{}};
    for (const SweepParameter& p : parameters) {
        std::vector<std::vector<std::string>> next;
        for (const auto& v : out)
            for (const std::string& value : p.values) {
                auto w = v;
                w.push_back(value);
                next.push_back(std::move(w));
            }
        out = std::move(next);
    }
    return out;
}

std::string with_values(const std::string& text, const std::vector<KeyValue>& values, const std::string& text_source)
{
    YAML::Node root = YAML::Load(text);
    for (const KeyValue& kv : values) {
        const KeyPath path = split_key(kv.key, kv.where);
        const std::string key = concat(kv.where, "key '", kv.key, "': ");
        YAML::Node node = root;
        for (std::size_t s = 0; s < path.names.size(); ++s) {
            const bool last = s + 1 == path.names.size() && path.indices[s] < 0;
            if (!node.IsMap()) throw InputError(concat(key, "'", path.names[s], "' is not inside a map in ", text_source));
            if (last) {
                try {
                    node[path.names[s]] = YAML::Load(kv.value);
                } catch (const YAML::Exception& e) {
                    throw InputError(concat(key, "got '", kv.value, "'; expected a YAML value (", e.msg, ")"));
                }
                break;
            }
            if (!node[path.names[s]] || node[path.names[s]].IsNull()) {
                if (path.indices[s] >= 0) throw InputError(concat(key, text_source, " has no list '", path.names[s], "'"));
                node[path.names[s]] = YAML::Node(YAML::NodeType::Map);  // a map the text leaves to its defaults
            }
            YAML::Node child(node[path.names[s]]);
            if (path.indices[s] >= 0) {
                if (!child.IsSequence() || static_cast<std::size_t>(path.indices[s]) >= child.size())
                    throw InputError(concat(key, text_source, " has no item ", path.indices[s], " in '", path.names[s], "'"));
                const YAML::Node item = child[static_cast<std::size_t>(path.indices[s])];
                child.reset(item);  // alias, not assignment: assignment would overwrite the list
                if (s + 1 == path.names.size()) throw InputError(concat(key, "names a list item, not a value"));
            }
            node.reset(child);
        }
    }
    YAML::Emitter e;
    e.SetDoublePrecision(17);
    e << root;
    std::string out = e.c_str();
    out += "\n";
    return out;
}

Scenario Sweep::variant_scenario(std::size_t index) const
{
    const auto all = variants();
    DIPPER_ASSERT(index < all.size(), "variant index out of range");
    std::vector<KeyValue> values;
    for (std::size_t k = 0; k < parameters.size(); ++k)
        values.push_back({parameters[k].key, all[index][k], concat(source, ": parameters[", k, "]: ")});
    return parse_scenario(with_values(base_text, values, base_source), concat(base_source, " (variant ", index, " of ", source, ")"), base_dir);
}

Sweep load_sweep(const std::string& path)
{
    Sweep s;
    s.source = path;
    const std::string text = read_text(path, "sweep file");
    YAML::Node root;
    try {
        root = YAML::Load(text);
    } catch (const YAML::Exception& e) {
        throw InputError(concat(path, ":", e.mark.line + 1, ":", e.mark.column + 1, ": not valid YAML: ", e.msg));
    }
    if (!root.IsMap()) throw InputError(concat(path, ": expected a map with dipper_sweep, base and parameters"));
    for (auto it = root.begin(); it != root.end(); ++it) {
        const std::string key = it->first.Scalar();
        if (key != "dipper_sweep" && key != "base" && key != "parameters")
            throw InputError(concat(at(path, it->first), "unknown key '", key, "'; valid keys are: dipper_sweep, base, parameters"));
    }
    if (!root["dipper_sweep"] || root["dipper_sweep"].Scalar() != "1")
        throw InputError(concat(path, ": dipper_sweep: expected 1 (the format this dipper reads)"));
    if (!root["base"] || !root["base"].IsScalar()) throw InputError(concat(path, ": base: expected the base scenario file"));
    const fs::path dir = fs::absolute(path).parent_path();
    const fs::path base = fs::path(root["base"].Scalar()).is_absolute() ? fs::path(root["base"].Scalar()) : dir / root["base"].Scalar();
    s.base_source = base.string();
    s.base_text = read_text(s.base_source, concat("base scenario (", at(path, root["base"]), "base)"));
    s.base_dir = base.parent_path().string();
    parse_scenario(s.base_text, s.base_source, s.base_dir);  // the base alone must be valid

    const YAML::Node params = root["parameters"];
    if (!params || !params.IsSequence() || params.size() == 0)
        throw InputError(concat(path, ": parameters: expected a list of {key, values} or {key, from, to, step}"));
    for (std::size_t k = 0; k < params.size(); ++k) {
        const YAML::Node p = params[k];
        const std::string where = concat(at(path, p), "parameters[", k, "]");
        if (!p.IsMap()) throw InputError(concat(where, ": expected a map {key, values} or {key, from, to, step}"));
        for (auto it = p.begin(); it != p.end(); ++it) {
            const std::string key = it->first.Scalar();
            if (key != "key" && key != "values" && key != "from" && key != "to" && key != "step")
                throw InputError(concat(at(path, it->first), "unknown key 'parameters[", k, "].", key, "'; valid keys are: key, values, from, to, step"));
        }
        SweepParameter sp;
        if (!p["key"] || !p["key"].IsScalar()) throw InputError(concat(where, ".key: expected a scenario key path"));
        sp.key = p["key"].Scalar();
        split_key(sp.key, concat(at(path, p["key"]), "parameters[", k, "].key: "));
        for (const SweepParameter& other : s.parameters)
            if (other.key == sp.key)
                throw InputError(concat(at(path, p["key"]), "parameters[", k, "].key: '", sp.key, "' is swept already; each key once"));
        if (p["values"]) {
            if (p["from"] || p["to"] || p["step"]) throw InputError(concat(where, ": give either values or from/to/step, not both"));
            if (!p["values"].IsSequence() || p["values"].size() == 0) throw InputError(concat(at(path, p["values"]), "parameters[", k, "].values: expected a non-empty list"));
            for (const auto& v : p["values"]) {
                YAML::Emitter e;
                e << YAML::Flow << v;
                sp.values.push_back(e.c_str());
            }
        } else {
            double range[3];
            const char* names[3] = {"from", "to", "step"};
            for (int r = 0; r < 3; ++r) {
                const YAML::Node n = p[names[r]];
                if (!n || !n.IsScalar()) throw InputError(concat(where, ".", names[r], ": expected a number (or give values)"));
                char* end = nullptr;
                range[r] = std::strtod(n.Scalar().c_str(), &end);
                if (*end != '\0' || !std::isfinite(range[r]))
                    throw InputError(concat(at(path, n), "parameters[", k, "].", names[r], ": got \"", n.Scalar(), "\"; expected a number"));
            }
            if (!(range[2] > 0.0) || !(range[1] >= range[0]))
                throw InputError(concat(where, ": expected from <= to and step > 0; got from ", range[0], ", to ", range[1], ", step ", range[2]));
            const double count = std::floor((range[1] - range[0]) / range[2] + 1e-9) + 1.0;
            if (count > 10000) throw InputError(concat(where, ": ", count, " values; at most 10000"));
            for (int i = 0; i < static_cast<int>(count); ++i) sp.values.push_back(number_text(range[0] + i * range[2]));
        }
        s.parameters.push_back(sp);
    }
    // every variant must be a valid scenario before anything runs; their count first, from the parameters' counts
    // (three ranges of 10,000 values would be 10^12 variants to list)
    double product = 1.0;
    std::string counts;
    for (const SweepParameter& p : s.parameters) {
        product *= static_cast<double>(p.values.size());
        counts += concat(counts.empty() ? "" : " x ", p.values.size(), " (", p.key, ")");
    }
    // each variant is parsed and checked here (1.5 ms each): 10,000 take 15 s, far more runs than any study makes
    if (product > 10000) throw InputError(concat(path, ": ", product, " variants, ", counts, "; at most 10000"));
    const std::size_t n = s.variants().size();
    for (std::size_t v = 0; v < n; ++v) s.variant_scenario(v);
    return s;
}

namespace {
std::string variant_dir(const std::string& out_dir, std::size_t v)
{
    char name[32];
    std::snprintf(name, sizeof name, "variant_%03zu", v);
    return (fs::path(out_dir) / name).string();
}
}  // namespace

SweepOutcome run_sweep_variants(const Sweep& sweep, const std::string& out_dir, const RunOptions& options, int rank, int ranks)
{
    SweepOutcome outcome;
    int& failed = outcome.failed;
    const std::size_t n = sweep.variants().size();
    for (std::size_t v = 0; v < n; ++v) {
        if (static_cast<int>(v % static_cast<std::size_t>(ranks)) != rank) continue;
        try {
            const RunResult r = run_scenario(sweep.variant_scenario(v), variant_dir(out_dir, v), options);
            if (r.status != RunStatus::completed) ++failed;
            if (r.stopped_by_signal) {  // the user stops the sweep, not one variant of it
                outcome.stopped = true;
                return outcome;
            }
        } catch (const InputError& e) {
            // a variant refused as it starts (a pour that places nothing, too little memory) stops only itself:
            // its summary says why, and the others run on
            ++failed;
            std::fprintf(stderr, "dipper: sweep variant %zu refused: %s\n", v, e.what());
            std::error_code error;
            fs::create_directories(variant_dir(out_dir, v), error);
            const std::string path = variant_dir(out_dir, v) + "/summary.json";
            std::ofstream out = open_for_writing(path);
            std::string message;
            for (char c : std::string(e.what())) {
                if (c == '"' || c == '\\') message += '\\';
                message += static_cast<unsigned char>(c) < 32 ? ' ' : c;
            }
            out << "{\n  \"status\": \"refused\",\n  \"message\": \"" << message << "\"\n}\n";
            finish_writing(out, path);
        }
    }
    return outcome;
}

namespace {

/// The passes of a summary.json, each as the text of its {...} object.
std::vector<std::string> pass_objects(const std::string& summary)
{
    std::vector<std::string> passes;
    const std::size_t start = summary.find("\"passes\": [");
    if (start == std::string::npos) return passes;
    const std::size_t end = summary.find(']', start);
    std::size_t at = summary.find("{\"pass\":", start);
    while (at != std::string::npos && at < end) {
        const std::size_t close = summary.find('}', at);
        passes.push_back(summary.substr(at, close - at + 1));
        at = summary.find("{\"pass\":", close);
    }
    return passes;
}

}  // namespace

void write_sweep_table(const Sweep& sweep, const std::string& out_dir)
{
    const auto all = sweep.variants();
    std::vector<std::string> summaries;
    std::size_t passes = 0;
    for (std::size_t v = 0; v < all.size(); ++v) {
        const std::string summary_path = variant_dir(out_dir, v) + "/summary.json";
        std::ifstream in(summary_path);
        if (!in) throw InputError(concat("sweep variant ", v, " has no summary ('", summary_path, "'); did it run?"));
        std::stringstream text;
        text << in.rdbuf();
        summaries.push_back(text.str());
        passes = std::max(passes, pass_objects(summaries.back()).size());
    }
    const std::string path = (fs::path(out_dir) / "sweep.csv").string();
    std::ofstream out = open_for_writing(path);
    out << "variant";
    for (const auto& p : sweep.parameters) out << ',' << p.key;
    out << ",status,time_s,steps,particles,mass_kg,kinetic_energy_J,state_hash";
    // region masses, passes and wear as in the first variant's scenario
    const Scenario first = sweep.variant_scenario(0);
    for (const RegionProbe& r : first.regions) out << ',' << r.name << "_mass_kg";
    if (first.repose) out << ",repose_angle_deg";
    for (std::size_t k = 1; k <= passes; ++k)
        out << ",pass" << k << "_mass_kg,pass" << k << "_fill_factor,pass" << k << "_mean_dig_force_N,pass" << k << "_mean_interface_force_N,pass"
            << k << "_mean_interface_force_without_lip_N";
    if (first.shovel) out << ",tonnage_t";
    for (const WearSpec& w : first.wear) {
        out << ",wear_" << w.part << "_m3";
        if (w.part == "dipper") out << ",wear_dipper_bottom_m3,wear_dipper_lip_m3,wear_dipper_bars_m3";
    }
    out << '\n';
    for (std::size_t v = 0; v < all.size(); ++v) {
        const std::string& s = summaries[v];
        out << v;
        for (const std::string& value : all[v]) out << ",\"" << value << '"';
        for (const char* key : {"status", "time_s", "steps", "particles", "mass_kg", "kinetic_energy_J", "state_hash"})
            out << ',' << json_field(s, key);
        // names are looked up inside their own objects (a wall may carry a region's name)
        const std::string regions = s.substr(std::min(s.size(), s.find("\"region_mass_kg\"")));
        for (const RegionProbe& r : first.regions) out << ',' << json_field(regions, r.name);
        if (first.repose) out << ',' << json_field(s, "repose_angle_deg");
        const std::vector<std::string> p = pass_objects(s);
        for (std::size_t k = 0; k < passes; ++k)
            for (const char* key : {"mass_kg", "fill_factor", "mean_dig_force_N", "mean_interface_force_N", "mean_interface_force_without_lip_N"})
                out << ',' << (k < p.size() ? json_field(p[k], key) : "");
        if (first.shovel) out << ',' << json_field(s, "tonnage_t");
        const std::string wear = s.substr(std::min(s.size(), s.find("\"wear\": {")));
        for (const WearSpec& w : first.wear) {
            const std::string part = wear.substr(std::min(wear.size(), wear.find("\"" + w.part + "\": {")));
            out << ',' << json_field(part, "volume_m3");
            if (w.part == "dipper") {
                const std::string by_region = part.substr(std::min(part.size(), part.find("\"volume_by_region_m3\"")));
                for (const char* region : {"bottom", "lip", "bars"}) out << ',' << json_field(by_region, region);
            }
        }
        out << '\n';
    }
    finish_writing(out, path);
}

}  // namespace dipper::scenario
