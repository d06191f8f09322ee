// The spheres within reach of convex bodies (rocks' hulls): one pair per sphere and body with the faces within
// reach copied beside it, at most one contact per pair, and its push on the sphere and reaction on the body.
#pragma once

#include "core/vec3.h"
#include "dem/contact_law.h"
#include "dem/material.h"
#include "dem/particle_store.h"
#include "dem/wall_contact.h"
#include "dem/walls.h"
#include "meshes/triangle_mesh.h"

#include <cstdint>
#include <vector>

namespace dipper::dem {

/// The pairs are in particle order, so that the spheres' state is read in one sweep; each keeps its contact in
/// place from step to step, as a sphere pair does, until the next rebuild.
class ConvexPairs {
public:
    /// The pairs from each particle's walls within reach (`candidates`, a particle's in [candidate_start[i],
    /// candidate_start[i + 1]), a mesh's triangles in one run): each run of a convex mesh's triangles becomes one
    /// pair. No pair touches until take_contacts gives them last step's contacts.
    void build(const std::vector<std::uint32_t>& candidate_start, const std::vector<MeshCandidate>& candidates,
               const std::vector<MeshWall>& meshes, int threads);
    /// Moves each contact on a convex body (`mesh_of(contact)` its mesh index, -1 for another wall) into its pair,
    /// if the sphere is still within reach of the body (otherwise the contact has ended); the others stay in order.
    template <class MeshOf>
    void take_contacts(std::vector<WallContact>& contacts, MeshOf mesh_of);
    /// Appends the touching pairs' contacts, in pair order.
    void append_contacts(std::vector<WallContact>& out) const;

    /// Before a step's passes: the pairs shared out among `threads` by cost, from their state now (pass_begin,
    /// pass_end), and the law constants cleared if a body's mass changed.
    void start_step(int threads);
    std::size_t pass_begin(int t) const { return pass_start_[static_cast<std::size_t>(t)]; }
    std::size_t pass_end(int t) const { return pass_start_[static_cast<std::size_t>(t) + 1]; }
    /// A body's mass changed: every pair's law constants are found again at its next contact.
    void forget_constants() { constants_stale_ = true; }
    /// Before compute: the pairs it works on, all but those of a frozen particle (`particle_frozen`) and a frozen body
    /// (`wall_frozen` by wall id, `mesh_wall_id` each mesh's), whose contacts stay as they were. Found again only after
    /// a build or when `frozen_version` (the caller's count of changes of the frozen flags) changed, as SpherePairs does.
    void update_live(const std::vector<std::uint8_t>& particle_frozen, const std::vector<std::uint8_t>& wall_frozen,
                     const std::vector<std::int32_t>& mesh_wall_id, std::uint64_t frozen_version);
    /// The pairs left out by update_live that touch (their contacts stand as they were).
    std::size_t frozen_touching() const { return frozen_touching_; }
    /// The contacts of the live pairs among [begin, end) (update_live): each touching pair's push on its sphere and
    /// reaction on its body (added to body_force and body_torque by wall id); the first pair past the overlap limit
    /// in first_deep. Returns how many of them touch.
    std::size_t compute(std::size_t begin, std::size_t end, const ParticleStore& p, const std::vector<ConvexFrame>& frames,
                        const MaterialTable& materials, const std::vector<double>& bulk_modulus_Pa, double max_overlap_ratio,
                        double dt_s, std::size_t& first_deep, Vec3* body_force, Vec3* body_torque);
    /// Adds the pushes of particle i's pairs to force and torque, in pair order.
    void push(std::size_t i, Vec3& force, Vec3& torque) const
    {
        for (std::uint32_t k = pair_start_[i]; k < pair_start_[i + 1]; ++k) {
            const Push& p = push_[pair_index_[k]];
            force += p.force_N;
            torque += p.torque_N_m;
        }
    }
    /// Under RollingResistance::own_spin: adds the sum of mu_roll r Fn of particle i's pairs to spin_resistance.
    void push_spin_resistance(std::size_t i, double& spin_resistance) const
    {
        for (std::uint32_t k = pair_start_[i]; k < pair_start_[i + 1]; ++k) spin_resistance += spin_N_m_[pair_index_[k]];
    }

