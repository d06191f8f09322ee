#include "wear/wear_surface.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dipper::wear {

std::vector<double> lumped_node_areas_m2(const meshes::TriangleMesh& mesh)
{
    std::vector<double> area(mesh.vertex_count(), 0.0);
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t)
        for (const std::uint32_t v : mesh.triangles()[t]) area[v] += mesh.triangle_area_m2(t) / 3.0;
    return area;
}

std::vector<double> smooth_node_volumes(const meshes::TriangleMesh& mesh, const std::vector<double>& node_area_m2,
                                        std::vector<double> volume, int iterations)
{
    if (iterations < 0) throw InputError(concat("wear smoothing iterations must be >= 0; got ", iterations));
    if (iterations == 0) return volume;
    const std::size_t n = mesh.vertex_count();
    DIPPER_ASSERT(volume.size() == n && node_area_m2.size() == n, "one value per node");

    // the nodes sharing a triangle with each node, each once, sorted (a deterministic order of summation)
    std::vector<std::vector<std::uint32_t>> neighbours(n);
    for (const auto& tri : mesh.triangles())
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                if (a != b) neighbours[tri[static_cast<std::size_t>(a)]].push_back(tri[static_cast<std::size_t>(b)]);
    std::vector<double> total_weight(n);
    for (std::size_t v = 0; v < n; ++v) {
        auto& list = neighbours[v];
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end()), list.end());
        double w = 4.0 * node_area_m2[v];
        for (const std::uint32_t m : list) w += node_area_m2[m];
        total_weight[v] = w;
    }

    std::vector<double> next(n);
    for (int it = 0; it < iterations; ++it) {
        std::fill(next.begin(), next.end(), 0.0);
        for (std::size_t v = 0; v < n; ++v) {
            if (volume[v] == 0.0 || total_weight[v] == 0.0) {
                next[v] += volume[v];  // an unused node keeps what it has (nothing)
                continue;
            }
            const double per_area = volume[v] / total_weight[v];
            double handed_out = 0.0;
            for (const std::uint32_t m : neighbours[v]) {
                const double share = per_area * node_area_m2[m];
                next[m] += share;
                handed_out += share;
            }
            next[v] += volume[v] - handed_out;  // the node's own 4 a_n share, exactly the remainder
        }
        volume.swap(next);
    }
    return volume;
}

SurfacePoint locate_on_surface(const meshes::TriangleMesh& mesh, const Vec3& point_m)
{
    SurfacePoint best;
    double best_d2 = std::numeric_limits<double>::infinity();
    const auto& x = mesh.vertices_m();
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const auto& tri = mesh.triangles()[t];
        const meshes::ClosestPoint c = meshes::closest_point_on_triangle(point_m, x[tri[0]], x[tri[1]], x[tri[2]]);
        if (c.distance_squared < best_d2) {
            best_d2 = c.distance_squared;
            best.triangle = t;
            best.point_m = c.point;
        }
    }
    best.distance_m = std::sqrt(best_d2);
    // barycentric weights of the closest point, from the sub-triangle areas
    const auto& tri = mesh.triangles()[best.triangle];
    const Vec3 a = x[tri[0]], b = x[tri[1]], c = x[tri[2]];
    const Vec3 n = cross(b - a, c - a);
    const double nn = dot(n, n);
    best.weights[0] = dot(cross(c - b, best.point_m - b), n) / nn;
    best.weights[1] = dot(cross(a - c, best.point_m - c), n) / nn;
    best.weights[2] = 1.0 - best.weights[0] - best.weights[1];
    return best;
}

double interpolate_node_field(const meshes::TriangleMesh& mesh, const std::vector<double>& node_field,
                              const Vec3& point_m, double tolerance_m, const std::string& what)
{
    DIPPER_ASSERT(node_field.size() == mesh.vertex_count(), "one value per node");
    const SurfacePoint s = locate_on_surface(mesh, point_m);
    if (!(s.distance_m <= tolerance_m))
        throw InputError(concat(what, ": point (", point_m.x, ", ", point_m.y, ", ", point_m.z, ") m is ", s.distance_m,
                                " m from the surface; expected within ", tolerance_m, " m (is it in the part's frame?)"));
    const auto& tri = mesh.triangles()[s.triangle];
    return s.weights[0] * node_field[tri[0]] + s.weights[1] * node_field[tri[1]] + s.weights[2] * node_field[tri[2]];
}

WearSurface::WearSurface(std::string name, meshes::TriangleMesh mesh, WearLaw law, std::int32_t surface_id)
    : name_(std::move(name)), mesh_(std::move(mesh)), law_(law), surface_id_(surface_id)
{
    if (mesh_.triangle_count() == 0) throw InputError(concat("wear surface '", name_, "': the mesh has no triangles"));
    const std::size_t t = mesh_.triangle_count();
    volume_m3_.assign(t, 0.0);
    normal_impulse_N_s_.assign(t, 0.0);
    tangential_impulse_N_s_.assign(t, 0.0);
    contact_steps_.assign(t, 0);
    impacts_.assign(t, 0);
    node_area_m2_ = lumped_node_areas_m2(mesh_);
}

