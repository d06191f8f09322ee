// Only what moves: spheres and rocks at rest, away from the machine and from moving material, are frozen (held
// still, out of the integration and of the contacts between frozen bodies) and let go when something moving
// comes within a margin. At rest means going nowhere: a body that stays within rest_speed x rest_time of one point
// for rest_time, however it jitters there, and went no faster than the rest speed of late (over the last 10-20 ms at
// the default rest time). Moving means going somewhere fast: more than ten times the rest speed of late. What lies
// between (a slow creep) neither freezes nor keeps others from freezing. The thesis' simplified model held its
// resting particles fixed by hand; EDEM calls the same a dynamic domain.
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
    /// A body is frozen only if nothing moving (a sphere or rock that moved faster than kMovingFactor x rest_speed
    /// of late, a moving wall's bounding sphere) lies in its cell of this size or the 26 around
    /// it: at least this far from it.
    double margin_m = 1.0;
    /// At rest: the centre (a rock's bounding centre) has stayed within rest_speed x rest_time of one point for
    /// rest_time (on average no faster than this, whatever its speed of the moment) and went no faster than this
    /// of late (over the last rest_time_s / 20 to rest_time_s / 10).
    double rest_speed_m_per_s = 0.01;
    /// ... over at least this long.
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

    /// Holds spheres (dense indices now) and rocks (indices in CoupledWorld::rocks()) fixed for the rest of the run:
    /// frozen at once and never let go, whether the domain is enabled or not. This is the thesis' simplified model's
    /// boundary: a pile cut to the region the dipper works in, its 0.5 m boundary layer constrained in all directions.
    void hold(CoupledWorld& coupled, const std::vector<std::size_t>& spheres, const std::vector<std::size_t>& rocks);
    std::size_t held_bodies() const { return held_bodies_; }

    /// Moving: a mean speed over the last 10-20 ms (at the default rest time) above this times the rest speed. A
    /// settling pile's creep and the rattle of bodies that ring in place stay below it; material the machine sets
    /// going exceeds it within a few milliseconds.
    static constexpr double kMovingFactor = 10.0;

    /// Whether the sphere with this particle id counted as moving at the last update (nothing within the margin of
    /// it was frozen then).
    bool sphere_moving(std::uint32_t id) const;

    std::size_t frozen_spheres() const { return frozen_spheres_; }
    std::size_t frozen_rocks() const { return frozen_rocks_; }
    /// Spheres and rocks that were at rest (frozen or kept from freezing by something moving near them) and that
    /// moved, at the last update.
    std::size_t resting_bodies() const { return resting_bodies_; }
    std::size_t moving_bodies() const { return moving_bodies_; }

    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

private:
    /// The checkpoint's fields, listed once for writing and reading (core/state_io.h).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& s);
    /// The cells (margin_m wide, or wider where the bodies spread far) that hold moving things, and those next to them.
    void mark(const Vec3& lo_m, const Vec3& hi_m);
    std::size_t cell_index(const Vec3& p) const;
    /// Marks a cell hot (once).
    void heat(std::size_t cell);
    bool near(const Vec3& lo_m, const Vec3& hi_m) const;
    /// Calls visit(cell) for the cells a box overlaps until it returns true; whether one did.
    template <class Visit>
    bool any_cell(const Vec3& lo_m, const Vec3& hi_m, Visit visit) const;

    /// One body's rest: the point it has stayed near and for how long. A body that leaves the reach of its anchor
    /// gets a new anchor where it is and starts again from 0 s; a new body's anchor is at infinity. Its speed is its
    /// mean over a window of one to two kWindowsPerRestTime-ths of the rest time (10-20 ms at 0.2 s): from where it
    /// was when the older of its two windows began to where it is; a window of one coupling step would read a body
    /// that rings in place (a rattler in a rock cage, a rock under Bullet's sawtooth) as going somewhere.
    static constexpr double kNowhere = 1e300;
    /// held: frozen for good (hold), judged no more
    enum class Motion : std::uint64_t { resting, creeping, moving, held };  // 64 bits: a Rest has no padding to checkpoint
    struct Rest {
        Vec3 anchor_m{kNowhere, kNowhere, kNowhere};
        Vec3 older_m{kNowhere, kNowhere, kNowhere};  ///< where it was when the older window began
        Vec3 newer_m{kNowhere, kNowhere, kNowhere};  ///< ... and the newer one
        double time_s = 0.0;   ///< how long it has stayed within reach of its anchor
        double older_s = 0.0;  ///< how long ago the older window began
        double newer_s = 0.0;  ///< ... and the newer one
        Motion motion = Motion::creeping;
    };
    static constexpr double kWindowsPerRestTime = 20.0;
    /// The body now at x, after interval_s: its rest moved on and what it did.
    Motion advance(Rest& rest, const Vec3& x, double interval_s) const;

    DynamicDomainSettings settings_;
    std::vector<Rest> sphere_rest_;  ///< by particle id
    std::vector<Rest> rock_rest_;    ///< by rock (CoupledWorld::rocks() order)
    std::size_t resting_bodies_ = 0, moving_bodies_ = 0;
    std::size_t frozen_spheres_ = 0, frozen_rocks_ = 0;
    std::size_t held_bodies_ = 0;  ///< counted from the rests at hold and read_state (not a checkpoint field)
    // the grid of the last update (scratch)
    Vec3 lo_m_;
    double cell_m_ = 1.0;
    int dims_[3] = {1, 1, 1};
    /// A cell is hot (near) in this update when its stamp is stamp_; the hot cells listed once each.
    std::vector<std::uint16_t> hot_stamp_, near_stamp_;
    std::uint16_t stamp_ = 0;
    std::vector<std::size_t> hot_cells_;
};

}  // namespace dipper::coupling
