// The walls within reach of each particle, found at each neighbour rebuild: every plane and mesh triangle that
// lies within r + skin of a particle's centre, in particle order (what a checkpoint keeps), and split from them
// the planes and open meshes' triangles, with the triangles copied beside them (what the wall contacts read at
// every step). The candidates on convex bodies become ConvexPairs.
#pragma once

#include "core/state_io.h"
#include "dem/convex_pairs.h"
#include "dem/particle_store.h"
#include "dem/sphere_pairs.h"
#include "dem/wall_contact.h"
#include "dem/walls.h"
#include "meshes/triangle_mesh.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace dipper::dem {

/// The world's walls as the search reads them.
struct WallSet {
    const std::vector<PlaneWall>& planes;
    const std::vector<double>& plane_offset_m;      ///< point . normal of each plane
    const std::vector<std::int32_t>& plane_wall_id;
    const std::vector<MeshWall>& meshes;
    const std::vector<std::int32_t>& mesh_wall_id;
    const std::vector<std::uint8_t>& wall_removed;  ///< per wall id
};

/// A wall feature a sphere touches, before the one-contact-per-feature filter.
struct WallHit {
    std::int32_t wall, triangle;
    meshes::Feature feature;
    std::int32_t local_index;  ///< which edge or vertex of the triangle (meshes::ClosestPoint)
    std::uint32_t candidate;   ///< the triangle's place in the particle's lists (kPlaneCandidate for a plane)
    Vec3 point, normal;
    double overlap;
    bool keep;  ///< false for a hit that is not a contact of its own (the same point, or not a local minimum)
};

/// What a build may take over from the one before it. A particle that sits bit for bit where it sat then, with the
/// same radius and skin, among meshes none of which has been posed since, has the same candidates (the search is
/// exact and does not depend on the grid): a frozen bed's spheres among frozen rocks (coupling::DynamicDomain).
struct CandidateCarry {
    const std::vector<std::uint32_t>& old_index;     ///< by particle, in the new order: its index at the last build
    const std::vector<std::uint8_t>& unmoved;        ///< by particle, in the new order: position and radius unchanged
    const std::vector<std::uint8_t>& mesh_unchanged; ///< by mesh: not posed since the last build (meshes not added)
};

class WallCandidates {
public:
    /// Finds every particle's candidates in the cells of `grid` (the particles sorted by cell) and splits them
    /// (split). A mesh's triangles are binned by their inflated bounding boxes, a convex body as a whole by its
    /// bounding sphere. With `carry`, a particle it marks unmoved keeps its last candidates when every mesh binned
    /// into its cell and every mesh among them is unchanged (the same candidates as a search would find).
    void build(const CellGrid& grid, const ParticleStore& particles, double skin_m, const WallSet& walls, ConvexPairs& convex,
               int threads, const CandidateCarry* carry = nullptr);
    /// Particles whose candidates the last build took over rather than searched.
    std::size_t carried() const { return carried_; }
    /// Makes the pairs of spheres and convex bodies, and the per-particle lists of planes and open meshes'
    /// triangles, from the candidates.
    void split(const std::vector<MeshWall>& meshes, ConvexPairs& convex, int threads);

    /// The planes and open meshes' triangles of particle i: [first(i), last(i)), planes first.
    std::uint32_t first(std::size_t i) const { return wall_start_[i]; }
    std::uint32_t last(std::size_t i) const { return wall_start_[i + 1]; }
    const MeshCandidate& at(std::uint32_t k) const { return wall_[k]; }
    const PackedTriangle& triangle(std::uint32_t k) const { return triangles_[k]; }  ///< body frame (planes: unused)
    const TriangleIds& ids(std::uint32_t k) const { return ids_[k]; }
    /// The particles with at least one such candidate, in order.
    const std::vector<std::uint32_t>& particles() const { return particles_; }
    /// Whether the lists are for n particles (not before the first build, nor while particles wait for a rebuild).
    bool lists_for(std::size_t n) const { return wall_start_.size() == n + 1; }

    /// The walls among particle i's candidates that a sphere of radius r at x touches (planes, then mesh
    /// triangles), each hit marked `keep` when it is a contact of its own: one contact per point of the surface
    /// that is locally closest to the centre.
    void touching(std::uint32_t i, const Vec3& x, double r, const WallSet& walls, std::vector<WallHit>& hits) const;

    void write_state(StateWriter& out) const;
    /// Reads what write_state wrote and checks its indices against the walls (a corrupt file must not crash a run);
    /// call split afterwards.
    void read_state(StateReader& in, std::size_t planes, const std::vector<MeshWall>& meshes);
    /// The indices' check of read_state: the lists are for `n` particles, or at most n while `more_may_come`.
    bool sized_for(std::size_t n, bool more_may_come) const
    {
        return more_may_come ? start_.size() <= n + 1 : start_.size() == n + 1;
    }

private:
    std::vector<std::uint32_t> start_;   ///< every candidate of particle i in [start_[i], start_[i + 1])
    std::vector<MeshCandidate> all_;
    std::vector<std::uint32_t> wall_start_;
    std::vector<MeshCandidate> wall_;
    std::vector<std::uint32_t> particles_;
    std::vector<PackedTriangle> triangles_;  ///< beside wall_
    std::vector<TriangleIds> ids_;           ///< beside wall_, read only for touched triangles
    /// The search's large working lists, kept for their capacity: fresh ones of some megabytes would be mapped
    /// and faulted in page by page at every rebuild (measured: a third of the rebuild).
    std::vector<std::pair<std::uint32_t, MeshCandidate>> entries_;  ///< (cell, triangle)
    std::vector<MeshCandidate> bucket_;                             ///< triangles by cell
    std::vector<std::vector<MeshCandidate>> per_block_;
    std::vector<std::uint32_t> old_start_;  ///< the last build's start_ and all_ while a build takes from them
    std::vector<MeshCandidate> old_all_;
    std::size_t carried_ = 0;
};

}  // namespace dipper::dem
