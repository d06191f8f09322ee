#include "meshes/vtk_surface.h"

#include "core/errors.h"
#include "core/files.h"

namespace dipper::meshes {

namespace {

void write_fields(std::ostream& out, const std::vector<ScalarField>& fields)
{
    for (const auto& [name, values] : fields) {
        out << "<DataArray type=\"Float64\" Name=\"" << name << "\" format=\"ascii\">\n";
        for (const double v : values) out << v << '\n';
        out << "</DataArray>\n";
    }
}

}  // namespace

void write_surface_vtp(const std::string& path, const std::vector<Vec3>& vertices_m,
                       const std::vector<std::array<std::uint32_t, 3>>& triangles,
                       const std::vector<ScalarField>& point_fields, const std::vector<ScalarField>& cell_fields)
{
    for (const auto& f : point_fields)
        DIPPER_ASSERT(f.second.size() == vertices_m.size(), "point field '" + f.first + "' needs one value per vertex");
    for (const auto& f : cell_fields)
        DIPPER_ASSERT(f.second.size() == triangles.size(), "cell field '" + f.first + "' needs one value per triangle");

    std::ofstream out = open_for_writing(path);
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n"
        << "<Piece NumberOfPoints=\"" << vertices_m.size()
        << "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" << triangles.size() << "\">\n";
    out << "<Points>\n<DataArray type=\"Float64\" Name=\"position_m\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const Vec3& v : vertices_m) out << v.x << ' ' << v.y << ' ' << v.z << '\n';
    out << "</DataArray>\n</Points>\n";
    if (!point_fields.empty()) {
        out << "<PointData Scalars=\"" << point_fields.front().first << "\">\n";
        write_fields(out, point_fields);
        out << "</PointData>\n";
    }
    if (!cell_fields.empty()) {
        out << "<CellData Scalars=\"" << cell_fields.front().first << "\">\n";
        write_fields(out, cell_fields);
        out << "</CellData>\n";
    }
    out << "<Polys>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const auto& t : triangles) out << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
    out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t k = 0; k < triangles.size(); ++k) out << 3 * (k + 1) << '\n';
    out << "</DataArray>\n</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
    finish_writing(out, path);
}

}  // namespace dipper::meshes
