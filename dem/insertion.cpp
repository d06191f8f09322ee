#include "dem/insertion.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

namespace dipper::dem {

namespace {

/// A hash grid of spheres for overlap checks during insertion.
class SphereHash {
public:
    explicit SphereHash(double cell_m) : cell_(cell_m) {}
    void add(const Vec3& c, double r)
    {
        centres_.push_back(c);
        radii_.push_back(r);
        cells_[key(cell_index(c))].push_back(static_cast<std::uint32_t>(centres_.size() - 1));
    }
    /// True if a sphere (c, r) overlaps none of the stored ones. Stored radii must be <= the cell size.
    bool free(const Vec3& c, double r) const
    {
        const auto base = cell_index(c);
        const int reach = static_cast<int>(std::ceil((r + max_radius_) / cell_));
        for (int dz = -reach; dz <= reach; ++dz)
            for (int dy = -reach; dy <= reach; ++dy)
                for (int dx = -reach; dx <= reach; ++dx) {
                    const auto it = cells_.find(key({base[0] + dx, base[1] + dy, base[2] + dz}));
                    if (it == cells_.end()) continue;
                    for (std::uint32_t k : it->second) {
                        const double d = r + radii_[k];
                        if (norm_squared(centres_[k] - c) < d * d) return false;
                    }
                }
        return true;
    }
    void set_max_radius(double r) { max_radius_ = std::max(max_radius_, r); }

private:
    std::array<long long, 3> cell_index(const Vec3& c) const
    {
        return {static_cast<long long>(std::floor(c.x / cell_)), static_cast<long long>(std::floor(c.y / cell_)),
                static_cast<long long>(std::floor(c.z / cell_))};
    }
    static std::uint64_t key(const std::array<long long, 3>& i)
    {
        return (static_cast<std::uint64_t>(i[0] & 0x1fffff) << 42) | (static_cast<std::uint64_t>(i[1] & 0x1fffff) << 21) |
               static_cast<std::uint64_t>(i[2] & 0x1fffff);
    }
    double cell_, max_radius_ = 0.0;
    std::vector<Vec3> centres_;
    std::vector<double> radii_;
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
};

/// Existing particles that could touch the box [lo, hi].
SphereHash hash_of_existing(const World& world, const Vec3& lo, const Vec3& hi, double cell)
{
    SphereHash hash(cell);
    const auto& p = world.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec3& x = p.position_m[i];
        const double r = p.radius_m[i];
        if (x.x + r < lo.x || x.y + r < lo.y || x.z + r < lo.z || x.x - r > hi.x || x.y - r > hi.y || x.z - r > hi.z) continue;
        hash.set_max_radius(r);
        hash.add(x, r);
    }
    return hash;
}

}  // namespace

void SizeDistribution::validate(const std::string& where) const
{
    if (classes.empty()) throw InputError(concat("size distribution has no classes (", where, ")"));
    double sum = 0.0;
    for (std::size_t c = 0; c < classes.size(); ++c) {
        require_positive(classes[c].radius_m, concat("radius_m of size class ", c), where);
        require_in_range(classes[c].mass_fraction, 0.0, 1.0, concat("mass_fraction of size class ", c), where);
        sum += classes[c].mass_fraction;
    }
    if (std::abs(sum - 1.0) > 1e-6)
        throw InputError(concat("mass fractions of the size distribution sum to ", sum, "; expected 1 (", where, ")"));
}

double SizeDistribution::max_radius_m() const
{
    double r = 0.0;
    for (const SizeClass& c : classes) r = std::max(r, c.radius_m);
    return r;
}

double particles_for_mass(const SizeDistribution& distribution, double density, double total_mass_kg)
{
    double count = 0.0;
    for (const SizeClass& c : distribution.classes) count += c.mass_fraction * total_mass_kg / sphere_mass_kg(c.radius_m, density);
    return count;
}

std::vector<double> radii_for_mass(const SizeDistribution& distribution, double density, double total_mass_kg)
{
    distribution.validate("radii_for_mass");
    require_positive(density, "density_kg_per_m3", "radii_for_mass");
    require_positive(total_mass_kg, "total_mass_kg", "radii_for_mass");
    std::vector<SizeClass> sorted = distribution.classes;
    std::sort(sorted.begin(), sorted.end(), [](const SizeClass& a, const SizeClass& b) { return a.radius_m > b.radius_m; });
    const double total_count = particles_for_mass(distribution, density, total_mass_kg);
    if (!(total_count <= kMaxFillParticles))
        throw InputError(concat(total_mass_kg, " kg of these sizes (the smallest of radius ", sorted.back().radius_m, " m) at ",
                                density, " kg/m3 makes ", total_count, " particles; at most ", kMaxFillParticles,
                                " are made at once: check the mass and the radii"));
    std::vector<double> radii;
    for (const SizeClass& c : sorted) {
        const double m = sphere_mass_kg(c.radius_m, density);
        const auto count = static_cast<std::size_t>(std::llround(c.mass_fraction * total_mass_kg / m));
        radii.insert(radii.end(), count, c.radius_m);
    }
    return radii;
}

