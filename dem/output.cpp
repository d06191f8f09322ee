#include "dem/output.h"

#include "core/errors.h"
#include "core/files.h"
#include "meshes/vtk_surface.h"

#include <cstdio>
#include <filesystem>
#include <iomanip>

namespace dipper::dem {

namespace {

void write_vec3_array(std::ostream& out, const char* name, const std::vector<Vec3>& values)
{
    out << "<DataArray type=\"Float64\" Name=\"" << name << "\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const Vec3& v : values) out << v.x << ' ' << v.y << ' ' << v.z << '\n';
    out << "</DataArray>\n";
}

template <typename T>
void write_scalar_array(std::ostream& out, const char* type, const char* name, const std::vector<T>& values)
{
    out << "<DataArray type=\"" << type << "\" Name=\"" << name << "\" format=\"ascii\">\n";
    for (const T& v : values) out << +v << '\n';
    out << "</DataArray>\n";
}

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
    std::ofstream out = open_for_writing(path);
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n"
        << "<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n
        << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n<Points>\n";
    write_vec3_array(out, "position_m", p.position_m);
    out << "</Points>\n<PointData Scalars=\"radius_m\" Vectors=\"velocity_m_per_s\">\n";
    write_scalar_array(out, "Float64", "radius_m", p.radius_m);
    write_vec3_array(out, "velocity_m_per_s", p.velocity_m_per_s);
    write_vec3_array(out, "angular_velocity_rad_per_s", p.angular_velocity_rad_per_s);
    write_scalar_array(out, "UInt16", "material", p.material);
    write_scalar_array(out, "UInt32", "id", p.id);
    out << "</PointData>\n<Verts>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << i << '\n';
    out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << i + 1 << '\n';
    out << "</DataArray>\n</Verts>\n</Piece>\n</PolyData>\n</VTKFile>\n";
    finish_writing(out, path);
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
