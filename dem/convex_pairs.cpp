#include "dem/convex_pairs.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <omp.h>

namespace dipper::dem {

namespace {

bool has_vertex(const PackedTriangle& t, const Vec3& v) { return t.a == v || t.b == v || t.c == v; }
/// The end points of edge k of a triangle, in the numbering of meshes::ClosestPoint (ab, bc, ca).
std::pair<Vec3, Vec3> edge_ends(const PackedTriangle& t, int k) { return k == 0 ? std::pair{t.a, t.b} : k == 1 ? std::pair{t.b, t.c} : std::pair{t.c, t.a}; }

}  // namespace

void ConvexPairs::build(const std::vector<std::uint32_t>& candidate_start, const std::vector<MeshCandidate>& candidates,
                        const std::vector<MeshWall>& meshes, int threads)
{
    // A convex body's triangles become one pair of the sphere and that body, with the faces copied beside it
    // (the candidates list a particle's triangles mesh by mesh, so a body's faces are one run).
    const std::size_t n = candidate_start.empty() ? 0 : candidate_start.size() - 1;
    pairs_.clear();
    for (std::size_t i = 0; i < n; ++i) {
        for (std::uint32_t k = candidate_start[i]; k < candidate_start[i + 1];) {
            const MeshCandidate mc = candidates[k];
            if (mc.triangle == kPlaneCandidate || !meshes[mc.mesh].convex()) {
                ++k;
                continue;
            }
            std::uint32_t run_end = k + 1;
            while (run_end < candidate_start[i + 1] && candidates[run_end].mesh == mc.mesh) ++run_end;
            pairs_.push_back({mc.mesh, static_cast<std::uint32_t>(i), k, run_end});
            k = run_end;
        }
    }

    // the faces beside the pairs, in pair order, and the face across each edge of each: every pair's on its own
    // (at full size, about 10^5 pairs per rebuild)
    const auto pair_count = static_cast<std::ptrdiff_t>(pairs_.size());
    std::vector<std::uint32_t> first_candidate(pairs_.size());
    std::uint32_t faces = 0;
    for (std::size_t q = 0; q < pairs_.size(); ++q) {
        Pair& p = pairs_[q];
        first_candidate[q] = p.face_begin;
        p.face_end = faces + (p.face_end - p.face_begin);
        p.face_begin = faces;
        faces = p.face_end;
    }
    faces_.resize(faces);
    face_triangle_.resize(faces);
    face_across_.resize(faces);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::ptrdiff_t q = 0; q < pair_count; ++q) {
        const Pair& p = pairs_[static_cast<std::size_t>(q)];
        for (std::uint32_t f = p.face_begin; f < p.face_end; ++f) {
            const std::uint32_t triangle = candidates[first_candidate[static_cast<std::size_t>(q)] + (f - p.face_begin)].triangle;
            faces_[f] = meshes[p.mesh].packed_body(triangle);
            face_triangle_[f] = static_cast<std::int32_t>(triangle);
        }
        for (std::uint32_t f = p.face_begin; f < p.face_end; ++f)
            for (int k = 0; k < 3; ++k) {
                const auto [e0, e1] = edge_ends(faces_[f], k);
                FaceAcross& across = face_across_[f];
                across.face[k] = kNoFace;
                across.edge[k] = 0;
                for (std::uint32_t g = p.face_begin; g < p.face_end; ++g) {
                    const PackedTriangle& gt = faces_[g];
                    if (g == f || !has_vertex(gt, e0) || !has_vertex(gt, e1)) continue;
                    across.face[k] = g;
                    for (int j = 0; j < 3; ++j) {  // the edge of g with both ends (g is not degenerate: one)
                        const auto [g0, g1] = edge_ends(gt, j);
                        if ((g0 == e0 && g1 == e1) || (g0 == e1 && g1 == e0)) across.edge[k] = static_cast<std::uint8_t>(j);
                    }
                    break;
                }
            }
    }
    // a pair's contact is read only while it touches, so the contacts need no clearing
    contacts_.resize(pairs_.size());
    constants_.assign(pairs_.size(), ContactConstants{});
    touching_.assign(pairs_.size(), 0);
    push_.assign(pairs_.size(), Push{});
    spin_N_m_.assign(pairs_.size(), 0.0);
    pair_start_.assign(n + 1, 0);
    for (const Pair& p : pairs_) ++pair_start_[p.particle + 1];
    std::partial_sum(pair_start_.begin(), pair_start_.end(), pair_start_.begin());
    pair_index_.resize(pairs_.size());
    for (std::size_t k = 0; k < pairs_.size(); ++k) pair_index_[pair_start_[pairs_[k].particle]++] = static_cast<std::uint32_t>(k);
    for (std::size_t i = n; i > 0; --i) pair_start_[i] = pair_start_[i - 1];  // the fill moved each start to the next
    if (n > 0) pair_start_[0] = 0;
    live_stale_ = true;
}

