// A wear surface: the triangle mesh of one machine part with the wear its contacts have done. Wear is
// summed per triangle; the mesh is in the part's own (body) frame, so the map moves with the part.
#pragma once

#include "core/contact_record.h"
#include "core/state_io.h"
#include "meshes/triangle_mesh.h"
#include "wear/laws.h"

#include <cstdint>
#include <string>
#include <vector>

namespace dipper::wear {

/// Volume-conserving smoothing of nodal wear volumes (thesis Paper B §3.4). In each iteration every node
/// hands its wear volume out to itself and to the nodes that share a triangle with it, in proportion to
/// their lumped areas with its own weighted 4: node n keeps 4 a_n / W_n of its volume and gives
/// a_m / W_n to each neighbour m, W_n = 4 a_n + sum of a_m. Every node hands out exactly what it had, so
/// the total is conserved to round-off; a single spike leaves depth 4 V/W_n at the node and V/W_n at each
/// neighbour (the 4:1 weights), on any mesh.
std::vector<double> smooth_node_volumes(const meshes::TriangleMesh& mesh, const std::vector<double>& node_area_m2,
                                        std::vector<double> node_volume_m3, int iterations);

/// Lumped nodal areas: a third of each triangle's area to each of its corners.
std::vector<double> lumped_node_areas_m2(const meshes::TriangleMesh& mesh);

/// Where a point lies on a mesh: the closest triangle, the closest point, and its barycentric weights.
struct SurfacePoint {
    std::size_t triangle = 0;
    Vec3 point_m;
    double distance_m = 0.0;
    double weights[3] = {0.0, 0.0, 0.0};
};
SurfacePoint locate_on_surface(const meshes::TriangleMesh& mesh, const Vec3& point_m);

/// A nodal field at a point, interpolated on the closest triangle. Throws InputError naming `what` if the
/// point is farther than `tolerance_m` from the surface.
double interpolate_node_field(const meshes::TriangleMesh& mesh, const std::vector<double>& node_field,
                              const Vec3& point_m, double tolerance_m, const std::string& what);

class WearSurface {
public:
    /// `surface_id` is the id that contact records of this part carry (a DEM wall id or a rigid body's
    /// surface id); the records' triangle ids index `mesh`.
    WearSurface(std::string name, meshes::TriangleMesh mesh, WearLaw law, std::int32_t surface_id);

    /// Adds the wear of one step: the records of this surface are used, the others ignored. A record whose
    /// triangle id is outside the mesh is an error (the record and the mesh do not belong together).
    void accumulate(const std::vector<ContactRecord>& contacts, double dt_s);
    /// Adds the wear of one contact during a step of dt_s. Does not advance the accumulated time.
    void add_contact(const ContactRecord& contact, double dt_s);
    /// Advances the time over which contact forces are averaged (accumulate() does it itself).
    void add_time(double dt_s) { time_s_ += dt_s; }

    const std::string& name() const { return name_; }
    const meshes::TriangleMesh& mesh() const { return mesh_; }
    const WearLaw& law() const { return law_; }
    std::int32_t surface_id() const { return surface_id_; }
    double accumulated_time_s() const { return time_s_; }

    // ---- per triangle
    const std::vector<double>& triangle_volume_m3() const { return volume_m3_; }
    std::vector<double> triangle_depth_m() const;
    /// Time-mean normal and tangential contact force on each triangle over the accumulated time, N.
    std::vector<double> mean_normal_force_N() const;
    std::vector<double> mean_tangential_force_N() const;
    /// Number of contact-steps and of impacts (first steps of contacts) on each triangle.
    const std::vector<std::uint64_t>& contact_steps() const { return contact_steps_; }
    const std::vector<std::uint64_t>& impacts() const { return impacts_; }
    double total_volume_m3() const;

    // ---- per node
    const std::vector<double>& node_area_m2() const { return node_area_m2_; }
    /// Nodal wear volumes (a third of each triangle's volume to each corner), smoothed `iterations` times.
    std::vector<double> node_volume_m3(int smoothing_iterations) const;
    /// Nodal depth = nodal volume / lumped nodal area, m.
    std::vector<double> node_depth_m(int smoothing_iterations) const;
    /// Depth at a point on the surface (body frame), interpolated from the nodal depths of the closest
    /// triangle. Throws InputError if the point is farther than `tolerance_m` from the surface.
    double depth_at_m(const Vec3& point_m, int smoothing_iterations, double tolerance_m, const std::string& what) const;

    /// Checkpoints: the accumulated time and the per-triangle sums. read_state refuses a state of a
    /// mesh with another number of triangles.
    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

    /// The same surface with every wear volume and the law's constant multiplied by `factor`: what a
    /// re-run with the scaled constant gives, for laws linear in their constant.
    WearSurface scaled(double factor) const;

private:
    /// The checkpoint's fields, listed once for writing and reading (core/state_io.h).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& s);
    std::string name_;
    meshes::TriangleMesh mesh_;
    WearLaw law_;
    std::int32_t surface_id_;
    double time_s_ = 0.0;
    std::vector<double> volume_m3_;
    std::vector<double> normal_impulse_N_s_, tangential_impulse_N_s_;
    std::vector<std::uint64_t> contact_steps_, impacts_;
    std::vector<double> node_area_m2_;
};

}  // namespace dipper::wear
