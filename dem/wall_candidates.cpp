#include "dem/wall_candidates.h"

#include "core/errors.h"
#include "meshes/triangle_mesh.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dipper::dem {

void WallCandidates::build(const CellGrid& grid, const ParticleStore& particles, double skin_m, const WallSet& walls,
                           ConvexPairs& convex, int threads, const CandidateCarry* carry)
{
    carried_ = 0;
    if (carry) {
        old_start_.swap(start_);
        old_all_.swap(all_);
    }
    const Vec3& lo = grid.lo;
    const double cell = grid.cell;
    const int* dims = grid.dims;
    const std::vector<std::uint32_t>& cell_start = grid.cell_start;
    const std::size_t n = particles.size();
    start_.assign(n + 1, 0);
    all_.clear();
    triangles_.clear();
    ids_.clear();
    if ((walls.planes.empty() && walls.meshes.empty()) || n == 0) {
        split(walls.meshes, convex, threads);
        return;
    }
    double r_max = 0.0;
    for (double r : particles.radius_m) r_max = std::max(r_max, r);
    const double reach = r_max + skin_m;

    // Triangles into every cell their inflated bounding box overlaps; a convex body (a rock) as a whole, by its
    // bounding sphere, into every cell that sphere's inflated box overlaps, for its particles to test all its
    // faces (a triangle within reach of a centre is within reach of the sphere, so the candidates are the same,
    // in the same order). The thesis' pile then puts its 20,188 rocks into the cells on one thread instead of
    // their 645,464 triangles, and needs none of their vertices in the world frame.
    constexpr std::uint32_t kWholeMesh = kPlaneCandidate - 1;
    const std::size_t cell_count = cell_start.size() - 1;
    // the large lists (entries_, bucket_, per_block_) are kept from rebuild to rebuild for their capacity
    std::vector<std::uint32_t> bucket_count(cell_count + 1, 0);
    auto& entries = entries_;
    entries.clear();
    // the cells of the box [vmin - reach, vmax + reach] that hold a particle
    auto bin = [&](const Vec3& vmin, const Vec3& vmax, MeshCandidate what) {
        int c0[3], c1[3];
        for (int a = 0; a < 3; ++a) {
            const double f0 = std::floor((vmin[a] - reach - lo[a]) / cell), f1 = std::floor((vmax[a] + reach - lo[a]) / cell);
            if (f1 < 0.0 || f0 > dims[a] - 1) return;
            c0[a] = static_cast<int>(std::max(f0, 0.0));
            c1[a] = static_cast<int>(std::min(f1, static_cast<double>(dims[a] - 1)));
        }
        for (int z = c0[2]; z <= c1[2]; ++z)
            for (int y = c0[1]; y <= c1[1]; ++y)
                for (int x = c0[0]; x <= c1[0]; ++x) {
                    const auto c = static_cast<std::uint32_t>((static_cast<std::size_t>(z) * dims[1] + y) * dims[0] + x);
                    if (cell_start[c] == cell_start[c + 1]) continue;  // no particle there
                    entries.push_back({c, what});
                }
    };
    for (std::size_t m = 0; m < walls.meshes.size(); ++m) {
        const MeshWall& mw = walls.meshes[m];
        if (walls.wall_removed[static_cast<std::size_t>(walls.mesh_wall_id[m])]) continue;
        if (mw.convex()) {
            const Vec3 centre = mw.bound_centre_world_m();
            const double radius = mw.bound_radius_m();
            bin(centre - Vec3{radius, radius, radius}, centre + Vec3{radius, radius, radius},
                {static_cast<std::uint32_t>(m), kWholeMesh});
            continue;
        }
        const auto& verts = mw.vertices_world_m();
        const auto& tris = mw.mesh().triangles();
        for (std::size_t t = 0; t < tris.size(); ++t) {
            const Vec3& a = verts[tris[t][0]];
            const Vec3& b = verts[tris[t][1]];
            const Vec3& c = verts[tris[t][2]];
            bin({std::min({a.x, b.x, c.x}), std::min({a.y, b.y, c.y}), std::min({a.z, b.z, c.z})},
                {std::max({a.x, b.x, c.x}), std::max({a.y, b.y, c.y}), std::max({a.z, b.z, c.z})},
                {static_cast<std::uint32_t>(m), static_cast<std::uint32_t>(t)});
        }
    }
    for (const auto& e : entries) ++bucket_count[e.first + 1];
    std::partial_sum(bucket_count.begin(), bucket_count.end(), bucket_count.begin());
    auto& bucket = bucket_;
    bucket.resize(entries.size());
    {
        std::vector<std::uint32_t> fill(bucket_count.begin(), bucket_count.end() - 1);
        for (const auto& e : entries) bucket[fill[e.first]++] = e.second;
    }

    // Each particle keeps the planes, then the triangles of its own cell, that lie within r + skin. The particles
    // go in blocks handed out as threads come free, joined in block order: the cells of a bed's bottom or of a
    // pile's rocks hold most of the candidates, so equal halves of the particles are far from equal work (in the
    // thesis' settling column the first of two threads took nearly twice as long as the second).
    auto& per_block = per_block_;
    const int blocks = threads == 1 ? 1 : 16 * threads;
    per_block.resize(static_cast<std::size_t>(blocks));
    std::vector<std::uint32_t> counts(n, 0);
    const bool may_carry = carry && old_start_.size() == carry->unmoved.size() + 1 && carry->unmoved.size() == n;
    std::size_t carried = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : carried)
    for (int b = 0; b < blocks; ++b) {
        std::size_t begin, end;
        thread_block(n, b, blocks, begin, end);
        std::vector<MeshCandidate> out = std::move(per_block[static_cast<std::size_t>(b)]);  // a local, moved back at
        out.clear();                                                                         // the end (the headers share a cache line)
        for (std::size_t i = begin; i < end; ++i) {
            const Vec3 p = particles.position_m[i];
            int c[3];
            for (int a = 0; a < 3; ++a) c[a] = std::clamp(static_cast<int>((p[a] - lo[a]) / cell), 0, dims[a] - 1);
            const auto cid = static_cast<std::size_t>((static_cast<std::size_t>(c[2]) * dims[1] + c[1]) * dims[0] + c[0]);
            if (may_carry && carry->unmoved[i]) {
                // Every mesh that may lie within reach now is binned into this cell, and every one within reach
                // then is among the old candidates: none of them posed since, the search would find the same list
                const std::uint32_t o = carry->old_index[i];
                bool same = true;
                for (std::uint32_t k = bucket_count[cid]; k < bucket_count[cid + 1] && same; ++k)
                    same = carry->mesh_unchanged[bucket[k].mesh] != 0;
                for (std::uint32_t k = old_start_[o]; k < old_start_[o + 1] && same; ++k)
                    same = old_all_[k].triangle == kPlaneCandidate || carry->mesh_unchanged[old_all_[k].mesh] != 0;
                if (same) {
                    out.insert(out.end(), old_all_.begin() + old_start_[o], old_all_.begin() + old_start_[o + 1]);
                    counts[i] = old_start_[o + 1] - old_start_[o];
                    ++carried;
                    continue;
                }
            }
            const double range = particles.radius_m[i] + skin_m;
            for (std::size_t q = 0; q < walls.planes.size(); ++q)
                if (dot(p, walls.planes[q].normal) - walls.plane_offset_m[q] < range && !walls.wall_removed[static_cast<std::size_t>(walls.plane_wall_id[q])]) {
                    out.push_back({static_cast<std::uint32_t>(q), kPlaneCandidate});
                    ++counts[i];
                }
            std::uint32_t body_mesh = kPlaneCandidate;
            Vec3 pb;
            double behind = range;
            for (std::uint32_t k = bucket_count[cid]; k < bucket_count[cid + 1]; ++k) {
                const MeshCandidate mc = bucket[k];
                if (mc.mesh != body_mesh) {
                    body_mesh = mc.mesh;
                    pb = walls.meshes[mc.mesh].to_body(p);
                    // A convex body's face that the centre lies more than the skin behind cannot come to face
                    // it before the next rebuild, and only faces it faces can hold its contact (find_wall_contacts)
                    behind = walls.meshes[mc.mesh].convex() ? skin_m : range;
                }
                const MeshWall& mw = walls.meshes[mc.mesh];
                if (mc.triangle == kWholeMesh) {
                    // no face of a body whose bounding sphere lies beyond reach (with a margin far above round-off)
                    const double beyond = (mw.bound_radius_m() + range) * (1.0 + 1e-9);
                    if (norm_squared(pb - mw.bound_centre_body_m()) > beyond * beyond) continue;
                }
                const std::uint32_t first = mc.triangle == kWholeMesh ? 0 : mc.triangle;
                const std::uint32_t last = mc.triangle == kWholeMesh ? static_cast<std::uint32_t>(mw.mesh().triangle_count()) : mc.triangle + 1;
                for (std::uint32_t tri = first; tri < last; ++tri) {
                    const PackedTriangle& pt = mw.packed_body(tri);
                    const double plane_distance = dot(pb - pt.a, pt.normal);
                    if (plane_distance >= range || plane_distance <= -behind) continue;
                    if (meshes::closest_point_on_triangle(pb, pt.a, pt.b, pt.c).distance_squared < range * range) {
                        out.push_back({mc.mesh, tri});
                        ++counts[i];
                    }
                }
            }
        }
        per_block[static_cast<std::size_t>(b)] = std::move(out);
    }
    carried_ = carried;
    for (std::size_t i = 0; i < n; ++i) start_[i + 1] = start_[i] + counts[i];
    for (const auto& v : per_block) all_.insert(all_.end(), v.begin(), v.end());
    split(walls.meshes, convex, threads);
}



