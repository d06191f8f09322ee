#include "meshes/vtk_surface.h"

#include "core/errors.h"
#include "core/files.h"
#include "meshes/vtk_xml.h"

namespace dipper::meshes {

void write_surface_vtp(const std::string& path, const std::vector<Vec3>& vertices_m,
                       const std::vector<std::array<std::uint32_t, 3>>& triangles,
                       const std::vector<ScalarField>& point_fields, const std::vector<ScalarField>& cell_fields)
{
    for (const auto& f : point_fields)
        DIPPER_ASSERT(f.second.size() == vertices_m.size(), "point field '" + f.first + "' needs one value per vertex");
    for (const auto& f : cell_fields)
        DIPPER_ASSERT(f.second.size() == triangles.size(), "cell field '" + f.first + "' needs one value per triangle");

    VtkAppendedArrays arrays;
    std::string body = concat("<PolyData>\n<Piece NumberOfPoints=\"", vertices_m.size(),
                              "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"", triangles.size(), "\">\n");
    static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is three packed doubles");
    body += "<Points>\n" + arrays.add("position_m", vertices_m.empty() ? nullptr : &vertices_m[0].x, 3 * vertices_m.size(), 3) + "</Points>\n";
    const auto fields = [&](const char* tag, const std::vector<ScalarField>& list) {
        if (list.empty()) return;
        body += concat("<", tag, " Scalars=\"", list.front().first, "\">\n");
        for (const auto& [name, values] : list) body += arrays.add(name, values.data(), values.size());
        body += concat("</", tag, ">\n");
    };
    fields("PointData", point_fields);
    fields("CellData", cell_fields);
    std::vector<std::int64_t> connectivity, offsets;
    connectivity.reserve(3 * triangles.size());
    offsets.reserve(triangles.size());
    for (const auto& t : triangles) {
        connectivity.insert(connectivity.end(), {t[0], t[1], t[2]});
        offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
    }
    body += "<Polys>\n" + arrays.add("connectivity", connectivity.data(), connectivity.size()) +
            arrays.add("offsets", offsets.data(), offsets.size()) + "</Polys>\n</Piece>\n</PolyData>\n";
    arrays.write(path, "PolyData", body);
}

}  // namespace dipper::meshes
