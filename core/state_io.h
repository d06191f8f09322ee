// Binary state files (checkpoints): a writer and a reader of plain values and arrays, in this machine's
// byte order, with an FNV-1a 64 checksum over everything written. The reader checks every length
// against what is left, so a truncated or corrupt file gives an error, never a crash or a huge allocation.
//
// A class lists its checkpoint fields once, in one template that the writer and the reader both run:
//
//     template <class IO, class Self> static void state_fields(IO& io, Self& s)
//     {
//         io.tag("counter");
//         io(s.count_, s.sums_, s.name_);   // plain values, std::vector of plain values, std::string, bool
//     }
//     void write_state(StateWriter& out) const { state_fields(out, *this); }
//     void read_state(StateReader& in) { state_fields(in, *this); /* then check what was read */ }
//
// Self is the class itself when reading and the const class when writing. A field that goes through an
// accessor is read into a local and applied under `if constexpr (IO::reading)`.
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
    static constexpr bool reading = false;
    /// Writes each field: a plain value raw, a std::vector as its length and elements, a std::string as
    /// text, a bool as one byte.
    template <typename... T>
    void operator()(const T&... fields)
    {
        (field(fields), ...);
    }
    template <typename T>
    void field(const T& v)
    {
        value(v);
    }
    template <typename T>
    void field(const std::vector<T>& v)
    {
        array(v);
    }
    void field(const std::string& s) { text(s); }
    void field(bool b) { value<std::uint8_t>(b ? 1 : 0); }
    /// How many of something the state holds (the reader refuses another number).
    void count(std::size_t n, const char* /*what*/) { value<std::uint64_t>(n); }
    /// A part with its own state: its write_state.
    template <typename T>
    void object(const T& part)
    {
        part.write_state(*this);
    }

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

    static constexpr bool reading = true;
    /// Reads each field back in place, as StateWriter::operator() wrote it.
    template <typename... T>
    void operator()(T&... fields)
    {
        (field(fields), ...);
    }
    template <typename T>
    void field(T& v)
    {
        v = value<T>();
    }
    template <typename T>
    void field(std::vector<T>& v)
    {
        array(v);
    }
    void field(std::string& s) { s = text(); }
    void field(bool& b) { b = value<std::uint8_t>() != 0; }
    /// Reads a count that StateWriter::count wrote and refuses one other than `n`, the number of `what` the
    /// reading world was built with.
    void count(std::size_t n, const char* what);
    /// A part with its own state: its read_state.
    template <typename T>
    void object(T& part)
    {
        part.read_state(*this);
    }

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