void WearSurface::add_contact(const ContactRecord& c, double dt_s)
{
    if (c.triangle_id < 0 || static_cast<std::size_t>(c.triangle_id) >= mesh_.triangle_count())
        throw InputError(concat("wear surface '", name_, "': contact record names triangle ", c.triangle_id,
                                "; the mesh has triangles 0..", mesh_.triangle_count() - 1));
    const auto t = static_cast<std::size_t>(c.triangle_id);
    const double v = law_.volume_m3(c, dt_s);
    if (!std::isfinite(v) || v < 0.0)
        throw SimulationError(concat("wear surface '", name_, "': contact on triangle ", t, " gives wear volume ", v,
                                     " m^3 (force ", c.normal_force_N, " N, displacement ",
                                     norm(c.relative_displacement_m), " m)"));
    volume_m3_[t] += v;
    normal_impulse_N_s_[t] += c.normal_force_N * dt_s;
    tangential_impulse_N_s_[t] += norm(c.tangential_force_N) * dt_s;
    ++contact_steps_[t];
    if (c.first_step) ++impacts_[t];
}

void WearSurface::accumulate(const std::vector<ContactRecord>& contacts, double dt_s)
{
    for (const ContactRecord& c : contacts)
        if (c.surface_id == surface_id_) add_contact(c, dt_s);
    time_s_ += dt_s;
}

std::vector<double> WearSurface::triangle_depth_m() const
{
    std::vector<double> depth(volume_m3_.size());
    for (std::size_t t = 0; t < depth.size(); ++t) depth[t] = volume_m3_[t] / mesh_.triangle_area_m2(t);
    return depth;
}

std::vector<double> WearSurface::mean_normal_force_N() const
{
    std::vector<double> f(normal_impulse_N_s_.size(), 0.0);
    if (time_s_ > 0.0)
        for (std::size_t t = 0; t < f.size(); ++t) f[t] = normal_impulse_N_s_[t] / time_s_;
    return f;
}

std::vector<double> WearSurface::mean_tangential_force_N() const
{
    std::vector<double> f(tangential_impulse_N_s_.size(), 0.0);
    if (time_s_ > 0.0)
        for (std::size_t t = 0; t < f.size(); ++t) f[t] = tangential_impulse_N_s_[t] / time_s_;
    return f;
}

double WearSurface::total_volume_m3() const
{
    double sum = 0.0;
    for (const double v : volume_m3_) sum += v;
    return sum;
}

std::vector<double> WearSurface::node_volume_m3(int smoothing_iterations) const
{
    std::vector<double> node(mesh_.vertex_count(), 0.0);
    for (std::size_t t = 0; t < mesh_.triangle_count(); ++t)
        for (const std::uint32_t v : mesh_.triangles()[t]) node[v] += volume_m3_[t] / 3.0;
    return smooth_node_volumes(mesh_, node_area_m2_, std::move(node), smoothing_iterations);
}

std::vector<double> WearSurface::node_depth_m(int smoothing_iterations) const
{
    std::vector<double> depth = node_volume_m3(smoothing_iterations);
    for (std::size_t v = 0; v < depth.size(); ++v) depth[v] = node_area_m2_[v] > 0.0 ? depth[v] / node_area_m2_[v] : 0.0;
    return depth;
}

double WearSurface::depth_at_m(const Vec3& point_m, int smoothing_iterations, double tolerance_m,
                               const std::string& what) const
{
    return interpolate_node_field(mesh_, node_depth_m(smoothing_iterations), point_m, tolerance_m,
                                  concat(what, " on wear surface '", name_, "'"));
}

WearSurface WearSurface::scaled(double factor) const
{
    WearSurface s = *this;
    s.law_ = law_.scaled(factor);
    for (double& v : s.volume_m3_) v *= factor;
    return s;
}

template <class IO, class Self>
void WearSurface::state_fields(IO& io, Self& s)
{
    io.tag("wear surface");
    std::string name = s.name_;
    io(name);
    if constexpr (IO::reading)
        if (name != s.name_) io.fail(concat("wear surface '", name, "' where the run has '", s.name_, "'"));
    io(s.time_s_, s.volume_m3_, s.normal_impulse_N_s_, s.tangential_impulse_N_s_, s.contact_steps_, s.impacts_);
}

void WearSurface::write_state(StateWriter& out) const { state_fields(out, *this); }

void WearSurface::read_state(StateReader& in)
{
    state_fields(in, *this);
    const std::size_t n = mesh_.triangle_count();
    if (volume_m3_.size() != n || normal_impulse_N_s_.size() != n || tangential_impulse_N_s_.size() != n ||
        contact_steps_.size() != n || impacts_.size() != n)
        in.fail(concat("wear surface '", name_, "': per-triangle sums of another mesh (", volume_m3_.size(), " triangles, the part has ", n, ")"));
}

}  // namespace dipper::wear