void WallCandidates::split(const std::vector<MeshWall>& meshes, ConvexPairs& convex, int threads)
{
    // Planes and open meshes stay with their particle; the triangles of a convex body become one pair of the sphere
    // and that body (ConvexPairs)
    const std::size_t n = start_.empty() ? 0 : start_.size() - 1;
    convex.build(start_, all_, meshes, threads);

    // the other candidates, with their triangles beside them
    wall_start_.assign(n + 1, 0);
    wall_.clear();
    for (std::size_t i = 0; i < n; ++i) {
        for (std::uint32_t k = start_[i]; k < start_[i + 1]; ++k) {
            const MeshCandidate mc = all_[k];
            if (mc.triangle == kPlaneCandidate || !meshes[mc.mesh].convex()) wall_.push_back(mc);
        }
        wall_start_[i + 1] = static_cast<std::uint32_t>(wall_.size());
    }
    particles_.clear();
    for (std::size_t i = 0; i < n; ++i)
        if (wall_start_[i + 1] > wall_start_[i]) particles_.push_back(static_cast<std::uint32_t>(i));
    triangles_.resize(wall_.size());
    ids_.resize(wall_.size());
    for (std::size_t k = 0; k < wall_.size(); ++k)
        if (wall_[k].triangle != kPlaneCandidate) {
            triangles_[k] = meshes[wall_[k].mesh].packed_body(wall_[k].triangle);
            ids_[k] = meshes[wall_[k].mesh].triangle_ids(wall_[k].triangle);
        }
}


