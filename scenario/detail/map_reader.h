// Reading one YAML map of a scenario file through the key table (scenario/keys.h): unknown and repeated keys
// refused with their line, absent keys given the table's default, every value checked for its type.
#pragma once

#include "core/errors.h"
#include "core/vec3.h"
#include "scenario/keys.h"
#include "scenario/scenario.h"  // joined

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

namespace dipper::scenario::detail {

/// One YAML map of the scenario, read through the key table: every key it holds must be in the table,
/// every key read must be in the table, and an absent key takes the table's default.
class MapReader {
public:
    MapReader(YAML::Node node, std::string spec_path, std::string shown_path, const std::string& source,
              YAML::Mark mark)
        : node_(std::move(node)), spec_(std::move(spec_path)), shown_(std::move(shown_path)), source_(source), mark_(mark)
    {
        if (!node_.IsDefined() || node_.IsNull()) {
            node_ = YAML::Node(YAML::NodeType::Map);
            return;
        }
        mark_ = node_.Mark();
        if (!node_.IsMap())
            throw InputError(concat(position(node_.Mark()), shown_.empty() ? "the file" : shown_, ": got ", shown(node_),
                                    "; expected a map of keys (key: value)"));
        const std::vector<std::string> valid = child_keys(spec_);
        for (auto it = node_.begin(); it != node_.end(); ++it) {
            const std::string key = it->first.Scalar();
            for (auto before = node_.begin(); before != it; ++before)
                if (before->first.Scalar() == key)
                    throw InputError(concat(position(it->first.Mark()), "key '", full(key), "' appears twice (first on line ",
                                            before->first.Mark().line + 1, "); give each key once"));
            bool known = false;
            for (const auto& v : valid) known = known || v == key;
            if (!known)
                throw InputError(concat(position(it->first.Mark()), "unknown key '", full(key), "'; valid keys",
                                        spec_.empty() ? "" : concat(" under '", shown_, "'"), " are: ", joined(valid)));
        }
    }

    /// The value under key; nullopt if the key is absent or has no value (`key:` or `key: ~`).
    std::optional<YAML::Node> find(const std::string& key) const
    {
        for (auto it = node_.begin(); it != node_.end(); ++it)
            if (it->first.Scalar() == key) {
                if (it->second.IsNull()) return std::nullopt;
                return it->second;
            }
        return std::nullopt;
    }
    std::optional<YAML::Mark> key_mark(const std::string& key) const
    {
        for (auto it = node_.begin(); it != node_.end(); ++it)
            if (it->first.Scalar() == key) return it->first.Mark();
        return std::nullopt;
    }

    bool has(const std::string& key) const { return find(key).has_value(); }

    /// "FILE:LINE:COL: key.path" of a key (of the map itself if the key is absent).
    std::string where(const std::string& key) const
    {
        const auto n = find(key);
        const auto k = key_mark(key);
        return concat(position(n ? n->Mark() : (k ? *k : mark_)), full(key));
    }