void require_mass_fits(double total_mass_kg, double density_kg_per_m3, const Vec3& lo, const Vec3& hi, const std::string& where)
{
    constexpr double kDensestPacking = 0.7405;  // pi / sqrt(18), face-centred cubic
    const Vec3 size = hi - lo;
    const double box_m3 = size.x * size.y * size.z;
    const double solid_m3 = total_mass_kg / density_kg_per_m3;
    if (solid_m3 > kDensestPacking * box_m3)
        throw InputError(concat(where, ": ", total_mass_kg, " kg at ", density_kg_per_m3, " kg/m3 is ", solid_m3,
                                " m3 of solid, more than the box of ", box_m3, " m3 holds even at the densest packing of spheres (",
                                kDensestPacking * box_m3 * density_kg_per_m3, " kg, 74 % solid); a random fill places about half that: ",
                                "make the box larger or the mass smaller"));
}

BoxRegion::BoxRegion(const Vec3& lo, const Vec3& hi) : lo_(lo), hi_(hi)
{
    if (!is_finite(lo) || !is_finite(hi) || !(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
        throw InputError(concat("box region needs finite corners with max > min on every axis; got min (", lo.x, ", ", lo.y,
                                ", ", lo.z, ") max (", hi.x, ", ", hi.y, ", ", hi.z, ")"));
}

bool BoxRegion::holds(const Vec3& c, double r) const
{
    return c.x - r >= lo_.x && c.y - r >= lo_.y && c.z - r >= lo_.z && c.x + r <= hi_.x && c.y + r <= hi_.y && c.z + r <= hi_.z;
}

FillReport fill_random(World& world, const Region& region, const SizeDistribution& distribution, MaterialIndex material,
                       double total_mass_kg, std::uint64_t seed, int attempts_per_particle)
{
    if (material >= world.materials().size() || world.materials().material(material).is_surface)
        throw InputError(concat("fill_random: material index ", material, " is not a particle material"));
    const double density = world.materials().material(material).density_kg_per_m3;
    const Vec3 lo = region.bounds_min_m(), hi = region.bounds_max_m();
    require_mass_fits(total_mass_kg, density, lo, hi, "fill_random");
    const std::vector<double> radii = radii_for_mass(distribution, density, total_mass_kg);
    const double r_max = distribution.max_radius_m();
    SphereHash hash = hash_of_existing(world, lo, hi, 2.0 * r_max);
    hash.set_max_radius(r_max);

    std::mt19937_64 random(seed);
    std::uniform_real_distribution<double> ux(lo.x, hi.x), uy(lo.y, hi.y), uz(lo.z, hi.z);
    FillReport report;
    report.requested = radii.size();
    for (std::size_t k = 0; k < radii.size(); ++k) {
        const double r = radii[k];
        bool placed = false;
        for (int attempt = 0; attempt < attempts_per_particle && !placed; ++attempt) {
            const Vec3 c{ux(random), uy(random), uz(random)};
            if (!region.holds(c, r) || !hash.free(c, r)) continue;
            hash.add(c, r);
            world.add_particle({c, {}, {}, r, material}, concat("fill_random particle ", k));
            report.placed_mass_kg += world.particles().mass_kg.back();
            placed = true;
        }
        if (!placed)
            throw InputError(concat("fill_random: no free place for particle ", k, " of ", radii.size(), " (radius ", r,
                                    " m) after ", attempts_per_particle, " attempts; the region is too small for ",
                                    total_mass_kg, " kg (placed ", report.placed_mass_kg, " kg); use a larger region or less mass"));
        ++report.placed;
    }
    return report;
}

FillReport fill_lattice(World& world, const Vec3& lo, const Vec3& hi, double radius_m, double spacing_m,
                        MaterialIndex material, double jitter_m, std::uint64_t seed)
{
    require_positive(radius_m, "radius_m", "fill_lattice");
    require_non_negative(jitter_m, "jitter_m", "fill_lattice");
    if (!(spacing_m >= 2.0 * radius_m + 2.0 * jitter_m))
        throw InputError(concat("fill_lattice: spacing_m must be >= 2 radius + 2 jitter = ", 2.0 * radius_m + 2.0 * jitter_m,
                                " m so that particles cannot overlap; got ", spacing_m));
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<double> u(-jitter_m, jitter_m);
    FillReport report;
    const double first = radius_m + jitter_m;
    for (double z = lo.z + first; z <= hi.z - first + 1e-12; z += spacing_m)
        for (double y = lo.y + first; y <= hi.y - first + 1e-12; y += spacing_m)
            for (double x = lo.x + first; x <= hi.x - first + 1e-12; x += spacing_m) {
                const Vec3 c{x + u(random), y + u(random), z + u(random)};
                world.add_particle({c, {}, {}, radius_m, material}, "fill_lattice");
                report.placed_mass_kg += world.particles().mass_kg.back();
                ++report.placed;
            }
    report.requested = report.placed;
    return report;
}

Pourer::Pourer(BoxRegion region, SizeDistribution distribution, MaterialIndex material, double mass_flow_kg_per_s,
               double total_mass_kg, const Vec3& initial_velocity_m_per_s, std::uint64_t seed, double start_s)
    : region_(region), material_(material), mass_flow_kg_per_s_(mass_flow_kg_per_s),
      initial_velocity_(initial_velocity_m_per_s), not_before_s_(start_s), random_(seed)
{
    require_positive(mass_flow_kg_per_s, "mass_flow_kg_per_s", "Pourer");
    if (!(start_s >= 0.0) || !std::isfinite(start_s))
        throw InputError(concat("Pourer: start_s = ", start_s, "; expected a finite time >= 0"));
    if (!is_finite(initial_velocity_m_per_s)) throw InputError("Pourer: initial velocity must be finite");
    require_positive(total_mass_kg, "total_mass_kg", "Pourer");
    distribution.validate("Pourer");
    // the particle count follows from the density, known when the first update sees the world
    distribution_ = std::move(distribution);
    total_mass_kg_ = total_mass_kg;
}

std::size_t Pourer::update(World& world)
{
    if (start_time_s_ < 0.0) {
        if (world.time_s() < not_before_s_) return 0;
        start_time_s_ = world.time_s();
        const Material& m = world.materials().material(material_);
        if (m.is_surface) throw InputError("Pourer: material is a surface material");
        radii_ = radii_for_mass(distribution_, m.density_kg_per_m3, total_mass_kg_);
        // mix sizes so that every size class enters throughout the pour
        std::shuffle(radii_.begin(), radii_.end(), random_);
    }
    const double due_kg = mass_flow_kg_per_s_ * (world.time_s() - start_time_s_);
    // particle k enters once the flow has delivered the mass poured before it, so the first enters at once
    if (done() || poured_mass_kg_ > due_kg) return 0;

    const Vec3 lo = region_.bounds_min_m(), hi = region_.bounds_max_m();
    double r_max = 0.0;
    for (double r : radii_) r_max = std::max(r_max, r);
    SphereHash hash = hash_of_existing(world, lo, hi, 2.0 * r_max);
    hash.set_max_radius(r_max);
    std::uniform_real_distribution<double> ux(lo.x, hi.x), uy(lo.y, hi.y), uz(lo.z, hi.z);
    const double density = world.materials().material(material_).density_kg_per_m3;
    std::size_t added = 0;
    while (!done() && poured_mass_kg_ <= due_kg) {
        const double r = radii_[next_];
        bool placed = false;
        for (int attempt = 0; attempt < 200 && !placed; ++attempt) {
            const Vec3 c{ux(random_), uy(random_), uz(random_)};
            if (!region_.holds(c, r) || !hash.free(c, r)) continue;
            hash.add(c, r);
            world.add_particle({c, initial_velocity_, {}, r, material_}, concat("Pourer particle ", next_));
            placed = true;
        }
        if (!placed) break;  // the region is full for now; the rest waits for the next call
        poured_mass_kg_ += sphere_mass_kg(r, density);
        ++next_;
        ++added;
    }
    return added;
}

template <class IO, class Self>
void Pourer::state_fields(IO& io, Self& s, std::string& random)
{
    io.tag("pourer");
    io(s.radii_, s.next_, s.poured_mass_kg_, s.start_time_s_, random);
}

void Pourer::write_state(StateWriter& out) const
{
    std::ostringstream text;
    text << random_;
    std::string random = text.str();
    state_fields(out, *this, random);
}

void Pourer::read_state(StateReader& in)
{
    std::string random;
    state_fields(in, *this, random);
    if (next_ > radii_.size()) in.fail("a pour further along than it has particles");
    std::istringstream text(random);
    text >> random_;
    if (!text) in.fail("an unreadable random state");
}

}  // namespace dipper::dem
