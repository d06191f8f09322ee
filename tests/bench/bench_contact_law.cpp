// Cost of one evaluation of the contact law (Google Benchmark): a resting contact, a sliding contact,
// the same through the convenience overload that recomputes the pair constants, and sphere pairs through
// the batched (SIMD) form the pair loop uses, geometry and torques included.
#include "dem/contact_law.h"
#include "dem/pair_batch.h"

#include <benchmark/benchmark.h>

#include <vector>

using namespace dipper;
using namespace dipper::dem;

namespace {

constexpr std::size_t kContacts = 4096;

struct Batch {
    std::vector<Vec3> normal, velocity, spin;
    std::vector<double> overlap;
    std::vector<ContactHistory> history;
};

/// Table 2 ore pairs of 0.1 m spheres with small random-looking motions (sliding when `slide`).
Batch make_batch(bool slide)
{
    Batch b;
    for (std::size_t k = 0; k < kContacts; ++k) {
        const double a = 0.001 * static_cast<double>(k);
        b.normal.push_back(normalized(Vec3{std::sin(a), std::cos(3.0 * a), 1.0}));
        b.velocity.push_back(Vec3{1e-3 * std::cos(a), 1e-3 * std::sin(a), -1e-4} * (slide ? 500.0 : 1.0));
        b.spin.push_back(Vec3{0.01 * std::sin(5.0 * a), 0.02, 0.0});
        b.overlap.push_back(1e-5 * (1.0 + 0.5 * std::sin(7.0 * a)));
        b.history.push_back({});
    }
    return b;
}

const PairCoefficients kOre = table2::ore_ore;
const double kKn = pair_normal_stiffness(37.5e9, 0.1, 37.5e9, 0.1, 0.05);
const double kMass = 0.5 * 4.0 / 3.0 * M_PI * 1e-3 * 3700.0;

void run(benchmark::State& state, bool slide, bool rolling = true)
{
    Batch b = make_batch(slide);
    PairCoefficients pair = kOre;
    if (!rolling) pair.rolling_friction = 0.0;
    const ContactConstants k = contact_constants(kKn, kMass, 0.05, pair);
    for (auto _ : state) {
        for (std::size_t c = 0; c < kContacts; ++c) {
            const ContactForces f = linear_spring_dashpot(b.overlap[c], b.normal[c], b.velocity[c], b.spin[c], k, b.history[c], 5e-5);
            benchmark::DoNotOptimize(f);
        }
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(kContacts));
}

void BM_RestingContact(benchmark::State& state) { run(state, false); }
void BM_SlidingContact(benchmark::State& state) { run(state, true); }
void BM_RestingContactNoRolling(benchmark::State& state) { run(state, false, false); }

void BM_RestingContactWithConstants(benchmark::State& state)
{
    Batch b = make_batch(false);
    for (auto _ : state) {
        for (std::size_t c = 0; c < kContacts; ++c) {
            ContactState s;
            s.overlap_m = b.overlap[c];
            s.normal = b.normal[c];
            s.relative_velocity_m_per_s = b.velocity[c];
            s.relative_angular_velocity_rad_per_s = b.spin[c];
            s.effective_radius_m = 0.05;
            s.effective_mass_kg = kMass;
            s.normal_stiffness_N_per_m = kKn;
            const ContactForces f = linear_spring_dashpot(s, kOre, b.history[c], 5e-5);
            benchmark::DoNotOptimize(f);
        }
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(kContacts));
}

/// The same contacts as sphere pairs (0.1 m spheres) in batches of PairBatch::kCapacity.
void run_batched(benchmark::State& state, bool slide)
{
    const Batch b = make_batch(slide);
    const ContactConstants k = contact_constants(kKn, kMass, 0.05, kOre);
    std::vector<PairBatch> batches(kContacts / PairBatch::kCapacity);
    for (std::size_t c = 0; c < kContacts; ++c) {
        PairBatch& p = batches[c / PairBatch::kCapacity];
        const int lane = static_cast<int>(c % PairBatch::kCapacity);
        p.count = lane + 1;
        const Vec3 d = b.normal[c] * (0.2 - b.overlap[c]);
        p.dx[lane] = d.x; p.dy[lane] = d.y; p.dz[lane] = d.z;
        p.distance2[lane] = norm_squared(d);
        p.ri[lane] = p.rj[lane] = 0.1;
        p.share_i[lane] = 0.5;
        p.dvx[lane] = b.velocity[c].x; p.dvy[lane] = b.velocity[c].y; p.dvz[lane] = b.velocity[c].z;
        p.wix[lane] = b.spin[c].x; p.wiy[lane] = b.spin[c].y; p.wiz[lane] = b.spin[c].z;
        p.wjx[lane] = p.wjy[lane] = p.wjz[lane] = 0.0;
        p.set_constants(lane, k);
        p.sx[lane] = p.sy[lane] = p.sz[lane] = p.mx[lane] = p.my[lane] = p.mz[lane] = 0.0;
    }
    for (auto _ : state)
        for (PairBatch& p : batches) benchmark::DoNotOptimize(evaluate_pair_batch(p, 5e-5));
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(kContacts));
}

void BM_RestingPairBatched(benchmark::State& state) { run_batched(state, false); }
void BM_SlidingPairBatched(benchmark::State& state) { run_batched(state, true); }

}  // namespace

BENCHMARK(BM_RestingPairBatched);
BENCHMARK(BM_SlidingPairBatched);
BENCHMARK(BM_RestingContact);
BENCHMARK(BM_SlidingContact);
BENCHMARK(BM_RestingContactNoRolling);
BENCHMARK(BM_RestingContactWithConstants);
BENCHMARK_MAIN();