void WallCandidates::touching(std::uint32_t i, const Vec3& x, double r, const WallSet& walls, std::vector<WallHit>& hits) const
{
    hits.clear();
    auto push_hit = [&](const WallHit& h) { hits.push_back(h); };

    const std::uint32_t first = wall_start_[i], last = wall_start_[i + 1];
    if (first == last) return;  // most particles: no plane or open mesh within reach since the last rebuild

    // analytic planes (listed first)
    std::uint32_t k = first;
    for (; k < last && wall_[k].triangle == kPlaneCandidate; ++k) {
        const std::size_t q = wall_[k].mesh;
        const PlaneWall& pl = walls.planes[q];
        const double dist = dot(x, pl.normal) - walls.plane_offset_m[q];
        if (dist < r) push_hit({walls.plane_wall_id[q], -1, meshes::Feature::Face, 0, kPlaneCandidate, x - pl.normal * dist, pl.normal, r - dist, true});
    }

    // mesh triangles, each classified by the feature (face, edge, vertex) that holds the closest point; each
    // mesh's triangles are tested in its body frame, with the sphere's centre moved there once per mesh
    const int first_mesh_hit = static_cast<int>(hits.size());
    std::uint32_t body_mesh = kPlaneCandidate;
    const MeshWall* mw = nullptr;
    Vec3 xb;
    for (; k < last; ++k) {
        const MeshCandidate mc = wall_[k];
        if (mc.mesh != body_mesh) {
            body_mesh = mc.mesh;
            mw = &walls.meshes[mc.mesh];
            xb = mw->to_body(x);
        }
        const PackedTriangle& pt = triangles_[k];
        // a triangle whose plane is r or more away cannot be touched: one dot product spares the closest point
        const double plane_distance = dot(xb - pt.a, pt.normal);
        if (plane_distance >= r || plane_distance <= -r) continue;
        const meshes::ClosestPoint cp = meshes::closest_point_on_triangle(xb, pt.a, pt.b, pt.c);
        if (cp.distance_squared >= r * r) continue;
        const double dist = std::sqrt(cp.distance_squared);
        const Vec3 normal = mw->rotation() * (dist > 1e-12 * r ? (xb - cp.point) * (1.0 / dist) : pt.normal);
        push_hit({walls.mesh_wall_id[mc.mesh], static_cast<std::int32_t>(mc.triangle), cp.feature, cp.local_index, k,
                  mw->to_world(cp.point), normal, r - dist, true});
    }

    // One contact per point of the surface that is locally closest to the centre:
    // - hits at the same point (closer than 1e-9 r) are one contact, however the triangles there classify it: a
    //   feature shared by several triangles, or a centre whose projection lies within round-off of an edge or
    //   vertex (a turned mesh, a sphere placed over a node), which can fall inside one triangle and on the border
    //   of the next. The first hit there stays (its own decision is final, taken over all the hits);
    // - a face hit counts;
    // - an edge or vertex hit counts only if every triangle that shares that edge or vertex has its closest
    //   point there too. A triangle's closest point is unique, so one elsewhere on a triangle that holds this
    //   point is strictly closer, and this point is not a local minimum (however small the difference in
    //   overlap: a centre 1 um beside an edge of a flat plate). Every triangle that holds the point lies within
    //   r, so it is among the hits, and the check over the hits is exact.
    // A lone mesh hit has nothing to be compared with (the common case: one face of a rock). The ids of the
    // touched features are looked up only here.
    const int hit_count = static_cast<int>(hits.size());
    auto feature_id = [&](const WallHit& h) {
        const TriangleIds& ids = ids_[h.candidate];
        const auto local = static_cast<std::size_t>(h.local_index);
        return h.feature == meshes::Feature::Edge ? ids.edges[local] : ids.vertices[local];
    };
    const double same_point2 = 1e-18 * r * r;
    for (int a = first_mesh_hit; a < hit_count && hit_count - first_mesh_hit > 1; ++a) {
        WallHit& h = hits[static_cast<std::size_t>(a)];
        for (int b = first_mesh_hit; b < a && h.keep; ++b) {
            const WallHit& o = hits[static_cast<std::size_t>(b)];
            if (o.keep && o.wall == h.wall && norm_squared(o.point - h.point) < same_point2) h.keep = false;
        }
        if (!h.keep || h.feature == meshes::Feature::Face) continue;
        const std::uint32_t id = feature_id(h);
        for (int b = first_mesh_hit; b < hit_count && h.keep; ++b) {
            const WallHit& o = hits[static_cast<std::size_t>(b)];
            if (b == a || o.wall != h.wall || norm_squared(o.point - h.point) < same_point2) continue;
            const TriangleIds& other = ids_[o.candidate];
            const bool shares = h.feature == meshes::Feature::Edge
                                    ? (other.edges[0] == id || other.edges[1] == id || other.edges[2] == id)
                                    : (other.vertices[0] == id || other.vertices[1] == id || other.vertices[2] == id);
            if (shares) h.keep = false;
        }
    }
}

void WallCandidates::write_state(StateWriter& out) const { out(start_, all_); }

void WallCandidates::read_state(StateReader& in, std::size_t planes, const std::vector<MeshWall>& meshes)
{
    in(start_, all_);
    carried_ = 0;
    if (!start_.empty() && start_.back() != all_.size()) in.fail("wall candidate index mismatch");
    if (!std::is_sorted(start_.begin(), start_.end())) in.fail("a wall contact or candidate index that does not ascend");
    for (const MeshCandidate& c : all_) {
        if (c.triangle == kPlaneCandidate ? c.mesh >= planes : (c.mesh >= meshes.size() || c.triangle >= meshes[c.mesh].mesh().triangle_count()))
            in.fail("a wall candidate out of range");
    }
}

}  // namespace dipper::dem