    std::size_t size() const { return pairs_.size(); }
    bool touching(std::size_t k) const { return touching_[k] != 0; }
    const WallContact& contact(std::size_t k) const { return contacts_[k]; }
    /// Particle i's pairs, in pair order (after build).
    std::uint32_t first_of(std::size_t i) const { return pair_start_[i]; }
    std::uint32_t last_of(std::size_t i) const { return pair_start_[i + 1]; }
    std::uint32_t pair_at(std::uint32_t slot) const { return pair_index_[slot]; }
    /// The particles the pairs were built for.
    std::size_t particle_count() const { return pair_start_.empty() ? 0 : pair_start_.size() - 1; }

private:
    struct Pair { std::uint32_t mesh, particle, face_begin, face_end; };
    struct Push { Vec3 force_N, torque_N_m; };  ///< on the particle, about its centre
    /// The face across each edge (ab, bc, ca) of a pair's face among the pair's faces (the first in order that
    /// shares both ends, kNoFace if none), and which edge of it that is; found at each build by comparing every two
    /// faces of a pair (a pair holds the few faces within reach of one sphere).
    struct FaceAcross { std::uint32_t face[3]; std::uint8_t edge[3]; };
    static constexpr std::uint32_t kNoFace = 0xffffffffu;

    /// Whether `best`, the closest point of face face_f of a pair on one of its edges, is the body's: decided from
    /// the face across that edge, which may replace it (`best`, `best_face`).
    bool edge_point_is_closest(std::uint32_t face_f, const Vec3& xb, meshes::ClosestPoint& best, std::uint32_t& best_face) const;

    std::vector<Pair> pairs_;
    /// beside pairs_: the constants of the pair's law (eq. 4, 6, 8), found when it first touches after a build; a
    /// stiffness of zero (never a pair's: C_norm > 0) marks them not found yet
    std::vector<ContactConstants> constants_;
    bool constants_stale_ = false;
    std::vector<PackedTriangle> faces_;       ///< body frame, the faces within reach of each pair in turn
    std::vector<std::int32_t> face_triangle_; ///< beside faces_: the mesh's triangle
    std::vector<FaceAcross> face_across_;     ///< beside faces_
    std::vector<WallContact> contacts_;       ///< beside pairs_: the contact of this step, if touching
    std::vector<std::uint8_t> touching_;      ///< beside pairs_
    std::vector<Push> push_;                  ///< beside pairs_ (zero when apart)
    std::vector<double> spin_N_m_;            ///< beside pairs_: under own_spin mu_roll r Fn (zero when apart)
    std::vector<std::uint32_t> pair_start_, pair_index_;  ///< each particle's pairs
    std::vector<std::size_t> pass_start_;     ///< the pairs whose contacts each thread computes: shares of equal cost
    /// the pairs compute works on, in order: all but those of a frozen sphere and a frozen body (update_live)
    std::vector<std::uint32_t> live_;
    std::size_t frozen_touching_ = 0;
    bool live_stale_ = true;
    std::uint64_t live_frozen_version_ = 0;
};

template <class MeshOf>
void ConvexPairs::take_contacts(std::vector<WallContact>& contacts, MeshOf mesh_of)
{
    std::size_t kept = 0;
    for (std::size_t q = 0; q < contacts.size(); ++q) {
        const WallContact& c = contacts[q];
        const std::int64_t mesh = mesh_of(c);
        if (mesh < 0) {
            contacts[kept++] = c;
            continue;
        }
        for (std::uint32_t slot = pair_start_[c.particle]; slot < pair_start_[c.particle + 1]; ++slot) {
            const std::uint32_t k = pair_index_[slot];
            if (pairs_[k].mesh != static_cast<std::uint32_t>(mesh)) continue;
            if (!touching_[k]) {  // one contact per body (a second one only from an older rule)
                contacts_[k] = c;
                touching_[k] = 1;
            }
            break;
        }  // no pair: the sphere has gone out of reach, and the contact has ended
    }
    contacts.resize(kept);
}

}  // namespace dipper::dem
