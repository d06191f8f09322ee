// Text output files that fail loudly: a folder that cannot be written, or a disk that fills, is an error
// that names the file.
#pragma once

#include <fstream>
#include <string>

namespace dipper {

/// Opens `path` for writing with 10 significant digits; throws InputError naming the path if it cannot.
std::ofstream open_for_writing(const std::string& path);
/// Flushes and checks the stream; throws InputError naming the path if anything failed while writing.
void finish_writing(std::ofstream& out, const std::string& path);

}  // namespace dipper
