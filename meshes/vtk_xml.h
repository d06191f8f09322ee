// VTK XML files (.vtp) with their arrays appended as raw zlib-compressed binary, which ParaView and VTK's
// readers read directly: a third to a tenth of the size of the same file in ASCII, and exact (doubles are
// written as they are, not rounded to text).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dipper::meshes {

/// Collects a file's arrays, compressed as they are added, and writes the file around them.
///
///     VtkAppendedArrays a;
///     body += a.add("position_m", x.data(), 3 * n, 3);   // the DataArray element to place in the XML
///     a.write(path, "PolyData", body);
class VtkAppendedArrays {
public:
    /// Compresses `count` values (components x tuples) and returns the <DataArray .../> element that refers
    /// to them. Supported types: double, std::int64_t, std::uint32_t, std::uint16_t.
    template <typename T>
    std::string add(const std::string& name, const T* values, std::size_t count, int components = 1);

    /// Writes <VTKFile type="file_type"> with `body` (the XML inside it, e.g. <PolyData>...</PolyData>) and
    /// the appended arrays. Throws InputError if the file cannot be written.
    void write(const std::string& path, const std::string& file_type, const std::string& body) const;

private:
    std::string add_bytes(const std::string& name, const char* vtk_type, const void* bytes, std::size_t size, int components);
    std::vector<unsigned char> data_;
};

}  // namespace dipper::meshes
