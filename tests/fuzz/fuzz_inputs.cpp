// A seeded mutation fuzzer of what dipper reads from users' files: scenario and sweep files (read and
// checked as `dipper check` does), mesh files (STL, OBJ, PLY), checkpoints (resumed for 1 ms) and saved piles (a
// scenario started from them for 1 ms). Each input
// is a corpus file changed by a few random edits: bytes flipped, spans cut, repeated or moved, the file
// truncated, a number replaced by an extreme one (0, -1, 1e-17, 1e300, nan, a count of 10^11); a changed
// checkpoint mostly gets its checksum made to match.
//
// An input passes when dipper reads it or refuses it with an InputError or SimulationError. Anything else
// is a finding: another exception, a crash (under AddressSanitizer and UBSan, any memory or undefined-
// behaviour fault), or an input that takes longer than --input-seconds (a hang). The input is written to
// the output folder so that it can be replayed with --replay.
//
// usage: dipper_fuzz_inputs CORPUS_DIR OUT_DIR [--seconds S] [--input-seconds S] [--seed N] [--replay FILE]
#include "core/errors.h"
#include "core/state_io.h"
#include "meshes/mesh_io.h"
#include "scenario/runner.h"
#include "scenario/scenario.h"
#include "scenario/sweep.h"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
using namespace dipper;

namespace {

enum class Kind { scenario, mesh, checkpoint, pile };

struct Seed {
    Kind kind;
    std::string name, bytes;
};

std::string read_bytes(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& path, const std::string& bytes)
{
    std::ofstream out(path, std::ios::binary);
    out << bytes;
}

// the input under test, for the alarm's message (a hang) and for a crash's post-mortem
char g_current[4096] = "";

extern "C" void on_alarm(int)
{
    const char message[] = "dipper_fuzz_inputs: FOUND: an input ran past --input-seconds (a hang): ";
    (void)!write(2, message, sizeof message - 1);
    (void)!write(2, g_current, std::strlen(g_current));
    (void)!write(2, "\n", 1);
    _exit(2);
}

/// A few random edits of the seed's bytes.
std::string mutate(const std::string& seed, std::mt19937_64& random)
{
    static const char* const extremes[] = {"0", "-1", "1e-17", "1e300", "-1e300", "nan", "inf", "99999999999", "4294967296",
                                           "1e9", "2.5e-300", "0.5", "1e6", "-0", "3"};
    std::string s = seed;
    const auto pick = [&](std::size_t n) { return n == 0 ? std::size_t{0} : static_cast<std::size_t>(random() % n); };
    const int edits = 1 + static_cast<int>(random() % 3);
    for (int e = 0; e < edits; ++e) {
        switch (random() % 7) {
        case 0:  // one byte to any value
            if (!s.empty()) s[pick(s.size())] = static_cast<char>(random() & 0xFF);
            break;
        case 1: {  // a span cut out
            const std::size_t at = pick(s.size()), n = std::min(s.size() - at, 1 + pick(64));
            s.erase(at, n);
            break;
        }
        case 2: {  // a span repeated
            const std::size_t at = pick(s.size()), n = std::min(s.size() - at, 1 + pick(128));
            s.insert(pick(s.size()), s.substr(at, n));
            break;
        }
        case 3:  // the file cut short
            s.resize(pick(s.size() + 1));
            break;
        case 4: {  // a number made extreme (text files) or an 8-byte field overwritten (binary)
            std::vector<std::size_t> starts;
            for (std::size_t k = 0; k < s.size(); ++k)
                if ((std::isdigit(static_cast<unsigned char>(s[k])) != 0) && (k == 0 || std::strchr(" [,:-\n", s[k - 1]) != nullptr))
                    starts.push_back(k);
            if (starts.empty()) break;
            const std::size_t at = starts[pick(starts.size())];
            std::size_t end = at;
            while (end < s.size() && std::strchr("0123456789.eE+-", s[end]) != nullptr) ++end;
            s.replace(at, end - at, extremes[pick(std::size(extremes))]);
            break;
        }
        case 5: {  // eight bytes overwritten with 0xFF or zeros (counts and sizes of binary files)
            if (s.size() < 8) break;
            const std::size_t at = pick(s.size() - 7);
            std::fill_n(s.begin() + static_cast<std::ptrdiff_t>(at), 8, (random() & 1) ? '\xff' : '\0');
            break;
        }
        case 6: {  // a line moved
            std::vector<std::string> lines;
            std::size_t from = 0;
            for (std::size_t k = 0; k <= s.size(); ++k)
                if (k == s.size() || s[k] == '\n') lines.push_back(s.substr(from, k - from)), from = k + 1;
            if (lines.size() < 2) break;
            std::swap(lines[pick(lines.size())], lines[pick(lines.size())]);
            s.clear();
            for (std::size_t k = 0; k < lines.size(); ++k) s += (k ? "\n" : "") + lines[k];
            break;
        }
        }
    }
    return s;
}

/// Reads one input as dipper would; InputError and SimulationError are answers, anything else is not.
void exercise(Kind kind, const fs::path& file, const fs::path& work, const std::string& extension)
{
    switch (kind) {
    case Kind::scenario: {
        // a sweep file is read with every variant checked, as `dipper check` does
        if (read_bytes(file).find("dipper_sweep:") != std::string::npos) {
            (void)scenario::load_sweep(file.string());
            break;
        }
        const scenario::Scenario s = scenario::load_scenario(file.string());
        scenario::check_scenario(s);
        break;
    }
    case Kind::mesh:
        meshes::load_triangle_mesh(file.string());
        break;
    case Kind::checkpoint: {
        // a folder holding the run's outputs and the changed checkpoint, resumed for 1 ms of simulated time
        fs::remove_all(work);
        fs::create_directories(work);
        if (fs::exists(file.parent_path() / "probes.csv")) fs::copy(file.parent_path() / "probes.csv", work / "probes.csv");
        fs::copy_file(file, work / "checkpoint.bin");
        scenario::RunOptions quiet;
        quiet.progress = false;
        quiet.stop_after_s = 0.006;  // the corpus checkpoint is at 0.005 s
        scenario::resume_run(work.string(), quiet);
        break;
    }
    case Kind::pile: {
        fs::remove_all(work);
        const std::string text = "dipper_scenario: 1\nthreads: 1\ntime: {duration_s: 0.001}\nplanes:\n"
                                 "  - {name: floor, point_m: [0, 0, 0], normal: [0, 0, 1], material: ground}\n"
                                 "pile: " + file.filename().string() + "\noutput: {vtk_interval_s: 0}\n";
        scenario::RunOptions quiet;
        quiet.progress = false;
        scenario::run_scenario(scenario::parse_scenario(text, "pile_fuzz.yaml", file.parent_path().string()), work.string(), quiet);
        break;
    }
    }
    (void)extension;
}

}  // namespace

