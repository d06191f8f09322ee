#include "coupling/dynamic_domain.h"

#include "core/errors.h"
#include "coupling/coupled_world.h"
#include "dem/world.h"
#include "rigid/rigid_world.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dipper::coupling {

namespace {
/// The grid holds at most this many cells; bodies spread wider get wider cells (a larger margin, never smaller).
constexpr double kMaxCells = 1 << 24;
}  // namespace

DynamicDomain::DynamicDomain(DynamicDomainSettings settings) : settings_(settings)
{
    require_positive(settings_.margin_m, "margin_m", "dynamic domain");
    require_positive(settings_.rest_speed_m_per_s, "rest_speed_m_per_s", "dynamic domain");
    require_positive(settings_.rest_time_s, "rest_time_s", "dynamic domain");
}

DynamicDomain::Motion DynamicDomain::advance(Rest& rest, const Vec3& x, double interval_s) const
{
    if (rest.motion == Motion::held) return rest.motion;
    const double reach = settings_.rest_speed_m_per_s * settings_.rest_time_s;
    const double window = settings_.rest_time_s / kWindowsPerRestTime;
    // the two windows: a new body starts its newer one where it is and is judged once it has an older one
    rest.older_s += interval_s;
    rest.newer_s += interval_s;
    if (rest.newer_m.x == kNowhere) {
        rest.newer_m = x;
        rest.newer_s = 0.0;
    } else if (rest.newer_s >= window) {
        rest.older_m = rest.newer_m;
        rest.older_s = rest.newer_s;
        rest.newer_m = x;
        rest.newer_s = 0.0;
    }
    if (norm_squared(x - rest.anchor_m) > reach * reach) {
        rest.anchor_m = x;
        rest.time_s = 0.0;
    } else {
        rest.time_s += interval_s;
    }
    if (rest.older_m.x == kNowhere) return rest.motion = Motion::creeping;
    // its mean speed over the windows, squared and times the time squared
    const double moved2 = norm_squared(x - rest.older_m);
    const double slow = settings_.rest_speed_m_per_s * rest.older_s;
    const double fast = kMovingFactor * slow;
    // at rest: near its anchor long enough, and not set going of late (a body just struck is still within reach of
    // its anchor for a while, and must not freeze with the blow in it)
    if (moved2 > fast * fast)
        rest.motion = Motion::moving;
    else if (rest.time_s >= settings_.rest_time_s && moved2 <= slow * slow)
        rest.motion = Motion::resting;
    else
        rest.motion = Motion::creeping;
    return rest.motion;
}

bool DynamicDomain::sphere_moving(std::uint32_t id) const
{
    return id >= sphere_rest_.size() || sphere_rest_[id].motion == Motion::moving;
}

std::size_t DynamicDomain::cell_index(const Vec3& p) const
{
    std::size_t c[3];
    for (int a = 0; a < 3; ++a)
        c[a] = static_cast<std::size_t>(std::clamp(static_cast<int>(std::floor((p[a] - lo_m_[a]) / cell_m_)), 0, dims_[a] - 1));
    return (c[2] * static_cast<std::size_t>(dims_[1]) + c[1]) * static_cast<std::size_t>(dims_[0]) + c[0];
}

