// The world's neighbour search (docs/step.md, phase 3): when the lists are rebuilt, and the rebuild itself (the
// particles sorted by cell, the sphere pairs, the walls within reach with the pairs of spheres and convex bodies).
#include "dem/world.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <omp.h>

namespace dipper::dem {

bool World::needs_rebuild(double particle_move_m) const
{
    if (2.0 * particle_move_m > skin_m_) return true;

    // every rock is a mesh: at full size 20,000 of them, read on all threads (a maximum: the same in any order)
    double mesh_move = 0.0;
    const auto mesh_count = static_cast<std::ptrdiff_t>(meshes_.size());
#pragma omp parallel for schedule(static) reduction(max : mesh_move) num_threads(threads_) if (mesh_count > 2048)
    for (std::ptrdiff_t q = 0; q < mesh_count; ++q) {
        const auto m = static_cast<std::size_t>(q);
        if (meshes_[m].pose_version() == reference_mesh_version_[m]) continue;  // not moved since the rebuild
        mesh_move = std::max(mesh_move, meshes_[m].max_vertex_move_m(reference_mesh_rotation_[m], reference_mesh_translation_m_[m]));
    }
    return particle_move_m + mesh_move > skin_m_;
}

// ---- neighbour search ----------------------------------------------------------------------------

void World::rebuild()
{
    const std::size_t n = particles_.size();
    ++rebuild_count_;
    double r_max = 0.0;
    for (double r : particles_.radius_m) r_max = std::max(r_max, r);
    const double old_skin_m = skin_m_;
    skin_m_ = settings_.skin_fraction_of_radius * r_max;

    // The particles that sit bit for bit where they sat at the last rebuild (the frozen ones), by their index then:
    // their wall candidates may be taken over. Not after particles or walls came or went (rebuild_needed_), nor
    // after a checkpoint was read (the reference radii are not kept in it).
    const bool may_carry = settings_.carry_wall_candidates && !rebuild_needed_ && skin_m_ == old_skin_m && reference_position_m_.size() == n &&
                           reference_radius_m_.size() == n && reference_mesh_version_.size() == meshes_.size();
    rebuild_needed_ = false;
    std::vector<std::uint8_t> unmoved;
    if (may_carry) {
        unmoved.resize(n);
        for (std::size_t i = 0; i < n; ++i)
            unmoved[i] = particles_.position_m[i] == reference_position_m_[i] && particles_.radius_m[i] == reference_radius_m_[i];
    }

    // the cell grid over the particles, and their order sorted by cell
    std::vector<std::uint32_t> order, old_to_new(n);
    const CellGrid grid = CellGrid::sorting(particles_.position_m, 2.0 * r_max + skin_m_, order);
    for (std::size_t k = 0; k < n; ++k) old_to_new[order[k]] = static_cast<std::uint32_t>(k);
    particles_.permute(order);
    if (may_carry) {
        std::vector<std::uint8_t> by_new(n);
        for (std::size_t k = 0; k < n; ++k) by_new[k] = unmoved[order[k]];
        unmoved.swap(by_new);
    }
    stiffness_radius_N_per_m_.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        stiffness_radius_N_per_m_[i] = bulk_modulus_Pa_[particles_.material[i]] * particles_.radius_m[i];

    pairs_.rebuild(particles_, grid, skin_m_, old_to_new, threads_);

    // wall contacts keep their history (those on convex bodies too): renumbered and re-sorted by particle
    convex_.append_contacts(wall_contacts_);
    for (WallContact& c : wall_contacts_) c.particle = c.particle < n ? old_to_new[c.particle] : std::uint32_t(n);
    wall_contacts_.erase(std::remove_if(wall_contacts_.begin(), wall_contacts_.end(),
                                        [n](const WallContact& c) { return c.particle >= n; }),
                         wall_contacts_.end());
    std::stable_sort(wall_contacts_.begin(), wall_contacts_.end(),
                     [](const WallContact& a, const WallContact& b) { return a.particle < b.particle; });

    // planes and triangles near each particle, and the pairs of spheres and convex bodies, which take the
    // history of their contacts
    if (may_carry) {
        std::vector<std::uint8_t> mesh_unchanged(meshes_.size());
        for (std::size_t m = 0; m < meshes_.size(); ++m) mesh_unchanged[m] = meshes_[m].pose_version() == reference_mesh_version_[m];
        const CandidateCarry carry{order, unmoved, mesh_unchanged};
        candidates_.build(grid, particles_, skin_m_, wall_set(), convex_, threads_, &carry);
    } else {
        candidates_.build(grid, particles_, skin_m_, wall_set(), convex_, threads_);
    }
    convex_contact_count_ = 0;
    split_convex_contacts();

    reference_position_m_ = particles_.position_m;
    reference_radius_m_ = particles_.radius_m;
    reference_mesh_rotation_.resize(meshes_.size());
    reference_mesh_translation_m_.resize(meshes_.size());
    reference_mesh_version_.resize(meshes_.size());
    for (std::size_t m = 0; m < meshes_.size(); ++m) {
        reference_mesh_rotation_[m] = meshes_[m].rotation();
        reference_mesh_translation_m_[m] = meshes_[m].translation_m();
        reference_mesh_version_[m] = meshes_[m].pose_version();
    }
}

void World::split_candidates()
{
    candidates_.split(meshes_, convex_, threads_);
    convex_contact_count_ = 0;
}

void World::split_convex_contacts()
{
    // a contact on a convex body goes to its pair (if the sphere is still within reach), the others stay
    convex_.take_contacts(wall_contacts_, [this](const WallContact& c) -> std::int64_t {
        const WallRef& ref = walls_[static_cast<std::size_t>(c.wall)];
        return ref.is_mesh && meshes_[static_cast<std::size_t>(ref.index)].convex() ? ref.index : -1;
    });
    const std::size_t n = particles_.size();
    wall_contact_start_.assign(n + 1, 0);
    for (const WallContact& c : wall_contacts_) ++wall_contact_start_[c.particle + 1];
    std::partial_sum(wall_contact_start_.begin(), wall_contact_start_.end(), wall_contact_start_.begin());
}

std::vector<WallContact> World::merged_wall_contacts() const
{
    const std::size_t n = convex_.particle_count();
    if (convex_.size() == 0 || wall_contact_start_.size() != n + 1) return wall_contacts_;
    std::vector<WallContact> all;
    all.reserve(wall_contacts_.size() + convex_contact_count_);
    for (std::size_t i = 0; i < n; ++i) {
        all.insert(all.end(), wall_contacts_.begin() + wall_contact_start_[i], wall_contacts_.begin() + wall_contact_start_[i + 1]);
        for (std::uint32_t k = convex_.first_of(i); k < convex_.last_of(i); ++k)
            if (convex_.touching(convex_.pair_at(k))) all.push_back(convex_.contact(convex_.pair_at(k)));
    }
    return all;
}

}  // namespace dipper::dem
