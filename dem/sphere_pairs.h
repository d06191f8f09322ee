// The sphere pairs within reach of each other: the half neighbour list with the history of the touching pairs,
// their forces (DESIGN 1.1) and the per-thread sums the step gathers.
#pragma once

#include "core/state_io.h"
#include "core/vec3.h"
#include "dem/contact_law.h"
#include "dem/material.h"
#include "dem/particle_store.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace dipper::dem {

/// One touching sphere pair, for inspection and output.
struct PairContactView {
    std::uint32_t id_a = 0, id_b = 0;  ///< stable particle ids
    double overlap_m = 0.0;
    ContactHistory history;            ///< as seen from particle a
};

/// The cells the neighbour search bins the particles into; the particles are sorted by cell.
struct CellGrid {
    Vec3 lo;
    double cell = 0.0;
    int dims[3] = {1, 1, 1};
    std::vector<std::uint32_t> cell_start;  ///< the particles of cell c are [cell_start[c], cell_start[c + 1])

    /// The grid over the positions' bounding box, cells at least min_cell_m wide (coarser where the particles
    /// are sparse: at most max(64, 4 n) cells), and in `order` the particles sorted by cell (a stable counting
    /// sort: order[k] is the k-th particle in cell order) with cell_start counted for that order.
    static CellGrid sorting(const std::vector<Vec3>& positions, double min_cell_m, std::vector<std::uint32_t>& order);

    std::uint32_t cell_of(const Vec3& p) const
    {
        int c[3];
        for (int a = 0; a < 3; ++a) c[a] = std::clamp(static_cast<int>((p[a] - lo[a]) / cell), 0, dims[a] - 1);
        return static_cast<std::uint32_t>((static_cast<std::size_t>(c[2]) * dims[1] + c[1]) * dims[0] + c[0]);
    }
};

/// Contiguous block [begin, end) of n items for thread t of T: each thread's output stays in index order, so
/// concatenating per-thread results gives the same sequence for any thread count.
inline void thread_block(std::size_t n, int t, int threads, std::size_t& begin, std::size_t& end)
{
    begin = n * static_cast<std::size_t>(t) / static_cast<std::size_t>(threads);
    end = n * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(threads);
}

/// Pairs (i, j), i < j, sorted by i then j, closer than r_i + r_j + skin when the list was made.
class SpherePairs {
public:
    /// The list for particles sorted by cell in `grid`. The touching pairs of the old list keep their history
    /// (old particle k is now old_to_new[k]; a particle past its end is gone); pairs out of range have separated.
    void rebuild(const ParticleStore& p, const CellGrid& grid, double skin_m, const std::vector<std::uint32_t>& old_to_new, int threads);

    /// The forces of the touching pairs, each thread's block of pairs into its own arrays (same thread count, same
    /// bits); the springs into the history. A pair of two frozen particles keeps its contact as it was and is passed
    /// over: the pairs left are found again when the list or `frozen_version` (which counts changes of the
    /// particles' frozen flags) changes. Returns the largest overlap over the smaller radius.
    double compute_forces(const ParticleStore& p, const std::vector<double>& stiffness_radius_N_per_m, const MaterialTable& materials,
                          double dt_s, int threads, std::uint64_t frozen_version);
    /// Adds the pairs' force and torque on particle i to `force` and `torque` in thread order, and clears them
    /// for the next step while in cache. Each particle is taken by one thread; gathered() follows the last.
    void take(std::size_t i, Vec3& force, Vec3& torque)
    {
        for (std::size_t t = 0; t < thread_force_N_.size(); ++t) {
            if (i < thread_touched_[t].begin || i >= thread_touched_[t].end) continue;
            force += thread_force_N_[t][i];
            torque += thread_torque_N_m_[t][i];
            thread_force_N_[t][i] = Vec3{};
            thread_torque_N_m_[t][i] = Vec3{};
        }
    }
    /// Under RollingResistance::own_spin: adds the pairs' sum of mu_roll r_i Fn on particle i (the torque
    /// that resists its spin) to `spin_resistance`, in thread order, and clears it. Before take(i, ...).
    void take_spin_resistance(std::size_t i, double& spin_resistance)
    {
        for (std::size_t t = 0; t < thread_spin_N_m_.size(); ++t) {
            if (i < thread_touched_[t].begin || i >= thread_touched_[t].end) continue;
            spin_resistance += thread_spin_N_m_[t][i];
            thread_spin_N_m_[t][i] = 0.0;
        }
    }
    void gathered() { forces_clear_ = true; }

    std::size_t size() const { return pair_i_.size(); }
    std::uint32_t first(std::size_t k) const { return pair_i_[k]; }
    std::uint32_t second(std::size_t k) const { return pair_j_[k]; }
    std::size_t contact_count() const;
    /// The touching pairs by particle ids (a < b), sorted.
    std::vector<PairContactView> contacts(const ParticleStore& p) const;

    void write_state(StateWriter& out) const;
    /// Refuses a pair that names one of more than `particles` particles.
    void read_state(StateReader& in, std::size_t particles);

private:
    template <class IO, class Self>
    static void state_fields(IO& io, Self& s);
    std::vector<std::uint32_t> pair_i_, pair_j_;
    std::vector<ContactHistory> history_;
    std::vector<std::uint8_t> touching_;
    // forces and torques each thread's pairs add up, per particle; the gather adds them in thread order
    std::vector<std::vector<Vec3>> thread_force_N_, thread_torque_N_m_;
    std::vector<std::vector<double>> thread_spin_N_m_;  ///< under own_spin: sum of mu_roll r Fn, per particle
    /// The particles each thread's block of pairs touches: its force arrays hold sums there, and nothing elsewhere.
    struct ParticleRange { std::uint32_t begin = 0, end = 0; };
    std::vector<ParticleRange> thread_touched_;
    std::uint64_t version_ = 0;                             ///< counts changes of the list
    std::uint64_t touched_ranges_version_ = ~std::uint64_t{0};  ///< the list thread_touched_ was found for
    /// the pairs compute_forces works on when some particle is frozen, in order: all but those of two frozen particles
    std::vector<std::uint32_t> live_;
    bool all_live_ = true;                                      ///< no pair of two frozen particles: live_ is not used
    std::uint64_t live_version_ = ~std::uint64_t{0}, live_frozen_version_ = ~std::uint64_t{0};  ///< what live_ was found for
    bool forces_clear_ = false;  ///< every per-thread force array is all zero (the gather clears what it reads)
};

}  // namespace dipper::dem