    double number(const std::string& key) const
    {
        const std::string text = scalar(key, "a number");
        char* end = nullptr;
        errno = 0;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v))
            fail(key, concat("\"", text, "\""), concat("a finite number", unit_hint(key)));
        return v;
    }

    std::int64_t integer(const std::string& key) const
    {
        const std::string text = scalar(key, "an integer");
        char* end = nullptr;
        errno = 0;
        const long long v = std::strtoll(text.c_str(), &end, 10);
        if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE) fail(key, concat("\"", text, "\""), "an integer");
        return v;
    }

    std::string text(const std::string& key) const { return scalar(key, "a text"); }
    /// A text that must be one of `values`; anything else is an error listing them.
    std::string one_of(const std::string& key, const std::vector<std::string>& values) const
    {
        const std::string v = text(key);
        for (const std::string& allowed : values)
            if (v == allowed) return v;
        std::string list;
        for (std::size_t k = 0; k < values.size(); ++k)
            list += (k == 0 ? "" : k + 1 == values.size() ? " or " : ", ") + values[k];
        fail(key, concat("\"", v, "\""), list);
    }
    std::optional<std::string> optional_text(const std::string& key) const
    {
        if (!has(key)) return std::nullopt;
        return text(key);
    }

    bool boolean(const std::string& key) const
    {
        const std::string text = scalar(key, "true or false");
        if (text == "true") return true;
        if (text == "false") return false;
        fail(key, concat("\"", text, "\""), "true or false");
    }

    Vec3 vector3(const std::string& key) const
    {
        const YAML::Node n = has(key) ? *find(key) : YAML::Load(default_of(key));
        Vec3 v;
        if (!point_of(n, v)) fail(key, shown(n), concat("a list of 3 finite numbers [x, y, z]", unit_hint(key)));
        // positions, speeds, angles and accelerations of a mine site: a larger number is a typing slip whose
        // effects surface far from the key (a translate_m of 1e300 was refused as a "degenerate triangle")
        constexpr double kLargest = 1e6;
        if (!(std::abs(v.x) <= kLargest && std::abs(v.y) <= kLargest && std::abs(v.z) <= kLargest))
            fail(key, shown(n), concat("a list of 3 numbers each within +-", kLargest, unit_hint(key)));
        return v;
    }

    MapReader map(const std::string& key) const
    {
        spec_of(key);
        if (!has(key) && default_of(key) == "required") fail(key, "nothing", "a map (this key is required)");
        return MapReader(has(key) ? *find(key) : YAML::Node(), child_spec(key), full(key), source_, mark_);
    }

    std::vector<MapReader> maps(const std::string& key) const
    {
        spec_of(key);
        std::vector<MapReader> out;
        if (!has(key)) {
            if (default_of(key) == "required") fail(key, "nothing", "a list (this key is required)");
            return out;
        }
        const YAML::Node n = *find(key);
        if (!n.IsSequence()) fail(key, shown(n), "a list of maps");
        for (std::size_t k = 0; k < n.size(); ++k)
            out.emplace_back(n[k], child_spec(key) + "[]", concat(full(key), "[", k, "]"), source_, n[k].Mark());
        return out;
    }

    /// A list of at least `min_count` points [x, y, z].
    std::vector<Vec3> vector3_list(const std::string& key, std::size_t min_count) const
    {
        spec_of(key);
        const std::string expected = concat("a list of at least ", min_count, " points [x, y, z]");
        if (!has(key)) fail(key, "nothing", expected);
        const YAML::Node n = *find(key);
        if (!n.IsSequence() || n.size() < min_count) fail(key, shown(n), expected);
        std::vector<Vec3> out(n.size());
        for (std::size_t k = 0; k < n.size(); ++k)
            if (!point_of(n[k], out[k])) fail(key, shown(n), expected);
        return out;
    }

    std::vector<std::string> texts(const std::string& key) const
    {
        spec_of(key);
        if (!has(key)) fail(key, "nothing", "a list of names");
        const YAML::Node n = *find(key);
        if (!n.IsSequence()) fail(key, shown(n), "a list of names");
        std::vector<std::string> out;
        for (const auto& item : n) {
            if (!item.IsScalar()) fail(key, shown(n), "a list of names");
            out.push_back(item.Scalar());
        }
        return out;
    }

    [[noreturn]] void fail(const std::string& key, const std::string& got, const std::string& expected) const
    {
        throw InputError(concat(where(key), ": got ", got, "; expected ", expected));
    }

private:
    std::string full(const std::string& key) const { return shown_.empty() ? key : shown_ + "." + key; }
    std::string child_spec(const std::string& key) const { return spec_.empty() ? key : spec_ + "." + key; }
    const KeySpec& spec_of(const std::string& key) const
    {
        const KeySpec* s = find_key(child_spec(key));
        DIPPER_ASSERT(s != nullptr, "the parser reads key '" + child_spec(key) + "' that the key table lacks");
        return *s;
    }
    std::string default_of(const std::string& key) const { return spec_of(key).default_value; }
    std::string unit_hint(const std::string& key) const
    {
        const std::string d = spec_of(key).description;
        return d.empty() ? "" : concat(" (", d, ")");
    }
    std::string position(const YAML::Mark& m) const
    {
        return concat(source_, ":", m.line + 1, ":", m.column + 1, ": ");
    }
    /// A YAML list of exactly three finite numbers; false if it is anything else.
    static bool point_of(const YAML::Node& n, Vec3& v)
    {
        if (!n.IsSequence() || n.size() != 3) return false;
        for (int a = 0; a < 3; ++a) {
            const std::string text = n[a].IsScalar() ? n[a].Scalar() : "";
            char* end = nullptr;
            const double x = std::strtod(text.c_str(), &end);
            if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(x)) return false;
            (a == 0 ? v.x : a == 1 ? v.y : v.z) = x;
        }
        return true;
    }
    static std::string shown(const YAML::Node& n)
    {
        if (n.IsScalar()) return concat("\"", n.Scalar(), "\"");
        YAML::Emitter e;
        e << YAML::Flow << n;
        return e.c_str();
    }
    std::string scalar(const std::string& key, const char* expected) const
    {
        const KeySpec& spec = spec_of(key);
        if (!has(key)) {
            if (spec.default_value == "required") fail(key, "nothing", concat(expected, " (this key is required)"));
            DIPPER_ASSERT(spec.default_value != "none", "optional key without a default read as a value: " + spec.path);
            return spec.default_value;
        }
        const YAML::Node n = *find(key);
        if (!n.IsScalar()) fail(key, shown(n), expected);
        return n.Scalar();
    }

    YAML::Node node_;
    std::string spec_, shown_;
    const std::string& source_;
    YAML::Mark mark_;
};

}  // namespace dipper::scenario::detail
