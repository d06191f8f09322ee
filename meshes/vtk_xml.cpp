#include "meshes/vtk_xml.h"

#include "core/errors.h"
#include "core/files.h"

#include <zlib.h>

#include <algorithm>
#include <cstring>

namespace dipper::meshes {

namespace {

constexpr std::size_t kBlockBytes = 1 << 16;  // VTK decompresses block by block; 64 KiB as its own writer uses

template <typename T>
struct VtkType;
template <>
struct VtkType<double> {
    static constexpr const char* name = "Float64";
};
template <>
struct VtkType<std::int64_t> {
    static constexpr const char* name = "Int64";
};
template <>
struct VtkType<std::uint32_t> {
    static constexpr const char* name = "UInt32";
};
template <>
struct VtkType<std::uint16_t> {
    static constexpr const char* name = "UInt16";
};

void put_u64(std::vector<unsigned char>& out, std::uint64_t v)
{
    for (int k = 0; k < 8; ++k) out.push_back(static_cast<unsigned char>(v >> (8 * k)));  // little endian
}

}  // namespace

template <typename T>
std::string VtkAppendedArrays::add(const std::string& name, const T* values, std::size_t count, int components)
{
    static_assert(sizeof(T) == 8 || sizeof(T) == 4 || sizeof(T) == 2, "a VTK type of 2, 4 or 8 bytes");
    return add_bytes(name, VtkType<T>::name, values, count * sizeof(T), components);
}

template std::string VtkAppendedArrays::add<double>(const std::string&, const double*, std::size_t, int);
template std::string VtkAppendedArrays::add<std::int64_t>(const std::string&, const std::int64_t*, std::size_t, int);
template std::string VtkAppendedArrays::add<std::uint32_t>(const std::string&, const std::uint32_t*, std::size_t, int);
template std::string VtkAppendedArrays::add<std::uint16_t>(const std::string&, const std::uint16_t*, std::size_t, int);

std::string VtkAppendedArrays::add_bytes(const std::string& name, const char* vtk_type, const void* bytes, std::size_t size,
                                         int components)
{
    const std::size_t offset = data_.size();
    // the header (UInt64 words): number of blocks, a block's size, the last block's size when it is partial
    // (0 when full), then each block's compressed size; the compressed blocks follow
    const std::size_t blocks = (size + kBlockBytes - 1) / kBlockBytes;
    put_u64(data_, blocks);
    put_u64(data_, kBlockBytes);
    put_u64(data_, size % kBlockBytes);
    const std::size_t sizes_at = data_.size();
    data_.resize(data_.size() + 8 * blocks);
    const auto* in = static_cast<const unsigned char*>(bytes);
    for (std::size_t b = 0; b < blocks; ++b) {
        const std::size_t n = std::min(kBlockBytes, size - b * kBlockBytes);
        uLongf compressed = compressBound(static_cast<uLong>(n));
        const std::size_t at = data_.size();
        data_.resize(at + compressed);
        // level 1: most of level 6's reduction on these arrays at several times its speed
        if (compress2(data_.data() + at, &compressed, in + b * kBlockBytes, static_cast<uLong>(n), 1) != Z_OK)
            throw SimulationError(concat("VTK array '", name, "': zlib could not compress block ", b));
        data_.resize(at + compressed);
        std::uint64_t c = compressed;
        for (int k = 0; k < 8; ++k) data_[sizes_at + 8 * b + static_cast<std::size_t>(k)] = static_cast<unsigned char>(c >> (8 * k));
    }
    return concat("<DataArray type=\"", vtk_type, "\" Name=\"", name, "\" NumberOfComponents=\"", components,
                  "\" format=\"appended\" offset=\"", offset, "\"/>\n");
}

void VtkAppendedArrays::write(const std::string& path, const std::string& file_type, const std::string& body) const
{
    std::ofstream out = open_for_writing(path);
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"" << file_type
        << "\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n"
        << body << "<AppendedData encoding=\"raw\">\n_";
    out.write(reinterpret_cast<const char*>(data_.data()), static_cast<std::streamsize>(data_.size()));
    out << "\n</AppendedData>\n</VTKFile>\n";
    finish_writing(out, path);
}

}  // namespace dipper::meshes
