#include "dem/sphere_pairs.h"

#include "core/errors.h"
#include "dem/pair_batch.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <omp.h>

namespace dipper::dem {

CellGrid CellGrid::sorting(const std::vector<Vec3>& positions, double min_cell_m, std::vector<std::uint32_t>& order)
{
    const std::size_t n = positions.size();
    Vec3 lo{0.0, 0.0, 0.0}, hi{0.0, 0.0, 0.0};
    if (n > 0) {
        lo = hi = positions[0];
        for (const Vec3& p : positions) {
            lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
            hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
        }
    }
    CellGrid grid;
    grid.lo = lo;
    double& cell = grid.cell;
    cell = std::max(min_cell_m, 1e-12);
    int* dims = grid.dims;
    const std::size_t max_cells = std::max<std::size_t>(64, 4 * n);
    for (;;) {
        // counted in doubles: a particle thrown far away must not overflow the cell count
        double total = 1.0;
        for (int a = 0; a < 3; ++a) total *= std::floor((hi[a] - lo[a]) / cell) + 1.0;
        if (total <= static_cast<double>(max_cells)) break;
        cell *= std::max(1.25, std::cbrt(total / static_cast<double>(max_cells)));  // sparse: coarser cells
    }
    for (int a = 0; a < 3; ++a) dims[a] = static_cast<int>(std::floor((hi[a] - lo[a]) / cell)) + 1;
    const std::size_t cell_count = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];

    // sort particles by cell (counting sort, stable) for memory locality
    std::vector<std::uint32_t>& cell_start = grid.cell_start;
    cell_start.assign(cell_count + 1, 0);
    std::vector<std::uint32_t> particle_cell(n);
    order.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
        particle_cell[i] = grid.cell_of(positions[i]);
        ++cell_start[particle_cell[i] + 1];
    }
    std::partial_sum(cell_start.begin(), cell_start.end(), cell_start.begin());
    {
        std::vector<std::uint32_t> fill(cell_start.begin(), cell_start.end() - 1);
        for (std::size_t i = 0; i < n; ++i) order[fill[particle_cell[i]]++] = static_cast<std::uint32_t>(i);
    }
    return grid;
}

void SpherePairs::rebuild(const ParticleStore& p, const CellGrid& grid, double skin_m, const std::vector<std::uint32_t>& old_to_new, int threads)
{
    const std::size_t n = p.size();
    // carry the history of touching pairs over, renumbered and oriented so that i < j
    struct Carried { std::uint32_t i, j; ContactHistory history; std::uint8_t touching; };
    std::vector<Carried> carried;
    for (std::size_t k = 0; k < pair_i_.size(); ++k) {
        if (!touching_[k]) continue;
        if (pair_i_[k] >= n || pair_j_[k] >= n) continue;
        std::uint32_t a = old_to_new[pair_i_[k]], b = old_to_new[pair_j_[k]];
        ContactHistory h = history_[k];
        if (a > b) {  // seen from the other particle: both springs change sign
            std::swap(a, b);
            h.tangential_spring_m = -h.tangential_spring_m;
            h.rolling_torque_N_m = -h.rolling_torque_N_m;
        }
        carried.push_back({a, b, h, 1});
    }
    std::sort(carried.begin(), carried.end(),
              [](const Carried& a, const Carried& b) { return a.i != b.i ? a.i < b.i : a.j < b.j; });

    // new half list: j > i within range r_i + r_j + skin, cells visited in increasing index so j ascends
    std::vector<std::vector<std::uint32_t>> thread_i(static_cast<std::size_t>(threads)), thread_j(thread_i.size());
#pragma omp parallel num_threads(threads)
    {
        const int t = omp_get_thread_num();
        std::size_t begin, end;
        thread_block(n, t, threads, begin, end);
        // filled as locals and moved in at the end: the vectors' headers share a cache line (as below)
        std::vector<std::uint32_t> out_i, out_j;
        for (std::size_t i = begin; i < end; ++i) {
            const Vec3 xi = p.position_m[i];
            const double ri = p.radius_m[i];
            const std::uint32_t own = grid.cell_of(xi);
            const int cx = static_cast<int>(own % static_cast<std::uint32_t>(grid.dims[0]));
            const int cy = static_cast<int>((own / static_cast<std::uint32_t>(grid.dims[0])) % static_cast<std::uint32_t>(grid.dims[1]));
            const int cz = static_cast<int>(own / (static_cast<std::uint32_t>(grid.dims[0]) * static_cast<std::uint32_t>(grid.dims[1])));
            for (int dz = -1; dz <= 1; ++dz) {
                const int z = cz + dz;
                if (z < 0 || z >= grid.dims[2]) continue;
                for (int dy = -1; dy <= 1; ++dy) {
                    const int y = cy + dy;
                    if (y < 0 || y >= grid.dims[1]) continue;
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int xcell = cx + dx;
                        if (xcell < 0 || xcell >= grid.dims[0]) continue;
                        const std::uint32_t c = static_cast<std::uint32_t>((static_cast<std::size_t>(z) * grid.dims[1] + y) * grid.dims[0] + xcell);
                        if (c < own) continue;
                        for (std::uint32_t j = std::max<std::uint32_t>(grid.cell_start[c], static_cast<std::uint32_t>(i + 1));
                             j < grid.cell_start[c + 1]; ++j) {
                            const double range = ri + p.radius_m[j] + skin_m;
                            if (norm_squared(p.position_m[j] - xi) < range * range) {
                                out_i.push_back(static_cast<std::uint32_t>(i));
                                out_j.push_back(j);
                            }
                        }
                    }
                }
            }
        }
        thread_i[static_cast<std::size_t>(t)] = std::move(out_i);
        thread_j[static_cast<std::size_t>(t)] = std::move(out_j);
    }
    pair_i_.clear();
    pair_j_.clear();
    for (std::size_t t = 0; t < thread_i.size(); ++t) {
        pair_i_.insert(pair_i_.end(), thread_i[t].begin(), thread_i[t].end());
        pair_j_.insert(pair_j_.end(), thread_j[t].begin(), thread_j[t].end());
    }
    ++version_;
    const std::size_t pairs = pair_i_.size();
    history_.assign(pairs, ContactHistory{});
    touching_.assign(pairs, 0);

    // merge the carried history into the new list (both sorted by (i, j))
    {
        std::size_t c = 0;
        for (std::size_t k = 0; k < pairs && c < carried.size(); ++k) {
            while (c < carried.size() && (carried[c].i < pair_i_[k] || (carried[c].i == pair_i_[k] && carried[c].j < pair_j_[k])))
                ++c;  // a pair that drifted out of range has separated: its history ends
            if (c < carried.size() && carried[c].i == pair_i_[k] && carried[c].j == pair_j_[k]) {
                history_[k] = carried[c].history;
                touching_[k] = 1;
                ++c;
            }
        }
    }
}

