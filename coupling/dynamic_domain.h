// Only what moves: spheres and rocks at rest, away from the machine and from moving material, are frozen (held
// still, out of the integration and of the contacts between frozen bodies) and let go when something moving
// comes within a margin. The thesis' simplified model held its resting particles fixed by hand; EDEM calls the
// same a dynamic domain.
#pragma once

#include "core/state_io.h"
#include "core/vec3.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace dipper::coupling {

class CoupledWorld;

/// When a body counts as at rest, and how far from moving things it must be to be frozen.
struct DynamicDomainSettings {
    bool enabled = false;
    /// A body is frozen only if nothing moving (a sphere or rock faster than rest_speed, a moving wall's
    /// bounding sphere) lies in its cell of this size or the 26 around it: at least this far from it.
    double margin_m = 1.0;
    /// At rest: the speed of the centre plus the spin times the radius (a rock's bounding radius) at most this.
    double rest_speed_m_per_s = 0.01;
    /// ... for at least this long without a break.
    double rest_time_s = 0.2;
};

/// Decides after each coupling step which spheres (dem::World::set_frozen) and rocks (rigid::RigidWorld::set_frozen
/// with dem::World::set_wall_frozen) are frozen. The decision depends on the state alone, body by body, so a run
/// gives the same bits on any thread count and through a checkpoint.
class DynamicDomain {
public:
    explicit DynamicDomain(DynamicDomainSettings settings);
    const DynamicDomainSettings& settings() const { return settings_; }

    /// After a coupling step of interval_s: each body's time at rest, the cells near anything moving, and the
    /// bodies frozen or let go.
    void update(CoupledWorld& coupled, double interval_s);

    std::size_t frozen_spheres() const { return frozen_spheres_; }
    std::size_t frozen_rocks() const { return frozen_rocks_; }

    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

private:
    /// The checkpoint's fields, listed once for writing and reading (core/state_io.h).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& s);
    /// The cells (margin_m wide, or wider where the bodies spread far) that hold moving things, and those next to them.
    void mark(const Vec3& lo_m, const Vec3& hi_m);
    std::size_t cell_index(const Vec3& p) const;
    bool near(const Vec3& lo_m, const Vec3& hi_m) const;
    /// Calls visit(cell) for the cells a box overlaps until it returns true; whether one did.
    template <class Visit>
    bool any_cell(const Vec3& lo_m, const Vec3& hi_m, Visit visit) const;

    DynamicDomainSettings settings_;
    std::vector<double> sphere_rest_s_;  ///< by particle id: how long it has been at rest
    std::vector<double> rock_rest_s_;    ///< by rock (CoupledWorld::rocks() order)
    std::size_t frozen_spheres_ = 0, frozen_rocks_ = 0;
    // the grid of the last update (scratch)
    Vec3 lo_m_;
    double cell_m_ = 1.0;
    int dims_[3] = {1, 1, 1};
    std::vector<std::uint8_t> hot_, near_;
};

}  // namespace dipper::coupling
