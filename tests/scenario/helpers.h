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

/// A scenario of 2 t of 300 mm spheres off to the side on the ground, for 1 s on one thread, with `extra` keys
/// added (a shovel, rocks, wear).
inline std::string machine_scenario(const std::string& extra)
{
    return concat(R"(dipper_scenario: 1
name: machine
threads: 1
time: {duration_s: 1.0}
planes:
  - {name: ground, point_m: [0, 0, 0], normal: [0, 0, 1], material: ground}
fills:
  - {mass_kg: 2000, box: {min_m: [-20, -1, 0], max_m: [-18, 1, 1]}, sizes: [{radius_m: 0.15, mass_fraction: 1}]}
)", extra);
}

}  // namespace dipper::test
