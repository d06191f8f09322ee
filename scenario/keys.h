// Every key a scenario file may hold, with its type, default and meaning: the one table that the parser
// reads its keys from and that docs/scenario.md is checked against.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace dipper::scenario {

/// One key. `path` names it from the top with list items as `[]` (`fills[].sizes[].radius_m`);
/// `default_value` is "required", "none" (optional, no value) or the value taken when the key is absent,
/// written as in YAML.
struct KeySpec {
    std::string path;
    std::string type;  ///< number, integer, string, boolean, vector3, map, list
    std::string default_value;
    std::string description;
};

/// All keys, parents before their children.
const std::vector<KeySpec>& scenario_keys();
/// The key with this path; nullptr if there is none.
const KeySpec* find_key(const std::string& path);
/// The names of the keys directly under a map path ("" is the top), for "valid keys are ..." messages.
std::vector<std::string> child_keys(const std::string& path);

/// The library settings that a scenario key sets, as the library's messages name them
/// ("WorldSettings::step_s" is time.step_s).
const std::vector<std::pair<std::string, std::string>>& library_settings_as_keys();
/// A library message with each setting it names replaced by the scenario key that sets it.
std::string in_scenario_keys(std::string message);

}  // namespace dipper::scenario