void ConvexPairs::update_live(const std::vector<std::uint8_t>& particle_frozen, const std::vector<std::uint8_t>& wall_frozen,
                              const std::vector<std::int32_t>& mesh_wall_id, std::uint64_t frozen_version)
{
    // A frozen sphere against a frozen body keeps its contact as it was and adds nothing: compute passes over such
    // pairs without touching their data (in a bed frozen to 97 % they are most of the pairs, and reading each one's
    // frame and fetching its faces ahead cost a fifth of the step).
    if (!live_stale_ && live_frozen_version_ == frozen_version) return;
    live_.clear();
    frozen_touching_ = 0;
    for (std::size_t k = 0; k < pairs_.size(); ++k) {
        if (wall_frozen[static_cast<std::size_t>(mesh_wall_id[pairs_[k].mesh])] && particle_frozen[pairs_[k].particle])
            frozen_touching_ += touching_[k];
        else
            live_.push_back(static_cast<std::uint32_t>(k));
    }
    live_stale_ = false;
    live_frozen_version_ = frozen_version;
}

void ConvexPairs::append_contacts(std::vector<WallContact>& out) const
{
    for (std::size_t k = 0; k < pairs_.size(); ++k)
        if (touching_[k]) out.push_back(contacts_[k]);
}

void ConvexPairs::start_step(int threads)
{
    // The pairs' contacts are shared out by their cost, not by the particles' blocks: those are equal in
    // particles, and a settling column's lower half holds most of the pairs (in the thesis' calibration pile the
    // first of two threads took six times the second's share). A pair touching at the last step (closest point,
    // law and contact record) weighs as three apart: in that pile, at 1 s, weights of 1 and 4 left the first
    // thread's pass 1.45 and 0.88 times as long as the second's. The shares are found at every step from the
    // pairs' state, so a world read from a checkpoint shares them as the original did, and each thread sums its
    // share's reactions on the bodies in pair order (the totals are then the same for a thread count).
    const std::size_t pairs = pairs_.size();
    pass_start_.assign(static_cast<std::size_t>(threads) + 1, pairs);
    pass_start_[0] = 0;
    if (constants_stale_) {
        std::fill(constants_.begin(), constants_.end(), ContactConstants{});
        constants_stale_ = false;
    }
    if (threads == 1) return;
    constexpr std::size_t kTouchingWeight = 3;
    std::size_t touching = 0;
    for (std::uint8_t t : touching_) touching += t;
    const std::size_t total = pairs + (kTouchingWeight - 1) * touching;
    std::size_t sum = 0, t = 1;
    for (std::size_t k = 0; k < pairs && t < static_cast<std::size_t>(threads); ++k) {
        while (t < static_cast<std::size_t>(threads) && sum >= total * t / static_cast<std::size_t>(threads)) pass_start_[t++] = k;
        sum += touching_[k] ? kTouchingWeight : 1;
    }
}

bool ConvexPairs::edge_point_is_closest(std::uint32_t face_f, const Vec3& xb, meshes::ClosestPoint& best, std::uint32_t& best_face) const
{
    // The closest point q of face F lies on its edge E. In a closed convex mesh E has one more face, G; q is the
    // body's closest point when it is G's too (then x - q lies in the normal cone of E), or when x lies behind
    // G's plane (then it lies in that cone by F's own condition). A point of G's interior, or of E computed from
    // G and closer by round-off, is taken instead, as the search over all faces would take it. Anything else,
    // or G not among the pair's faces, leaves the answer to that search (returns false, `best` as it came).
    const FaceAcross& across = face_across_[face_f];
    const std::uint32_t g = across.face[best.local_index];
    if (g == kNoFace) return false;
    const PackedTriangle& gt = faces_[g];
    const double d = dot(xb - gt.a, gt.normal);
    if (d <= 0.0 || d * d >= best.distance_squared) return true;
    const meshes::ClosestPoint cp = meshes::closest_point_on_triangle(xb, gt.a, gt.b, gt.c);
    const bool on_e = cp.feature == meshes::Feature::Face ||
                      (cp.feature == meshes::Feature::Edge && cp.local_index == across.edge[best.local_index]);
    if (!on_e && cp.distance_squared < best.distance_squared) return false;
    if (cp.distance_squared < best.distance_squared) {
        best = cp;
        best_face = g;
    }
    return true;
}

