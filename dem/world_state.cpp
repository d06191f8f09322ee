// dem::World: checkpoints, the complete dynamic state written and read back bit for bit.
#include "dem/world.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace dipper::dem {

template <class IO, class Self>
void World::state_fields(IO& io, Self& s)
{
    io.tag("dem-world");
    // the materials and walls by name: a state read into a world built otherwise is refused
    io.count(s.materials_.size(), "materials");
    for (std::size_t m = 0; m < s.materials_.size(); ++m) {
        const std::string& ours = s.materials_.material(static_cast<MaterialIndex>(m)).name;
        std::string name = ours;
        io(name);
        if constexpr (IO::reading)
            if (name != ours) io.fail(concat("material ", m, " is '", name, "' in the state, '", ours, "' in this world"));
    }
    io.count(s.walls_.size(), "walls");
    for (std::size_t w = 0; w < s.walls_.size(); ++w) {
        const std::string ours = s.wall_name(static_cast<int>(w));
        std::string name = ours;
        io(name);
        if constexpr (IO::reading)
            if (name != ours) io.fail(concat("wall ", w, " is '", name, "' in the state, '", ours, "' in this world"));
    }
    if constexpr (IO::reading)
        s.particles_.read_state(io, s.materials_);
    else
        s.particles_.write_state(io);
    io(s.time_s_, s.step_s_, s.step_count_, s.rebuild_count_, s.prepared_, s.rebuild_needed_, s.step_checked_);
    io(s.wall_removed_, s.wall_frozen_);
    io.tag("mesh-poses");
    for (auto& m : s.meshes_) {
        Mat3 rotation = m.rotation();
        Vec3 translation = m.translation_m(), reference = m.reference_point_m(), velocity = m.reference_velocity_m_per_s(),
             spin = m.angular_velocity_rad_per_s();
        std::uint64_t version = m.pose_version();
        double mass = m.mass_kg();
        io(rotation, translation, reference, velocity, spin, version, mass);
        if constexpr (IO::reading) {
            bool finite = is_finite(translation) && is_finite(reference) && is_finite(velocity) && is_finite(spin);
            for (const auto& row : rotation.m)
                for (double x : row) finite = finite && std::isfinite(x);
            if (!finite) io.fail(concat("a pose of mesh '", m.name(), "' that is not finite"));
            m.restore_pose(rotation, translation, reference, velocity, spin, version);
            if (!(mass >= 0.0 && std::isfinite(mass))) io.fail(concat("a mass of ", mass, " kg for mesh '", m.name(), "'"));
            m.set_mass_kg(mass);
        }
    }
    io.tag("neighbours");
    if constexpr (IO::reading)
        s.pairs_.read_state(io, s.particles_.size());
    else
        s.pairs_.write_state(io);
    io(s.reference_position_m_, s.stiffness_radius_N_per_m_, s.reference_mesh_rotation_, s.reference_mesh_translation_m_,
       s.reference_mesh_version_, s.skin_m_);
    io.tag("wall-contacts");
    // one list sorted by particle, those on convex bodies included (read_state splits it again)
    std::vector<WallContact> contacts;
    std::vector<std::uint32_t> contact_start;
    if constexpr (!IO::reading) {
        contacts = s.merged_wall_contacts();
        if (!s.wall_contact_start_.empty()) {
            contact_start.assign(s.wall_contact_start_.size(), 0);
            for (const WallContact& c : contacts) ++contact_start[c.particle + 1];
            std::partial_sum(contact_start.begin(), contact_start.end(), contact_start.begin());
        }
    }
    io(contacts, contact_start);
    if constexpr (IO::reading) {
        s.wall_contacts_ = std::move(contacts);
        s.wall_contact_start_ = std::move(contact_start);
        s.candidates_.read_state(io, s.planes_.size(), s.meshes_);
    } else {
        s.candidates_.write_state(io);
    }
    io(s.wall_force_N_, s.wall_torque_N_m_, s.max_overlap_ratio_);
}

void World::write_state(StateWriter& out) const { state_fields(out, *this); }

void World::read_state(StateReader& in)
{
    state_fields(in, *this);
    reference_radius_m_.clear();  // nothing is carried over at the first rebuild after a read (World::rebuild)
    ++frozen_version_;
    if (!(time_s_ >= 0.0 && std::isfinite(time_s_)) || !(step_s_ >= 0.0 && std::isfinite(step_s_)))
        in.fail(concat("a time of ", time_s_, " s or a step of ", step_s_, " s"));
    if (wall_removed_.size() != walls_.size()) in.fail("a removed-wall flag for each wall");
    if (wall_frozen_.size() != walls_.size()) in.fail("a frozen-wall flag for each wall");
    for (std::size_t w = 0; w < walls_.size(); ++w)
        if (wall_frozen_[w] > 1 || (wall_frozen_[w] && !(walls_[w].is_mesh && meshes_[static_cast<std::size_t>(walls_[w].index)].convex())))
            in.fail(concat("wall '", wall_name(static_cast<int>(w)), "' frozen; only convex meshes can be"));
    std::fill(mesh_moved_.begin(), mesh_moved_.end(), 1);
    if (reference_mesh_rotation_.size() > meshes_.size()) in.fail("more mesh references than meshes");
    if (!(skin_m_ >= 0.0 && std::isfinite(skin_m_))) in.fail(concat("a neighbour skin of ", skin_m_, " m"));

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
