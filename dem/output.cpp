#include "dem/output.h"

#include "core/errors.h"
#include "core/files.h"
#include "meshes/vtk_surface.h"
#include "meshes/vtk_xml.h"

#include <cstdio>
#include <filesystem>
#include <iomanip>

namespace dipper::dem {

namespace {

std::string numbered(const std::string& stem, int index)
{
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "_%06d.vtp", index);
    return stem + buffer;
}

}  // namespace

void write_particles_vtp(const World& world, const std::string& path)
{
    const ParticleStore& p = world.particles();
    const std::size_t n = p.size();
    static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is three packed doubles");
    const auto vec3 = [](const std::vector<Vec3>& v) { return v.empty() ? nullptr : &v[0].x; };
    meshes::VtkAppendedArrays arrays;
    std::string body = concat("<PolyData>\n<Piece NumberOfPoints=\"", n, "\" NumberOfVerts=\"", n,
                              "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n<Points>\n");
    body += arrays.add("position_m", vec3(p.position_m), 3 * n, 3);
    body += "</Points>\n<PointData Scalars=\"radius_m\" Vectors=\"velocity_m_per_s\">\n";
    body += arrays.add("radius_m", p.radius_m.data(), n);
    body += arrays.add("velocity_m_per_s", vec3(p.velocity_m_per_s), 3 * n, 3);
    body += arrays.add("angular_velocity_rad_per_s", vec3(p.angular_velocity_rad_per_s), 3 * n, 3);
    body += arrays.add("material", p.material.data(), n);
    body += arrays.add("id", p.id.data(), n);
    std::vector<std::int64_t> connectivity(n), offsets(n);
    for (std::size_t i = 0; i < n; ++i) {
        connectivity[i] = static_cast<std::int64_t>(i);
        offsets[i] = static_cast<std::int64_t>(i + 1);
    }
    body += "</PointData>\n<Verts>\n" + arrays.add("connectivity", connectivity.data(), n) + arrays.add("offsets", offsets.data(), n) +
            "</Verts>\n</Piece>\n</PolyData>\n";
    arrays.write(path, "PolyData", body);
}

void write_mesh_vtp(const MeshWall& wall, const std::string& path)
{
    meshes::write_surface_vtp(path, wall.vertices_world_m(), wall.mesh().triangles());
}

void PvdCollection::add(double time_s, const std::string& file)
{
    entries_.emplace_back(time_s, file);
    rewrite();
}

void PvdCollection::restore(std::vector<std::pair<double, std::string>> entries)
{
    entries_ = std::move(entries);
    rewrite();
}

void PvdCollection::rewrite() const
{
    const std::string tmp = path_ + ".tmp";
    {
        std::ofstream out = open_for_writing(tmp);
        out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n";
        for (const auto& [t, f] : entries_) out << "<DataSet timestep=\"" << t << "\" part=\"0\" file=\"" << f << "\"/>\n";
        out << "</Collection>\n</VTKFile>\n";
        finish_writing(out, tmp);
    }
    std::filesystem::rename(tmp, path_);  // atomic: a reader never sees half a collection
}

ParaViewSeries::ParaViewSeries(std::string directory)
    : dir_(std::move(directory)), particles_(dir_ + "/particles.pvd")
{
    std::error_code error;
    std::filesystem::create_directories(dir_, error);
    if (error) throw InputError(concat("cannot create output folder '", dir_, "': ", error.message()));
}

void ParaViewSeries::write(const World& world)
{
    const std::string file = numbered("particles", index_);
    write_particles_vtp(world, dir_ + "/" + file);
    particles_.add(world.time_s(), file);
    int mesh = 0;
    for (int w = 0; w < static_cast<int>(world.wall_count()); ++w) {
        if (!world.is_mesh(w)) continue;
        if (static_cast<std::size_t>(mesh) >= meshes_.size())
            meshes_.emplace_back(dir_ + "/wall_" + world.wall_name(w) + ".pvd");
        const std::string mesh_file = numbered("wall_" + world.wall_name(w), index_);
        write_mesh_vtp(world.mesh_wall(w), dir_ + "/" + mesh_file);
        meshes_[static_cast<std::size_t>(mesh)].add(world.time_s(), mesh_file);
        ++mesh;
    }
    ++index_;
}

WorldCsv::WorldCsv(const std::string& path, const World& world) : out_(open_for_writing(path)), path_(path)
{
    out_ << "time_s,kinetic_energy_J,particles,pair_contacts,wall_contacts,max_overlap_ratio";
    for (int w = 0; w < static_cast<int>(world.wall_count()); ++w)
        for (const char* axis : {"x", "y", "z"}) out_ << ",force_" << world.wall_name(w) << "_" << axis << "_N";
    out_ << '\n';
}

void WorldCsv::write_row(const World& world)
{
    out_ << world.time_s() << ',' << world.kinetic_energy_J() << ',' << world.particles().size() << ','
         << world.pair_contact_count() << ',' << world.wall_contact_count() << ',' << world.max_overlap_ratio();
    for (int w = 0; w < static_cast<int>(world.wall_count()); ++w) {
        const Vec3 f = world.wall_force_N(w);
        out_ << ',' << f.x << ',' << f.y << ',' << f.z;
    }
    out_ << '\n';
    finish_writing(out_, path_);
}

}  // namespace dipper::dem
