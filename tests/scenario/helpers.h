// Small helpers shared by the scenario tests.
#pragma once

#include "core/errors.h"
#include "scenario/scenario.h"

#include <fstream>
#include <sstream>
#include <string>

namespace dipper::test {

/// The InputError message of parsing `text` (as "case.yaml"), or "" if it parsed.
inline std::string scenario_error(const std::string& text)
{
    try {
        scenario::parse_scenario(text, "case.yaml", ".");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

/// A whole text file; "" if it cannot be read.
inline std::string read_text_file(const std::string& path)
{
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace dipper::test