int main(int argc, char** argv)
{
    if (argc < 3) {
        std::fprintf(stderr, "usage: dipper_fuzz_inputs CORPUS_DIR OUT_DIR [--seconds S] [--input-seconds S] [--seed N] [--replay FILE]\n");
        return 1;
    }
    const fs::path corpus = argv[1], out = argv[2];
    double seconds = 30.0;
    unsigned input_seconds = 20;
    std::uint64_t seed = 1;
    std::string replay;
    for (int k = 3; k + 1 < argc; k += 2) {
        const std::string option = argv[k];
        if (option == "--seconds") seconds = std::atof(argv[k + 1]);
        else if (option == "--input-seconds") input_seconds = static_cast<unsigned>(std::atoi(argv[k + 1]));
        else if (option == "--seed") seed = std::strtoull(argv[k + 1], nullptr, 10);
        else if (option == "--replay") replay = argv[k + 1];
        else {
            std::fprintf(stderr, "dipper_fuzz_inputs: unknown option %s\n", option.c_str());
            return 1;
        }
    }
    fs::create_directories(out);
    std::signal(SIGALRM, on_alarm);

    // the corpus: scenario files (*.yaml), mesh files (*.stl, *.obj, *.ply), checkpoints (*/checkpoint.bin
    // beside the probes.csv of their run) and saved piles (*.txt)
    std::vector<Seed> seeds;
    for (const auto& entry : fs::recursive_directory_iterator(corpus)) {
        if (!entry.is_regular_file()) continue;
        const std::string ext = entry.path().extension().string();
        const Kind kind = ext == ".yaml" ? Kind::scenario : ext == ".bin" ? Kind::checkpoint : ext == ".txt" ? Kind::pile : Kind::mesh;
        if (ext != ".yaml" && ext != ".bin" && ext != ".txt" && ext != ".stl" && ext != ".obj" && ext != ".ply") continue;
        seeds.push_back({kind, entry.path().string(), read_bytes(entry.path())});
    }
    std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
    if (seeds.empty()) {
        std::fprintf(stderr, "dipper_fuzz_inputs: no corpus files in %s\n", corpus.c_str());
        return 1;
    }

    std::mt19937_64 random(seed);
    const auto start = std::chrono::steady_clock::now();
    std::size_t tried[4] = {0, 0, 0, 0}, refused[4] = {0, 0, 0, 0}, found = 0;
    const char* const names[4] = {"scenario", "mesh", "checkpoint", "pile"};
    for (std::uint64_t n = 0;; ++n) {
        if (replay.empty() && std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > seconds) break;
        if (!replay.empty() && n > 0) break;
        // each seed as it is first, then mutations of seeds drawn at random
        const Seed& base = !replay.empty() ? seeds.front() : seeds[n < seeds.size() ? n : random() % seeds.size()];
        const Kind kind = replay.empty() ? base.kind
                                         : (fs::path(replay).extension() == ".yaml" ? Kind::scenario
                                            : fs::path(replay).extension() == ".bin" ? Kind::checkpoint
                                            : fs::path(replay).extension() == ".txt" ? Kind::pile : Kind::mesh);
        std::string bytes = !replay.empty() ? read_bytes(replay) : n < seeds.size() ? base.bytes : mutate(base.bytes, random);
        // a checkpoint's checksum catches nearly every change; three times in four it is made to match, so
        // that what the checksum guards is read (as a bug in a writer would have it read)
        if (replay.empty() && kind == Kind::checkpoint && n >= seeds.size() && bytes.size() > 8 && random() % 4 != 0) {
            const std::uint64_t sum = fnv1a(bytes.data(), bytes.size() - 8);
            std::memcpy(&bytes[bytes.size() - 8], &sum, 8);
        }
        // the input is written beside its seed so that relative file names (meshes, motion files) resolve
        const fs::path seed_path = !replay.empty() ? fs::path(replay) : fs::path(base.name);
        const fs::path input = replay.empty() ? seed_path.parent_path() / concat(".fuzz_input", seed_path.extension().string()) : seed_path;
        if (replay.empty()) write_bytes(input, bytes);
        std::snprintf(g_current, sizeof g_current, "input %llu from %s (saved as %s)", static_cast<unsigned long long>(n),
                      seed_path.c_str(), (out / concat("input_", n, seed_path.extension().string())).c_str());
        if (replay.empty()) write_bytes(out / "last_input", bytes);  // what a crash leaves behind
        const auto k = static_cast<int>(kind);
        ++tried[k];
        // a sweep is checked variant by variant: up to 10,000 of them, 15 s here and more under the sanitizers
        const bool sweep = kind == Kind::scenario && bytes.find("dipper_sweep:") != std::string::npos;
        alarm(sweep ? 6 * input_seconds : input_seconds);
        try {
            exercise(kind, input, out / "resume", seed_path.extension().string());
        } catch (const InputError&) {
            ++refused[k];
        } catch (const SimulationError&) {
            ++refused[k];
        } catch (const std::exception& e) {
            ++found;
            write_bytes(out / concat("input_", n, seed_path.extension().string()), bytes);
            std::fprintf(stderr, "dipper_fuzz_inputs: FOUND: %s: %s\n", g_current, e.what());
        }
        alarm(0);
        if (replay.empty()) fs::remove(input);
    }
    std::printf("dipper_fuzz_inputs: seed %llu, %zu corpus files, %.0f s:", static_cast<unsigned long long>(seed), seeds.size(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    for (int k = 0; k < 4; ++k) std::printf(" %s %zu tried (%zu refused)", names[k], tried[k], refused[k]);
    std::printf("; %zu found anything\n", found);
    return found == 0 ? 0 : 1;
}
