// dem::World: checkpoints, the complete dynamic state written and read back bit for bit.
#include "dem/world.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace dipper::dem {

void World::write_state(StateWriter& out) const
{
    out.tag("dem-world");
    out.value<std::uint64_t>(materials_.size());
    for (std::size_t m = 0; m < materials_.size(); ++m) out.text(materials_.material(static_cast<MaterialIndex>(m)).name);
    out.value<std::uint64_t>(walls_.size());
    for (std::size_t w = 0; w < walls_.size(); ++w) out.text(wall_name(static_cast<int>(w)));
    particles_.write_state(out);
    out.value(time_s_);
    out.value(step_s_);
    out.value(step_count_);
    out.value(rebuild_count_);
    out.value<std::uint8_t>(prepared_);
    out.value<std::uint8_t>(rebuild_needed_);
    out.value<std::uint8_t>(step_checked_);
    out.array(wall_removed_);
    out.array(wall_frozen_);
    out.tag("mesh-poses");
    for (const MeshWall& m : meshes_) {
        out.value(m.rotation());
        out.value(m.translation_m());
        out.value(m.reference_point_m());
        out.value(m.reference_velocity_m_per_s());
        out.value(m.angular_velocity_rad_per_s());
        out.value(m.pose_version());
        out.value(m.mass_kg());
    }
    out.tag("neighbours");
    pairs_.write_state(out);
    out.array(reference_position_m_);
    out.array(stiffness_radius_N_per_m_);
    out.array(reference_mesh_rotation_);
    out.array(reference_mesh_translation_m_);
    out.array(reference_mesh_version_);
    out.value(skin_m_);
    out.tag("wall-contacts");
    // one list sorted by particle, those on convex bodies included (read_state splits it again)
    const std::vector<WallContact> contacts = merged_wall_contacts();
    std::vector<std::uint32_t> contact_start;
    if (!wall_contact_start_.empty()) {
        contact_start.assign(wall_contact_start_.size(), 0);
        for (const WallContact& c : contacts) ++contact_start[c.particle + 1];
        std::partial_sum(contact_start.begin(), contact_start.end(), contact_start.begin());
    }
    out.array(contacts);
    out.array(contact_start);
    candidates_.write(out);
    out.array(wall_force_N_);
    out.array(wall_torque_N_m_);
    out.value(max_overlap_ratio_);
}