double SpherePairs::compute_forces(const ParticleStore& p, const std::vector<double>& stiffness_radius_N_per_m, const MaterialTable& materials,
                                   double dt_s, int threads, std::uint64_t frozen_version)
{
    const std::size_t pairs = pair_i_.size();
    const std::size_t n = p.size();
    // raw pointers: the writes to the force arrays cannot alias the inputs
    const Vec3* __restrict x = p.position_m.data();
    const Vec3* __restrict v = p.velocity_m_per_s.data();
    const Vec3* __restrict w = p.angular_velocity_rad_per_s.data();
    const double* __restrict r = p.radius_m.data();
    const double* __restrict m = p.mass_kg.data();
    const MaterialIndex* __restrict mat = p.material.data();
    const std::uint8_t* __restrict frozen = p.frozen.data();
    const double* __restrict kr = stiffness_radius_N_per_m.data();
    const std::uint32_t* __restrict pi = pair_i_.data();
    const std::uint32_t* __restrict pj = pair_j_.data();
    std::uint8_t* __restrict touching = touching_.data();
    ContactHistory* __restrict history = history_.data();
    const MaterialTable& table = materials;
    const RollingResistance rolling = table.rolling_resistance();
    const bool own_spin = rolling == RollingResistance::own_spin;
    double max_ratio = 0.0;
    thread_force_N_.resize(static_cast<std::size_t>(threads));
    thread_torque_N_m_.resize(static_cast<std::size_t>(threads));
    thread_spin_N_m_.resize(own_spin ? static_cast<std::size_t>(threads) : 0);
    const bool ranges_stale = touched_ranges_version_ != version_ || thread_touched_.size() != static_cast<std::size_t>(threads);
    if (thread_touched_.size() != static_cast<std::size_t>(threads)) forces_clear_ = false;
    thread_touched_.resize(static_cast<std::size_t>(threads));
    touched_ranges_version_ = version_;
    // Two frozen particles keep their contact as it was: in a bed frozen to nine tenths such pairs are most of the
    // list, and the pass goes over the others only (each thread over those in its block, so the same bits).
    if (live_version_ != version_ || live_frozen_version_ != frozen_version) {
        live_version_ = version_;
        live_frozen_version_ = frozen_version;
        live_.clear();
        for (std::size_t k = 0; k < pairs; ++k)
            if (!(frozen[pi[k]] & frozen[pj[k]])) live_.push_back(static_cast<std::uint32_t>(k));
        all_live_ = live_.size() == pairs;
        if (all_live_) live_.clear();
    }

    // Each thread takes a fixed block of pairs and adds both particles' shares into its own arrays; the
    // gather adds the threads' arrays in thread order. Same thread count, same bits.
#pragma omp parallel num_threads(threads) reduction(max : max_ratio)
    {
        const int t = omp_get_thread_num();
        std::size_t begin, end;
        thread_block(pairs, t, threads, begin, end);
        // The thread's pairs touch only particles lo..hi-1 (particles are ordered by cell, so a block of pairs
        // spans a block of particles): only that range of its arrays is cleared here and read by the gather.
        // Found once per neighbour list.
        if (ranges_stale) {
            std::uint32_t lo = std::numeric_limits<std::uint32_t>::max(), hi = 0;
            for (std::size_t k = begin; k < end; ++k) {
                lo = std::min(lo, std::min(pi[k], pj[k]));
                hi = std::max(hi, std::max(pi[k], pj[k]));
            }
            thread_touched_[static_cast<std::size_t>(t)] = begin < end ? ParticleRange{lo, hi + 1} : ParticleRange{0, 0};
        }
        auto& thread_force = thread_force_N_[static_cast<std::size_t>(t)];
        auto& thread_torque = thread_torque_N_m_[static_cast<std::size_t>(t)];
        if (thread_force.size() != n) thread_force.resize(n);
        if (thread_torque.size() != n) thread_torque.resize(n);
        Vec3* __restrict force = thread_force.data();
        Vec3* __restrict torque = thread_torque.data();
        double* __restrict spin = nullptr;
        if (own_spin) {
            auto& thread_spin = thread_spin_N_m_[static_cast<std::size_t>(t)];
            if (thread_spin.size() != n) thread_spin.assign(n, 0.0);
            if (!forces_clear_) std::fill(thread_spin.begin(), thread_spin.end(), 0.0);
            spin = thread_spin.data();
        }
        // the gather leaves every element it reads at zero; only after an interrupted step are they cleared here
        if (!forces_clear_) {
            std::fill(thread_force.begin(), thread_force.end(), Vec3{});
            std::fill(thread_torque.begin(), thread_torque.end(), Vec3{});
        }
        double local_max = 0.0;
        PairBatch batch;  // the touching pairs, gathered for the SIMD law and scattered after it
        double spin_lever_i[PairBatch::kCapacity], spin_lever_j[PairBatch::kCapacity];  // own_spin: mu_roll r_i, mu_roll r_j
        double memo_spin_i = 0.0, memo_spin_j = 0.0;

        // forces of the gathered pairs into the thread's arrays, springs back into the pair history
        auto flush = [&]() {
            local_max = std::max(local_max, evaluate_pair_batch(batch, dt_s));
            for (int c = 0; c < batch.count; ++c) {
                const std::uint32_t i = batch.i[c], j = batch.j[c];
                const Vec3 fi{batch.fx[c], batch.fy[c], batch.fz[c]};
                force[i] += fi;
                force[j] -= fi;
                torque[i] += Vec3{batch.tix[c], batch.tiy[c], batch.tiz[c]};
                torque[j] += Vec3{batch.tjx[c], batch.tjy[c], batch.tjz[c]};
                if (own_spin) {
                    spin[i] += spin_lever_i[c] * batch.fn[c];
                    spin[j] += spin_lever_j[c] * batch.fn[c];
                }
                history[batch.pair[c]] = {{batch.sx[c], batch.sy[c], batch.sz[c]}, {batch.mx[c], batch.my[c], batch.mz[c]}};
            }
            batch.count = 0;
        };

        ContactConstants memo;
        double memo_share_i = 0.5;
        double memo_ri = -1.0, memo_rj = -1.0, memo_mi = -1.0, memo_mj = -1.0;
        MaterialIndex memo_a = 0, memo_b = 0;
        const std::size_t live_begin = all_live_ ? begin : static_cast<std::size_t>(std::lower_bound(live_.begin(), live_.end(), begin) - live_.begin());
        const std::size_t live_end = all_live_ ? end : static_cast<std::size_t>(std::lower_bound(live_.begin(), live_.end(), end) - live_.begin());
        for (std::size_t q = live_begin; q < live_end; ++q) {
            const std::size_t k = all_live_ ? q : live_[q];
            const std::uint32_t i = pi[k], j = pj[k];
            const Vec3 d = x[i] - x[j];
            const double dist2 = norm_squared(d);
            const double rsum = r[i] + r[j];
            if (dist2 >= rsum * rsum) {
                if (touching[k]) {  // separated: the history of this contact ends
                    touching[k] = 0;
                    history[k] = ContactHistory{};
                }
                continue;
            }
            touching[k] = 1;

            // constants of the pair (eq. 4, 6, 8), recomputed only when the pair's kind changes: in a bed of
            // one size and material they are computed once per thread and step
            if (r[i] != memo_ri || r[j] != memo_rj || mat[i] != memo_a || mat[j] != memo_b || m[i] != memo_mi || m[j] != memo_mj) {
                memo_ri = r[i]; memo_rj = r[j]; memo_a = mat[i]; memo_b = mat[j]; memo_mi = m[i]; memo_mj = m[j];
                const double kr_sum = kr[i] + kr[j], m_sum = m[i] + m[j];
                const PairCoefficients& coefficients = table.pair_unchecked(mat[i], mat[j]);
                memo = contact_constants(kr[i] * kr[j] / kr_sum * coefficients.normal_stiffness_scale, m[i] * m[j] / m_sum,
                                         r[i] * r[j] / rsum, law_coefficients(coefficients, rolling));
                memo_spin_i = coefficients.rolling_friction * r[i];
                memo_spin_j = coefficients.rolling_friction * r[j];
                // The two springs k1 r1 and k2 r2 in series share the overlap in proportion to their
                // compliances: the contact point lies half-way for equal spheres and on the surface of a much
                // stiffer body (the wall limit).
                memo_share_i = kr[j] / kr_sum;
            }
            const int c = batch.count++;
            batch.pair[c] = static_cast<std::uint32_t>(k);
            batch.i[c] = i;
            batch.j[c] = j;
            batch.dx[c] = d.x; batch.dy[c] = d.y; batch.dz[c] = d.z;
            batch.distance2[c] = dist2;
            batch.ri[c] = r[i];
            batch.rj[c] = r[j];
            batch.share_i[c] = memo_share_i;
            const Vec3 dv = v[i] - v[j];
            batch.dvx[c] = dv.x; batch.dvy[c] = dv.y; batch.dvz[c] = dv.z;
            batch.wix[c] = w[i].x; batch.wiy[c] = w[i].y; batch.wiz[c] = w[i].z;
            batch.wjx[c] = w[j].x; batch.wjy[c] = w[j].y; batch.wjz[c] = w[j].z;
            batch.set_constants(c, memo);
            spin_lever_i[c] = memo_spin_i;
            spin_lever_j[c] = memo_spin_j;
            const ContactHistory& h = history[k];
            batch.sx[c] = h.tangential_spring_m.x; batch.sy[c] = h.tangential_spring_m.y; batch.sz[c] = h.tangential_spring_m.z;
            batch.mx[c] = h.rolling_torque_N_m.x; batch.my[c] = h.rolling_torque_N_m.y; batch.mz[c] = h.rolling_torque_N_m.z;
            if (batch.count == PairBatch::kCapacity) flush();
        }
        flush();
        max_ratio = std::max(max_ratio, local_max);
    }
    forces_clear_ = false;  // until the gather has read them
    return max_ratio;
}