template <class Visit>
bool DynamicDomain::any_cell(const Vec3& lo, const Vec3& hi, Visit visit) const
{
    int a0[3], a1[3];
    for (int a = 0; a < 3; ++a) {
        // boxes beyond the grid touch its border cells (the grid holds every body)
        a0[a] = std::clamp(static_cast<int>(std::floor((lo[a] - lo_m_[a]) / cell_m_)), 0, dims_[a] - 1);
        a1[a] = std::clamp(static_cast<int>(std::floor((hi[a] - lo_m_[a]) / cell_m_)), 0, dims_[a] - 1);
    }
    for (int z = a0[2]; z <= a1[2]; ++z)
        for (int y = a0[1]; y <= a1[1]; ++y)
            for (int x = a0[0]; x <= a1[0]; ++x)
                if (visit((static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x)) return true;
    return false;
}

void DynamicDomain::mark(const Vec3& lo, const Vec3& hi)
{
    any_cell(lo, hi, [this](std::size_t c) {
        heat(c);
        return false;
    });
}

void DynamicDomain::heat(std::size_t cell)
{
    if (hot_stamp_[cell] == stamp_) return;
    hot_stamp_[cell] = stamp_;
    hot_cells_.push_back(cell);
}

bool DynamicDomain::near(const Vec3& lo, const Vec3& hi) const
{
    return any_cell(lo, hi, [this](std::size_t c) { return near_stamp_[c] == stamp_; });
}

void DynamicDomain::update(CoupledWorld& coupled, double interval_s)
{
    if (!settings_.enabled) return;
    dem::World& dem = coupled.dem();
    rigid::RigidWorld& rigid = coupled.rigid();
    const dem::ParticleStore& p = dem.particles();
    const std::size_t n = p.size();
    const std::vector<RockRecord>& rocks = coupled.rocks();
    if (n == 0 && rocks.empty()) return;

    // 1. what each body did: rested (stayed near its anchor for rest_time_s), crept, or moved
    std::uint32_t max_id = 0;
    for (std::uint32_t id : p.id) max_id = std::max(max_id, id);
    if (n > 0 && sphere_rest_.size() <= max_id) sphere_rest_.resize(static_cast<std::size_t>(max_id) + 1);
    std::vector<Motion> sphere_motion(n);
    for (std::size_t i = 0; i < n; ++i) sphere_motion[i] = advance(sphere_rest_[p.id[i]], p.position_m[i], interval_s);
    struct RockNow {
        int wall;
        Vec3 centre;
        double radius;
        Motion motion;
    };
    rock_rest_.resize(rocks.size());
    std::vector<RockNow> rock_now(rocks.size());
    for (std::size_t k = 0; k < rocks.size(); ++k) {
        const int wall = coupled.body(coupled.index_of(rocks[k].body)).wall;
        const dem::MeshWall& m = dem.mesh_wall(wall);
        const Vec3 centre = m.bound_centre_world_m();
        rock_now[k] = {wall, centre, m.bound_radius_m(), advance(rock_rest_[k], centre, interval_s)};
    }

    resting_bodies_ = moving_bodies_ = 0;
    for (Motion m : sphere_motion) {
        resting_bodies_ += m == Motion::resting ? 1 : 0;
        moving_bodies_ += m == Motion::moving ? 1 : 0;
    }
    for (const RockNow& r : rock_now) {
        resting_bodies_ += r.motion == Motion::resting ? 1 : 0;
        moving_bodies_ += r.motion == Motion::moving ? 1 : 0;
    }

    // 2. the grid over every body, cells margin_m wide
    const double inf = std::numeric_limits<double>::infinity();
    Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
    auto grow = [&](const Vec3& a, const Vec3& b) {
        lo = {std::min(lo.x, a.x), std::min(lo.y, a.y), std::min(lo.z, a.z)};
        hi = {std::max(hi.x, b.x), std::max(hi.y, b.y), std::max(hi.z, b.z)};
    };
    for (const Vec3& x : p.position_m) grow(x, x);
    for (const RockNow& r : rock_now) grow(r.centre - Vec3{r.radius, r.radius, r.radius}, r.centre + Vec3{r.radius, r.radius, r.radius});
    lo_m_ = lo;
    cell_m_ = settings_.margin_m;
    for (;;) {
        double total = 1.0;
        for (int a = 0; a < 3; ++a) total *= std::floor((hi[a] - lo[a]) / cell_m_) + 1.0;
        if (total <= kMaxCells) break;
        cell_m_ *= std::max(1.25, std::cbrt(total / kMaxCells));
    }
    for (int a = 0; a < 3; ++a) dims_[a] = static_cast<int>(std::floor((hi[a] - lo[a]) / cell_m_)) + 1;
    const std::size_t cells = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
    // Which cells are hot and near is kept as this update's stamp in arrays over the grid, so that an update touches
    // the cells near moving things and the bodies' own, never the whole grid: bodies spread from the dig to the truck
    // make a grid of millions of cells at a margin of 0.3 m, and clearing it at every coupling step cost more than
    // the steps themselves.
    if (near_stamp_.size() < cells) {
        hot_stamp_.assign(cells, 0);
        near_stamp_.assign(cells, 0);
    }
    if (++stamp_ == 0) {  // the stamps wrapped: every cell to 0 once, this update 1
        std::fill(hot_stamp_.begin(), hot_stamp_.end(), 0);
        std::fill(near_stamp_.begin(), near_stamp_.end(), 0);
        stamp_ = 1;
    }
    hot_cells_.clear();

    // 3. the cells with something moving: spheres and rocks that moved, walls that move or may move (a machine
    //    part, a gate) over their bounding sphere
    for (std::size_t i = 0; i < n; ++i)
        if (sphere_motion[i] == Motion::moving) heat(cell_index(p.position_m[i]));
    for (const RockNow& r : rock_now)
        if (r.motion == Motion::moving) mark(r.centre - Vec3{r.radius, r.radius, r.radius}, r.centre + Vec3{r.radius, r.radius, r.radius});
    for (std::size_t w = 0; w < dem.wall_count(); ++w) {
        const int wall = static_cast<int>(w);
        if (!dem.is_mesh(wall) || dem.wall_removed(wall)) continue;
        const dem::MeshWall& m = dem.mesh_wall(wall);
        if (m.convex()) continue;  // rocks, above
        // a machine part (a body behind it) or a wall with a motion counts while it pauses too: what it holds must not
        // freeze and be pushed frozen when it starts again
        const bool may_move = m.mass_kg() > 0.0 || m.motion().has_value();
        if (!may_move && m.velocity_at(m.reference_point_m()) == Vec3{} && m.angular_velocity_rad_per_s() == Vec3{}) continue;
        const Vec3 c = m.bound_centre_world_m();
        const double r = m.bound_radius_m();
        mark(c - Vec3{r, r, r}, c + Vec3{r, r, r});
    }

    // 4. near: a hot cell and the 26 around it
    for (std::size_t c : hot_cells_) {
        const int x = static_cast<int>(c % static_cast<std::size_t>(dims_[0]));
        const int y = static_cast<int>(c / static_cast<std::size_t>(dims_[0]) % static_cast<std::size_t>(dims_[1]));
        const int z = static_cast<int>(c / (static_cast<std::size_t>(dims_[0]) * static_cast<std::size_t>(dims_[1])));
        for (int zz = std::max(0, z - 1); zz <= std::min(dims_[2] - 1, z + 1); ++zz)
            for (int yy = std::max(0, y - 1); yy <= std::min(dims_[1] - 1, y + 1); ++yy)
                for (int xx = std::max(0, x - 1); xx <= std::min(dims_[0] - 1, x + 1); ++xx)
                    near_stamp_[(static_cast<std::size_t>(zz) * dims_[1] + yy) * dims_[0] + xx] = stamp_;
    }

    // 5. frozen when at rest and not near anything moving, let go when something moving comes near
    frozen_spheres_ = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const bool freeze = sphere_motion[i] == Motion::held ||
                            (sphere_motion[i] == Motion::resting && near_stamp_[cell_index(p.position_m[i])] != stamp_);
        if (freeze != (p.frozen[i] != 0)) dem.set_frozen(i, freeze);
        frozen_spheres_ += freeze ? 1 : 0;
    }
    frozen_rocks_ = 0;
    for (std::size_t k = 0; k < rocks.size(); ++k) {
        const RockNow& r = rock_now[k];
        const bool freeze = r.motion == Motion::held ||
                            (r.motion == Motion::resting &&
                             !near(r.centre - Vec3{r.radius, r.radius, r.radius}, r.centre + Vec3{r.radius, r.radius, r.radius}));
        if (freeze != rigid.frozen(rocks[k].body)) {
            rigid.set_frozen(rocks[k].body, freeze);
            dem.set_wall_frozen(r.wall, freeze);
        }
        frozen_rocks_ += freeze ? 1 : 0;
    }
}

