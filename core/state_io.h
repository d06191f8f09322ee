// Binary state files (checkpoints): a writer and a reader of plain values and arrays, in this machine's
// byte order, with an FNV-1a 64 checksum over everything written. The reader checks every length
// against what is left, so a truncated or corrupt file gives an error, never a crash or a huge allocation.
#pragma once

#include "core/errors.h"

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

namespace dipper {

/// FNV-1a 64-bit hash of bytes, continuing from `hash` (start with kFnvOffset).
inline constexpr std::uint64_t kFnvOffset = 14695981039346656037ull;
std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t hash = kFnvOffset);

/// Collects a state in memory; save() writes it with a header line and the checksum at the end.
class StateWriter {
public:
    template <typename T>
    void value(const T& v)
    {
        static_assert(std::is_trivially_copyable_v<T>, "only plain values are written raw");
        raw(&v, sizeof(T));
    }
    template <typename T>
    void array(const std::vector<T>& v)
    {
        static_assert(std::is_trivially_copyable_v<T>, "only plain values are written raw");
        value<std::uint64_t>(v.size());
        raw(v.data(), v.size() * sizeof(T));
    }
    void text(const std::string& s)
    {
        value<std::uint64_t>(s.size());
        raw(s.data(), s.size());
    }
    /// A named section marker; the reader checks it, so a file written by other code is refused early.
    void tag(const char* name) { text(name); }
    void raw(const void* data, std::size_t bytes);

    /// Writes `magic` (one line), the bytes and their checksum to path.tmp, then renames it to path
    /// (a reader never sees half a file). Throws InputError naming the path if the disk refuses.
    void save(const std::string& path, const std::string& magic) const;

private:
    std::vector<unsigned char> bytes_;
};

/// Reads a file written by StateWriter::save, after checking the magic line and the checksum.
class StateReader {
public:
    /// Throws InputError naming the file if it is missing, truncated, corrupt or of another kind.
    StateReader(const std::string& path, const std::string& magic);

    template <typename T>
    T value()
    {
        static_assert(std::is_trivially_copyable_v<T>, "only plain values are read raw");
        T v;
        raw(&v, sizeof(T));
        return v;
    }
    template <typename T>
    void array(std::vector<T>& v)
    {
        const auto n = value<std::uint64_t>();
        if (n > left() / (sizeof(T) > 0 ? sizeof(T) : 1)) fail("an array longer than the file");
        v.resize(static_cast<std::size_t>(n));
        raw(v.data(), v.size() * sizeof(T));
    }
    std::string text();
    /// Checks a section marker written by StateWriter::tag.
    void tag(const char* name);
    void raw(void* data, std::size_t bytes);
    std::size_t left() const { return end_ - pos_; }
    /// Throws unless everything was read.
    void finish();
    [[noreturn]] void fail(const std::string& what) const;
    const std::string& path() const { return path_; }

private:
    std::string path_;
    std::vector<unsigned char> bytes_;
    std::size_t pos_ = 0, end_ = 0;
};

}  // namespace dipper