std::size_t SpherePairs::contact_count() const
{
    std::size_t count = 0;
    for (std::uint8_t t : touching_) count += t;
    return count;
}

std::vector<PairContactView> SpherePairs::contacts(const ParticleStore& p) const
{
    std::vector<PairContactView> out;
    for (std::size_t k = 0; k < pair_i_.size(); ++k) {
        if (!touching_[k]) continue;
        const std::uint32_t i = pair_i_[k], j = pair_j_[k];
        PairContactView c;
        c.id_a = p.id[i];
        c.id_b = p.id[j];
        c.overlap_m = p.radius_m[i] + p.radius_m[j] - norm(p.position_m[i] - p.position_m[j]);
        c.history = history_[k];
        if (c.id_a > c.id_b) {
            std::swap(c.id_a, c.id_b);
            c.history.tangential_spring_m = -c.history.tangential_spring_m;
            c.history.rolling_torque_N_m = -c.history.rolling_torque_N_m;
        }
        out.push_back(c);
    }
    std::sort(out.begin(), out.end(), [](const PairContactView& a, const PairContactView& b) {
        return a.id_a != b.id_a ? a.id_a < b.id_a : a.id_b < b.id_b;
    });
    return out;
}

template <class IO, class Self>
void SpherePairs::state_fields(IO& io, Self& s)
{
    io(s.pair_i_, s.pair_j_, s.history_, s.touching_);
}

void SpherePairs::write_state(StateWriter& out) const { state_fields(out, *this); }

void SpherePairs::read_state(StateReader& in, std::size_t particles)
{
    state_fields(in, *this);
    ++version_;
    // indices must stay inside the arrays they index (a corrupt file must not crash the run)
    if (pair_j_.size() != pair_i_.size() || history_.size() != pair_i_.size() || touching_.size() != pair_i_.size())
        in.fail("neighbour arrays of different lengths");
    for (std::size_t k = 0; k < pair_i_.size(); ++k)
        if (pair_i_[k] >= particles || pair_j_[k] >= particles) in.fail("a neighbour pair names a particle that does not exist");
}

}  // namespace dipper::dem
