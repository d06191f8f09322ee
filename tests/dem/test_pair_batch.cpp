// The batched (SIMD) sphere-pair law against the scalar law it must reproduce bit for bit.
#include "dem/pair_batch.h"

#include <catch2/catch.hpp>

#include <random>

using namespace dipper;
using namespace dipper::dem;

namespace {

struct Lane {
    Vec3 d, dv, wi, wj;
    double ri = 0.0, rj = 0.0, share_i = 0.5;
    ContactConstants k;
    ContactHistory h;
};

struct Expected {
    Vec3 force, torque_i, torque_j;
    ContactHistory h;
    double ratio = 0.0;
};

/// The pair geometry written out with Vec3 operations, in the order pair_batch.h documents.
Expected scalar_reference(Lane lane, double dt_s)
{
    Expected e;
    const double dist = std::sqrt(norm_squared(lane.d));
    const Vec3 n = dist > 0.0 ? lane.d * (1.0 / dist) : Vec3{0.0, 0.0, 1.0};
    const double overlap = (lane.ri + lane.rj) - dist;
    e.ratio = overlap / std::min(lane.ri, lane.rj);
    const double deflection_i = lane.share_i * overlap;
    const double a_i = lane.ri - deflection_i, a_j = lane.rj - (overlap - deflection_i);
    // the contact-point velocity from both arms, v_i + w_i x (-a_i n) - (v_j + w_j x (a_j n)), gathered into
    // one cross product: equal to round-off, and written so in the batch
    const Vec3 velocity = lane.dv - cross(lane.wi * a_i + lane.wj * a_j, n);
    const ContactForces f = linear_spring_dashpot(overlap, n, velocity, lane.wi - lane.wj, lane.k, lane.h, dt_s);
    e.force = n * f.normal_force_N + f.tangential_force_N;
    e.torque_i = f.rolling_torque_N_m - cross(n, f.tangential_force_N) * a_i;
    e.torque_j = -(f.rolling_torque_N_m + cross(n, f.tangential_force_N) * a_j);
    e.h = lane.h;
    return e;
}

}  // namespace

TEST_CASE("the batched pair law gives the scalar law's bits", "[dem][unit]")
{
    // Random touching pairs of Table 2 ore-like constants: sticking and sliding tangential springs, rolling
    // springs below and at their limit, a spring turned far out of the tangent plane (the closed-form
    // branch), zero history, coincident centres, unequal spheres and stiffness shares. Every output must
    // equal the scalar form exactly: the batch is the same arithmetic in the same order, without FMA.
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    auto vec = [&](double s) { return Vec3{u(rng), u(rng), u(rng)} * s; };
    const double dt = 5e-5;
    std::vector<Lane> lanes;
    for (int c = 0; c < 3 * PairBatch::kCapacity + 5; ++c) {
        Lane l;
        l.ri = 0.1 * (1.0 + 0.5 * (c % 3));
        l.rj = 0.1 * (1.0 + 0.25 * (c % 5));
        const double overlap = 1e-4 * (1.0 + u(rng)) + 1e-7;
        l.d = normalized(vec(1.0) + Vec3{0.0, 0.0, 1e-3}) * (l.ri + l.rj - overlap);
        if (c == 17) l.d = Vec3{};  // coincident centres
        l.share_i = 0.5 + 0.4 * u(rng);
        l.dv = vec(c % 4 == 0 ? 2.0 : 1e-3);  // every fourth slides
        l.wi = vec(c % 6 == 0 ? 30.0 : 0.05);
        l.wj = vec(0.05);
        const double kn = 1e8 * (1.0 + 0.5 * u(rng));
        l.k = contact_constants(kn, 5.0 + u(rng), l.ri * l.rj / (l.ri + l.rj), table2::ore_ore);
        if (c % 7 != 0) l.h = {vec(1e-5), vec(c % 3 == 0 ? 1e3 : 1e-2)};  // every third rolling spring beyond its limit
        if (c == 11) l.h.tangential_spring_m = Vec3{0.0, 0.0, 1e-5} + vec(1e-6);  // mostly along the normal
        lanes.push_back(l);
    }

    std::size_t checked = 0;
    int sliding = 0, rolling_limited = 0;
    for (std::size_t start = 0; start < lanes.size(); start += PairBatch::kCapacity) {
        PairBatch b;
        b.count = static_cast<int>(std::min<std::size_t>(PairBatch::kCapacity, lanes.size() - start));
        for (int c = 0; c < b.count; ++c) {
            const Lane& l = lanes[start + static_cast<std::size_t>(c)];
            b.dx[c] = l.d.x; b.dy[c] = l.d.y; b.dz[c] = l.d.z;
            b.distance2[c] = norm_squared(l.d);
            b.ri[c] = l.ri; b.rj[c] = l.rj; b.share_i[c] = l.share_i;
            b.dvx[c] = l.dv.x; b.dvy[c] = l.dv.y; b.dvz[c] = l.dv.z;
            b.wix[c] = l.wi.x; b.wiy[c] = l.wi.y; b.wiz[c] = l.wi.z;
            b.wjx[c] = l.wj.x; b.wjy[c] = l.wj.y; b.wjz[c] = l.wj.z;
            b.set_constants(c, l.k);
            b.sx[c] = l.h.tangential_spring_m.x; b.sy[c] = l.h.tangential_spring_m.y; b.sz[c] = l.h.tangential_spring_m.z;
            b.mx[c] = l.h.rolling_torque_N_m.x; b.my[c] = l.h.rolling_torque_N_m.y; b.mz[c] = l.h.rolling_torque_N_m.z;
        }
        const double max_ratio = evaluate_pair_batch(b, dt);
        double expected_max = 0.0;
        for (int c = 0; c < b.count; ++c) {
            const Lane& l = lanes[start + static_cast<std::size_t>(c)];
            const Expected e = scalar_reference(l, dt);
            expected_max = std::max(expected_max, e.ratio);
            CAPTURE(start + static_cast<std::size_t>(c));
            CHECK(Vec3{b.fx[c], b.fy[c], b.fz[c]} == e.force);
            CHECK(Vec3{b.tix[c], b.tiy[c], b.tiz[c]} == e.torque_i);
            CHECK(Vec3{b.tjx[c], b.tjy[c], b.tjz[c]} == e.torque_j);
            CHECK(Vec3{b.sx[c], b.sy[c], b.sz[c]} == e.h.tangential_spring_m);
            CHECK(Vec3{b.mx[c], b.my[c], b.mz[c]} == e.h.rolling_torque_N_m);
            // the cases the lanes were built to cover did occur
            CHECK(is_finite(e.force));
            const Vec3 n = l.d == Vec3{} ? Vec3{0, 0, 1} : normalized(l.d);
            const double normal_part = dot(e.force, n);
            const Vec3 tangential = e.force - n * normal_part;
            if (norm(tangential) >= 0.9 * 0.999999 * normal_part) ++sliding;
            if (norm(e.h.rolling_torque_N_m) > 0.0 &&
                norm(e.h.rolling_torque_N_m) >= 0.999999 * l.k.rolling_limit_m * std::max(0.0, normal_part))
                ++rolling_limited;
            ++checked;
        }
        CHECK(max_ratio == expected_max);
    }
    CHECK(checked == lanes.size());
    CHECK(sliding > 20);
    CHECK(rolling_limited > 20);
}