std::size_t ConvexPairs::compute(std::size_t begin, std::size_t end, const ParticleStore& particles, const std::vector<ConvexFrame>& frames,
                                 const MaterialTable& materials, const std::vector<double>& bulk_modulus_Pa, double max_overlap_ratio,
                                 double dt_s, std::size_t& first_deep, Vec3* __restrict body_force, Vec3* __restrict body_torque)
{
    const RollingResistance rolling = materials.rolling_resistance();
    // A convex body (a rock's hull) lies behind each of its face planes. A centre a radius or more in front of one
    // of the faces within reach touches none of them. A centre in front of some face lies outside, and the hull's
    // closest point then lies on a face it is in front of (the direction to it is in the normal cone there); a
    // face whose interior holds its closest point holds the hull's. So one contact per body at most, from the
    // faces the centre faces. A centre behind every face within reach is inside the body: it is pushed out
    // through the nearest face plane (an overlap beyond the radius, which the overlap limit stops).
    //
    // The pairs stream in order, but each meets its body's frame and its own contact record (read for its
    // history, written when touching) out of the order the hardware prefetches: both are fetched a few pairs
    // ahead, with the faces (on a bed of 20,000 spheres and 1,000 rocks the sphere-body phase took 13 % less
    // time, docs/BENCHMARKS.md). The faces take a fixed six lines, their 4.1 faces' 394 bytes on average there:
    // a loop over each pair's own count missed its end at every pair.
    constexpr std::size_t kAhead = 8;
    constexpr std::size_t kFaceLines = 6, kAcrossLines = 2;
    auto prefetch = [](const void* at, std::size_t bytes) {
        for (std::size_t line = 0; line < bytes; line += 64) __builtin_prefetch(static_cast<const char*>(at) + line);
    };
    std::size_t touching = 0;
    const auto live_begin = static_cast<std::size_t>(std::lower_bound(live_.begin(), live_.end(), begin) - live_.begin());
    const auto live_end = static_cast<std::size_t>(std::lower_bound(live_.begin(), live_.end(), end) - live_.begin());
    for (std::size_t q = live_begin; q < live_end; ++q) {
        const std::size_t k = live_[q];
        const Pair pair = pairs_[k];
        if (q + kAhead < live_end) {
            const std::size_t ahead = live_[q + kAhead];
            const Pair& next = pairs_[ahead];
            prefetch(&frames[next.mesh], sizeof(ConvexFrame));
            prefetch(&contacts_[ahead], sizeof(WallContact));
            prefetch(&constants_[ahead], sizeof(ContactConstants));
            prefetch(&faces_[next.face_begin], kFaceLines * 64);
            prefetch(&face_across_[next.face_begin], kAcrossLines * 64);
        }
        const ConvexFrame& frame = frames[pair.mesh];
        const std::uint32_t i = pair.particle;
        const Vec3 x = particles.position_m[i];
        const double r = particles.radius_m[i];
        const Vec3 xb = frame.to_body * (x - frame.translation_m);
        const double clear = r + frame.slack_m;
        double farthest = -std::numeric_limits<double>::infinity();
        std::uint32_t farthest_f = pair.face_begin;
        bool separated = false;
        for (std::uint32_t f = pair.face_begin; f < pair.face_end && !separated; ++f) {
            const double d = dot(xb - faces_[f].a, faces_[f].normal);
            separated = d >= clear;
            if (d > farthest) {
                farthest = d;
                farthest_f = f;
            }
        }
        bool touches = false;
        Vec3 point_b, normal_b;
        double overlap = 0.0;
        std::uint32_t face = farthest_f;
        if (!separated && farthest > 0.0) {
            // the face the centre is farthest in front of comes first: when the closest point of a sphere on a
            // face lies inside it, this is that face, and one query settles the body
            const PackedTriangle& ft = faces_[farthest_f];
            meshes::ClosestPoint best_cp = meshes::closest_point_on_triangle(xb, ft.a, ft.b, ft.c);
            if (best_cp.feature == meshes::Feature::Face) {
                // over the face: its plane gives the distance, the normal and the point, with no square root or
                // division in the way (on the bench bed two in three contacts, and 6 % off the pass)
                touches = farthest < r;
                normal_b = ft.normal;
                point_b = xb - ft.normal * farthest;
                overlap = r - farthest;
            } else {
                // a point on an edge is settled by the face across it (most closest points off a face lie on an
                // edge); else by the other faces the centre is in front of
                if (best_cp.feature != meshes::Feature::Edge || !edge_point_is_closest(farthest_f, xb, best_cp, face)) {
                    for (std::uint32_t f = pair.face_begin; f < pair.face_end; ++f) {
                        const PackedTriangle& pt = faces_[f];
                        const double d = dot(xb - pt.a, pt.normal);
                        if (f == farthest_f || d <= 0.0 || d * d >= best_cp.distance_squared) continue;
                        const meshes::ClosestPoint cp = meshes::closest_point_on_triangle(xb, pt.a, pt.b, pt.c);
                        if (cp.distance_squared < best_cp.distance_squared) {
                            face = f;
                            best_cp = cp;
                            if (cp.feature == meshes::Feature::Face) break;
                        }
                    }
                }
                if (best_cp.distance_squared < r * r) {
                    touches = true;
                    const double dist = std::sqrt(best_cp.distance_squared);
                    point_b = best_cp.point;
                    normal_b = dist > 1e-12 * r ? (xb - best_cp.point) * (1.0 / dist) : faces_[face].normal;
                    overlap = r - dist;
                }
            }
        } else if (!separated) {
            touches = true;
            normal_b = faces_[farthest_f].normal;
            point_b = xb - normal_b * farthest;
            overlap = r - farthest;
        }
        WallContact& c = contacts_[k];
        if (!touches) {
            if (touching_[k]) {  // separated: the history of this contact ends
                touching_[k] = 0;
                push_[k] = Push{};
                spin_N_m_[k] = 0.0;
            }
            continue;
        }
        ++touching;
        c.first_step = !touching_[k];
        if (c.first_step) c.history = ContactHistory{};
        touching_[k] = 1;
        c.particle = i;
        c.wall = frame.wall;
        c.triangle = face_triangle_[face];
        c.normal = transposed_times(frame.to_body, normal_b);
        c.point = transposed_times(frame.to_body, point_b) + frame.translation_m;
        c.overlap_m = overlap;
        const Vec3 v = particles.velocity_m_per_s[i];
        const Vec3 w = particles.angular_velocity_rad_per_s[i];
        // the constants of the law (eq. 4, 6, 8) of this sphere's kind against this body
        const MaterialIndex mat = particles.material[i];
        const double m = particles.mass_kg[i];
        const WallMotion& motion = frame.motion;
        const PairCoefficients& p = materials.pair_unchecked(mat, motion.material);
        ContactConstants& constants = constants_[k];
        if (constants.normal_stiffness_N_per_m == 0.0)
            constants = contact_constants(wall_normal_stiffness(bulk_modulus_Pa[mat], r, p.normal_stiffness_scale),
                                          motion.mass_kg > 0.0 ? m * motion.mass_kg / (m + motion.mass_kg) : m, r,
                                          law_coefficients(p, rolling));
        const Vec3 relative_velocity = v + cross(w, c.point - x) - motion.velocity_at(c.point);
        c.forces = linear_spring_dashpot(c.overlap_m, c.normal, relative_velocity, w - motion.angular_velocity_rad_per_s, constants,
                                         c.history, dt_s);
        c.relative_displacement_m = relative_velocity * dt_s;
        const Vec3 force = c.normal * c.forces.normal_force_N + c.forces.tangential_force_N;
        push_[k] = {force, cross(c.point - x, force) + c.forces.rolling_torque_N_m};
        if (rolling == RollingResistance::own_spin) spin_N_m_[k] = p.rolling_friction * r * c.forces.normal_force_N;
        // the body's reaction, while the contact is in cache
        const Vec3 on_wall = -force;
        body_force[frame.wall] += on_wall;
        body_torque[frame.wall] += cross(c.point - motion.reference_point_m, on_wall) - c.forces.rolling_torque_N_m;
        if (first_deep == kNoContact && c.overlap_m / r > max_overlap_ratio) first_deep = k;
    }
    return touching;
}

}  // namespace dipper::dem
