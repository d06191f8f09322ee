// Command-line options of the benchmark programs: "--key value" pairs and --help.
#pragma once

#include <cstdio>
#include <string>

namespace dipper::bench {

/// Hands each "--key value" pair to take(key, value), which returns false for a key it does not know.
/// Returns -1 when all were taken, else the exit status: 0 after --help (usage printed), 2 for an unknown
/// key or a key without a value (named on stderr with the usage).
template <class Take>
int read_options(int argc, char** argv, const char* usage, Take take)
{
    for (int k = 1; k < argc; k += 2) {
        const std::string key = argv[k];
        if (key == "--help" || key == "-h") {
            std::fputs(usage, stdout);
            return 0;
        }
        if (k + 1 >= argc) {
            std::fprintf(stderr, "option %s needs a value\n%s", argv[k], usage);
            return 2;
        }
        if (!take(key, argv[k + 1])) {
            std::fprintf(stderr, "unknown option %s\n%s", argv[k], usage);
            return 2;
        }
    }
    return -1;
}

}  // namespace dipper::bench
