#include "core/state_io.h"

#include <filesystem>
#include <fstream>
#include <iterator>

namespace dipper {

std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t hash)
{
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) {
        hash ^= p[k];
        hash *= 1099511628211ull;
    }
    return hash;
}

void StateWriter::raw(const void* data, std::size_t bytes)
{
    const auto* p = static_cast<const unsigned char*>(data);
    bytes_.insert(bytes_.end(), p, p + bytes);
}

void StateWriter::save(const std::string& path, const std::string& magic) const
{
    const std::string tmp = path + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw InputError(concat("cannot write state file '", tmp, "'"));
        const std::string header = magic + "\n";
        const std::uint64_t sum = fnv1a(bytes_.data(), bytes_.size(), fnv1a(header.data(), header.size()));
        out.write(header.data(), static_cast<std::streamsize>(header.size()));
        out.write(reinterpret_cast<const char*>(bytes_.data()), static_cast<std::streamsize>(bytes_.size()));
        out.write(reinterpret_cast<const char*>(&sum), sizeof sum);
        out.flush();
        if (!out) throw InputError(concat("writing state file '", tmp, "' failed (disk full?)"));
    }
    std::error_code error;
    std::filesystem::rename(tmp, path, error);
    if (error) throw InputError(concat("cannot rename '", tmp, "' to '", path, "': ", error.message()));
}

StateReader::StateReader(const std::string& path, const std::string& magic) : path_(path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(concat("cannot open state file '", path, "'"));
    bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    const std::string header = magic + "\n";
    if (bytes_.size() < header.size() || std::memcmp(bytes_.data(), header.data(), header.size()) != 0) {
        std::string first;
        for (unsigned char c : bytes_) {
            if (c == '\n' || first.size() > 40) break;
            first += (c >= 32 && c < 127) ? static_cast<char>(c) : '?';
        }
        throw InputError(concat("'", path, "' is not a state file of this kind: it starts with \"", first,
                                "\", expected \"", magic, "\""));
    }
    if (bytes_.size() < header.size() + sizeof(std::uint64_t))
        throw InputError(concat("state file '", path, "' is truncated: ", bytes_.size(), " bytes, no checksum"));
    end_ = bytes_.size() - sizeof(std::uint64_t);
    std::uint64_t stored;
    std::memcpy(&stored, bytes_.data() + end_, sizeof stored);
    const std::uint64_t sum = fnv1a(bytes_.data(), end_);
    if (sum != stored)
        throw InputError(concat("state file '", path, "' is corrupt or truncated: its checksum does not match (",
                                bytes_.size(), " bytes)"));
    pos_ = header.size();
}

void StateReader::raw(void* data, std::size_t bytes)
{
    if (bytes > left()) fail(concat("needed ", bytes, " more bytes, ", left(), " left"));
    if (bytes > 0) std::memcpy(data, bytes_.data() + pos_, bytes);
    pos_ += bytes;
}

std::string StateReader::text()
{
    const auto n = value<std::uint64_t>();
    if (n > left()) fail("a text longer than the file");
    std::string s(reinterpret_cast<const char*>(bytes_.data() + pos_), static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return s;
}

void StateReader::count(std::size_t n, const char* what)
{
    const auto read = value<std::uint64_t>();
    if (read != n) fail(concat("the state has ", read, " ", what, ", the world built from its input ", n));
}

void StateReader::tag(const char* name)
{
    const std::string got = text();
    if (got != name) fail(concat("expected section '", name, "', found '", got.substr(0, 40), "'"));
}

void StateReader::finish()
{
    if (left() != 0) fail(concat(left(), " unread bytes at the end"));
}

void StateReader::fail(const std::string& what) const
{
    throw InputError(concat("state file '", path_, "' does not match what this run expects at byte ", pos_, ": ", what,
                            " (was it written by another scenario or version?)"));
}

}  // namespace dipper
