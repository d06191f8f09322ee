// Text for summary.json: strings escaped, numbers at full precision or null.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace dipper::scenario::detail {

inline std::string json_escape(const std::string& s)
{
    std::string out;
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\', out += c;
        else if (c == '\n') out += "\\n";
        else if (static_cast<unsigned char>(c) < 32) {
            char u[8];
            std::snprintf(u, sizeof u, "\\u%04x", static_cast<unsigned>(c));
            out += u;
        }
        else out += c;
    }
    return out;
}

/// A number for JSON: full precision, or null where a diverged run left it non-finite.
inline std::string json_number(double v)
{
    if (!std::isfinite(v)) return "null";
    char buffer[40];
    std::snprintf(buffer, sizeof buffer, "%.10g", v);
    return buffer;
}

}  // namespace dipper::scenario::detail