void World::read_state(StateReader& in)
{
    in.tag("dem-world");
    const auto material_count = in.value<std::uint64_t>();
    if (material_count != materials_.size())
        in.fail(concat("the state has ", material_count, " materials, this world ", materials_.size()));
    for (std::size_t m = 0; m < materials_.size(); ++m) {
        const std::string name = in.text();
        if (name != materials_.material(static_cast<MaterialIndex>(m)).name)
            in.fail(concat("material ", m, " is '", name, "' in the state, '", materials_.material(static_cast<MaterialIndex>(m)).name,
                           "' in this world"));
    }
    const auto wall_count = in.value<std::uint64_t>();
    if (wall_count != walls_.size()) in.fail(concat("the state has ", wall_count, " walls, this world ", walls_.size()));
    for (std::size_t w = 0; w < walls_.size(); ++w) {
        const std::string name = in.text();
        if (name != wall_name(static_cast<int>(w)))
            in.fail(concat("wall ", w, " is '", name, "' in the state, '", wall_name(static_cast<int>(w)), "' in this world"));
    }
    particles_.read_state(in, materials_);
    time_s_ = in.value<double>();
    step_s_ = in.value<double>();
    if (!(time_s_ >= 0.0 && std::isfinite(time_s_)) || !(step_s_ >= 0.0 && std::isfinite(step_s_)))
        in.fail(concat("a time of ", time_s_, " s or a step of ", step_s_, " s"));
    step_count_ = in.value<std::uint64_t>();
    rebuild_count_ = in.value<std::uint64_t>();
    prepared_ = in.value<std::uint8_t>() != 0;
    rebuild_needed_ = in.value<std::uint8_t>() != 0;
    step_checked_ = in.value<std::uint8_t>() != 0;
    in.array(wall_removed_);
    if (wall_removed_.size() != walls_.size()) in.fail("a removed-wall flag for each wall");
    in.array(wall_frozen_);
    if (wall_frozen_.size() != walls_.size()) in.fail("a frozen-wall flag for each wall");
    for (std::size_t w = 0; w < walls_.size(); ++w)
        if (wall_frozen_[w] > 1 || (wall_frozen_[w] && !(walls_[w].is_mesh && meshes_[static_cast<std::size_t>(walls_[w].index)].convex())))
            in.fail(concat("wall '", wall_name(static_cast<int>(w)), "' frozen; only convex meshes can be"));
    in.tag("mesh-poses");
    for (MeshWall& m : meshes_) {
        const auto rotation = in.value<Mat3>();
        const auto translation = in.value<Vec3>();
        const auto reference = in.value<Vec3>();
        const auto velocity = in.value<Vec3>();
        const auto spin = in.value<Vec3>();
        const auto version = in.value<std::uint64_t>();
        bool finite = is_finite(translation) && is_finite(reference) && is_finite(velocity) && is_finite(spin);
        for (const auto& row : rotation.m)
            for (double x : row) finite = finite && std::isfinite(x);
        if (!finite) in.fail(concat("a pose of mesh '", m.name(), "' that is not finite"));
        m.restore_pose(rotation, translation, reference, velocity, spin, version);
        const double mass = in.value<double>();
        if (!(mass >= 0.0 && std::isfinite(mass))) in.fail(concat("a mass of ", mass, " kg for mesh '", m.name(), "'"));
        m.set_mass_kg(mass);
    }
    std::fill(mesh_moved_.begin(), mesh_moved_.end(), 1);
    in.tag("neighbours");
    pairs_.read_state(in, particles_.size());
    in.array(reference_position_m_);
    in.array(stiffness_radius_N_per_m_);
    in.array(reference_mesh_rotation_);
    in.array(reference_mesh_translation_m_);
    in.array(reference_mesh_version_);
    if (reference_mesh_rotation_.size() > meshes_.size()) in.fail("more mesh references than meshes");
    skin_m_ = in.value<double>();
    if (!(skin_m_ >= 0.0 && std::isfinite(skin_m_))) in.fail(concat("a neighbour skin of ", skin_m_, " m"));
    in.tag("wall-contacts");
    in.array(wall_contacts_);
    in.array(wall_contact_start_);
    candidates_.read(in, planes_.size(), meshes_);
    in.array(wall_force_N_);
    in.array(wall_torque_N_m_);
    max_overlap_ratio_ = in.value<double>();

    // indices must stay inside the arrays they index (a corrupt file must not crash the run)
    const std::size_t n = particles_.size();
    // particles added since the last neighbour rebuild (a pour) are not in the reference and index arrays
    // yet; the rebuild that rebuild_needed_ asks for takes them in
    const auto sized = [&](std::size_t size, std::size_t expected) {
        return rebuild_needed_ ? size <= expected : size == expected;
    };
    if (prepared_ && (!sized(reference_position_m_.size(), n) || reference_position_m_.size() != stiffness_radius_N_per_m_.size()))
        in.fail("reference arrays do not match the particle count");
    for (const WallContact& c : wall_contacts_)
        if (c.particle >= n || c.wall < 0 || static_cast<std::size_t>(c.wall) >= walls_.size()) in.fail("a wall contact out of range");
    if (prepared_ && (!sized(wall_contact_start_.size(), n + 1) || !candidates_.sized_for(n, rebuild_needed_)))
        in.fail("contact index arrays do not match the particle count");
    if (!wall_contact_start_.empty() && wall_contact_start_.back() != wall_contacts_.size()) in.fail("wall contact index mismatch");
    if (!std::is_sorted(wall_contact_start_.begin(), wall_contact_start_.end()))
        in.fail("a wall contact or candidate index that does not ascend");
    if (reference_mesh_version_.size() != reference_mesh_rotation_.size() ||
        reference_mesh_translation_m_.size() != reference_mesh_rotation_.size())
        in.fail("mesh reference arrays differ in length");
    split_candidates();
    split_convex_contacts();
    if (wall_force_N_.size() != walls_.size() || wall_torque_N_m_.size() != walls_.size())
        wall_force_N_.assign(walls_.size(), Vec3{}), wall_torque_N_m_.assign(walls_.size(), Vec3{});
    records_.clear();
    records_stale_ = true;
}

}  // namespace dipper::dem
