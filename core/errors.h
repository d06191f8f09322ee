// The two kinds of failure dipper reports: bad input, and a simulation that went wrong.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace dipper {

/// Bad input: a value, key, file or combination that the library refuses. The message names what was
/// wrong, the value received, what was expected, and where it came from.
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A run that went wrong: non-finite state, an overlap that means the step is too large, and so on.
/// The message names the step, time, particle or contact, and suggests a remedy.
class SimulationError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Builds a message from streamable parts: `concat("radius_m must be > 0; got ", r)`.
template <typename... Parts>
std::string concat(const Parts&... parts)
{
    std::ostringstream out;
    out.precision(10);
    (out << ... << parts);
    return out.str();
}

/// Throws InputError unless `value` is finite and > 0.
void require_positive(double value, const std::string& what, const std::string& where);
/// Throws InputError unless `value` is finite and >= 0.
void require_non_negative(double value, const std::string& what, const std::string& where);
/// Throws InputError unless lo <= value <= hi (and finite).
void require_in_range(double value, double lo, double hi, const std::string& what, const std::string& where);

}  // namespace dipper

/// Guards an internal invariant (a bug if it fails, not bad input). Stays on in release builds.
#define DIPPER_ASSERT(condition, message)                                                          \
    do {                                                                                           \
        if (!(condition))                                                                          \
            throw std::logic_error(std::string("internal error: ") + (message) + " [" #condition \
                                   "] at " __FILE__ ":" + std::to_string(__LINE__));               \
    } while (false)