template <class IO, class Self>
void DynamicDomain::state_fields(IO& io, Self& s)
{
    io.tag("dynamic-domain");
    io(s.sphere_rest_, s.rock_rest_, s.frozen_spheres_, s.frozen_rocks_);
}

void DynamicDomain::write_state(StateWriter& out) const { state_fields(out, *this); }

void DynamicDomain::read_state(StateReader& in)
{
    state_fields(in, *this);
    for (const auto* v : {&sphere_rest_, &rock_rest_})
        for (const Rest& r : *v) {
            for (double t : {r.time_s, r.older_s, r.newer_s})
                if (!(t >= 0.0) || !std::isfinite(t)) in.fail(concat("a time at rest of ", t, " s; expected a finite value >= 0"));
            for (const Vec3& x : {r.anchor_m, r.older_m, r.newer_m})
                if (!(std::abs(x.x) <= kNowhere && std::abs(x.y) <= kNowhere && std::abs(x.z) <= kNowhere))
                    in.fail(concat("a body's place at rest at (", x.x, ", ", x.y, ", ", x.z, ") m; expected finite coordinates"));
            if (static_cast<int>(r.motion) > static_cast<int>(Motion::held))
                in.fail(concat("a body's motion ", static_cast<int>(r.motion), "; expected 0, 1, 2 or 3"));
        }
    held_bodies_ = 0;
    for (const auto* v : {&sphere_rest_, &rock_rest_})
        for (const Rest& r : *v) held_bodies_ += r.motion == Motion::held ? 1 : 0;
}

void DynamicDomain::hold(CoupledWorld& coupled, const std::vector<std::size_t>& spheres, const std::vector<std::size_t>& rocks)
{
    dem::World& dem = coupled.dem();
    const dem::ParticleStore& p = dem.particles();
    for (std::size_t i : spheres) {
        if (i >= p.size()) throw InputError(concat("hold: sphere index ", i, " of ", p.size()));
        const std::uint32_t id = p.id[i];
        if (sphere_rest_.size() <= id) sphere_rest_.resize(static_cast<std::size_t>(id) + 1);
        Rest& rest = sphere_rest_[id];
        if (rest.motion == Motion::held) continue;
        rest.motion = Motion::held;
        ++held_bodies_;
        if (!p.frozen[i]) {
            dem.set_frozen(i, true);
            ++frozen_spheres_;
        }
    }
    const std::vector<RockRecord>& all = coupled.rocks();
    if (rock_rest_.size() < all.size()) rock_rest_.resize(all.size());
    for (std::size_t k : rocks) {
        if (k >= all.size()) throw InputError(concat("hold: rock index ", k, " of ", all.size()));
        Rest& rest = rock_rest_[k];
        if (rest.motion == Motion::held) continue;
        rest.motion = Motion::held;
        ++held_bodies_;
        if (!coupled.rigid().frozen(all[k].body)) {
            coupled.rigid().set_frozen(all[k].body, true);
            dem.set_wall_frozen(coupled.body(coupled.index_of(all[k].body)).wall, true);
            ++frozen_rocks_;
        }
    }
}

}  // namespace dipper::coupling
