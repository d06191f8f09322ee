#include "coupling/mixed_bed.h"

#include "core/errors.h"
#include "core/files.h"
#include "dem/insertion.h"
#include "dem/particle_store.h"
#include "rigid/rock_generator.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <random>
#include <sstream>
#include <unordered_map>

namespace dipper::coupling {

void MixedDistribution::validate(const std::string& where) const
{
    require_positive(spheres.radius_m, "the spheres' radius_m", where);
    require_in_range(spheres.mass_fraction, 0.0, 1.0, "the spheres' mass_fraction", where);
    double sum = spheres.mass_fraction;
    for (std::size_t c = 0; c < rocks.size(); ++c) {
        const std::string at = concat(where, ", rock class ", c);
        require_positive(rocks[c].size_m, "size_m", at);
        require_in_range(rocks[c].mass_fraction, 0.0, 1.0, "mass_fraction", at);
        sum += rocks[c].mass_fraction;
    }
    if (std::abs(sum - 1.0) > 1e-6)
        throw InputError(concat(where, ": mass fractions sum to ", sum, "; expected 1 (spheres plus all rock classes)"));
    if (!(elongation_min >= 1.0) || !(elongation_max >= elongation_min))
        throw InputError(concat(where, ": elongation range [", elongation_min, ", ", elongation_max, "]; expected 1 <= min <= max"));
}

namespace {

/// A placed rock as the placement sees it: world vertices, outward face planes, bounding sphere.
struct PlacedRock {
    Vec3 centre;
    double radius = 0.0;
    std::vector<Vec3> vertices;
    std::vector<Vec3> normals;
    std::vector<double> offsets;  ///< plane: dot(normal, x) = offset
};

PlacedRock place(const rigid::ConvexPolyhedron& shape, const Mat3& r, const Vec3& c)
{
    PlacedRock p;
    p.centre = c;
    for (const Vec3& v : shape.vertices_m()) {
        p.vertices.push_back(r * v + c);
        p.radius = std::max(p.radius, norm(v));
    }
    for (const auto& t : shape.triangles()) {
        const Vec3 a = p.vertices[t[0]], b = p.vertices[t[1]], d = p.vertices[t[2]];
        const Vec3 n = normalized(cross(b - a, d - a));
        p.normals.push_back(n);
        p.offsets.push_back(dot(n, a));
    }
    return p;
}

/// True if a face plane of `a` has every vertex of `b` at least `gap` in front of it: then they are apart.
/// Face planes alone can miss an edge-edge separation, so this errs towards calling rocks overlapping.
bool separated_by_faces(const PlacedRock& a, const PlacedRock& b, double gap)
{
    for (std::size_t f = 0; f < a.normals.size(); ++f) {
        bool all = true;
        for (const Vec3& v : b.vertices)
            if (dot(a.normals[f], v) - a.offsets[f] < gap) { all = false; break; }
        if (all) return true;
    }
    return false;
}

/// A sphere is clear of a rock if it lies wholly in front of one of the rock's face planes.
bool sphere_clear_of(const PlacedRock& rock, const Vec3& x, double r)
{
    if (norm(x - rock.centre) > rock.radius + r) return true;
    for (std::size_t f = 0; f < rock.normals.size(); ++f)
        if (dot(rock.normals[f], x) - rock.offsets[f] >= r) return true;
    return false;
}

Mat3 random_rotation(std::mt19937_64& rng)
{
    // uniform over rotations: a random unit quaternion (Shoemake)
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double u1 = u(rng), u2 = 2.0 * M_PI * u(rng), u3 = 2.0 * M_PI * u(rng);
    const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
    const double w = a * std::sin(u2), x = a * std::cos(u2), y = b * std::sin(u3), z = b * std::cos(u3);
    Mat3 m;
    m.m[0][0] = 1 - 2 * (y * y + z * z); m.m[0][1] = 2 * (x * y - z * w);     m.m[0][2] = 2 * (x * z + y * w);
    m.m[1][0] = 2 * (x * y + z * w);     m.m[1][1] = 1 - 2 * (x * x + z * z); m.m[1][2] = 2 * (y * z - x * w);
    m.m[2][0] = 2 * (x * z - y * w);     m.m[2][1] = 2 * (y * z + x * w);     m.m[2][2] = 1 - 2 * (x * x + y * y);
    return m;
}

/// Uniform grid of cell `cell` over a box holding sphere indices, for overlap checks during placement.
class SphereGrid {
public:
    SphereGrid(const Vec3& lo, const Vec3& hi, double cell) : lo_(lo), cell_(cell)
    {
        for (int a = 0; a < 3; ++a) dims_[a] = std::max(1, static_cast<int>(std::ceil((hi[a] - lo[a]) / cell)) + 2);
        cells_.resize(static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2]);
    }
    void add(const Vec3& x, double r)
    {
        centres_.push_back(x);
        radii_.push_back(r);
        cells_[index(x)].push_back(static_cast<std::uint32_t>(centres_.size() - 1));
    }
    bool free(const Vec3& x, double r) const
    {
        int c[3];
        for (int a = 0; a < 3; ++a) c[a] = coord(x, a);
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int i = c[0] + dx, j = c[1] + dy, k = c[2] + dz;
                    if (i < 0 || j < 0 || k < 0 || i >= dims_[0] || j >= dims_[1] || k >= dims_[2]) continue;
                    for (std::uint32_t s : cells_[(static_cast<std::size_t>(k) * dims_[1] + j) * dims_[0] + i]) {
                        const double d = r + radii_[s];
                        if (norm_squared(centres_[s] - x) < d * d) return false;
                    }
                }
        return true;
    }

private:
    int coord(const Vec3& x, int a) const { return std::clamp(static_cast<int>((x[a] - lo_[a]) / cell_) + 1, 0, dims_[a] - 1); }
    std::size_t index(const Vec3& x) const
    {
        return (static_cast<std::size_t>(coord(x, 2)) * dims_[1] + coord(x, 1)) * dims_[0] + coord(x, 0);
    }
    Vec3 lo_;
    double cell_;
    int dims_[3] = {1, 1, 1};
    std::vector<std::vector<std::uint32_t>> cells_;
    std::vector<Vec3> centres_;
    std::vector<double> radii_;
};

/// The placed rocks by cells of a uniform grid: each rock is listed in every cell its bounding sphere's box
/// meets, so a rock or sphere whose bounding sphere overlaps a rock's shares a cell with it. Placing a pile of
/// 20,000 rocks and 146,000 spheres then costs the rocks near each try, not all of those placed before it.
class RockGrid {
public:
    RockGrid(const Vec3& lo, double cell) : lo_(lo), cell_(cell) {}
    void add(std::uint32_t rock, const Vec3& centre, double radius)
    {
        for_cells(centre, radius, [&](std::int64_t key) { cells_[key].push_back(rock); });
        stamp_.push_back(0);
    }
    /// Calls `near(rock)` once for each rock listed in a cell that the sphere's box meets, until it returns false.
    template <class Near>
    bool all_of_near(const Vec3& centre, double radius, Near near)
    {
        ++query_;
        bool all = true;
        for_cells(centre, radius, [&](std::int64_t key) {
            if (!all) return;
            const auto it = cells_.find(key);
            if (it == cells_.end()) return;
            for (std::uint32_t rock : it->second) {
                if (stamp_[rock] == query_) continue;
                stamp_[rock] = query_;
                if (!near(rock)) {
                    all = false;
                    return;
                }
            }
        });
        return all;
    }

private:
    template <class Visit>
    void for_cells(const Vec3& centre, double radius, Visit visit) const
    {
        int from[3], to[3];
        for (int a = 0; a < 3; ++a) {
            from[a] = static_cast<int>(std::floor((centre[a] - radius - lo_[a]) / cell_));
            to[a] = static_cast<int>(std::floor((centre[a] + radius - lo_[a]) / cell_));
        }
        for (int k = from[2]; k <= to[2]; ++k)
            for (int j = from[1]; j <= to[1]; ++j)
                for (int i = from[0]; i <= to[0]; ++i) visit((static_cast<std::int64_t>(i) * 100003 + j) * 100019 + k);
    }
    Vec3 lo_;
    double cell_;
    std::unordered_map<std::int64_t, std::vector<std::uint32_t>> cells_;
    std::vector<std::uint64_t> stamp_;  ///< per rock: the last query that met it
    std::uint64_t query_ = 0;
};

}  // namespace

MixedFillReport fill_mixed(CoupledWorld& world, const Vec3& lo, const Vec3& hi, const MixedDistribution& distribution,
                           const MixedMaterials& materials, double total_mass_kg, std::uint64_t seed, int attempts,
                           const KeepFilter& keep)
{
    const std::string where = "fill_mixed";
    distribution.validate(where);
    require_positive(total_mass_kg, "total_mass_kg", where);
    require_positive(materials.density_kg_per_m3, "density_kg_per_m3", where);
    for (int a = 0; a < 3; ++a)
        if (!(hi[a] > lo[a])) throw InputError(concat(where, ": box corner hi must exceed lo on every axis"));
    dem::require_mass_fits(total_mass_kg, materials.density_kg_per_m3, lo, hi, where);
    {
        // a rock counted as the sphere of its size, as the classes are made below
        double count = distribution.spheres.mass_fraction * total_mass_kg /
                       dem::sphere_mass_kg(distribution.spheres.radius_m, materials.density_kg_per_m3);
        for (const RockClass& rc : distribution.rocks)
            count += rc.mass_fraction * total_mass_kg / dem::sphere_mass_kg(0.5 * rc.size_m, materials.density_kg_per_m3);
        if (!(count <= dem::kMaxFillParticles))
            throw InputError(concat(where, ": ", total_mass_kg, " kg of this mix makes ", count, " spheres and rocks; at most ",
                                    dem::kMaxFillParticles, " are made at once: check the mass and the sizes"));
    }
    dem::World& dem = world.dem();
    const double sphere_density = dem.materials().material(materials.sphere).density_kg_per_m3;
    if (std::abs(sphere_density - materials.density_kg_per_m3) > 1e-9 * materials.density_kg_per_m3)
        throw InputError(concat(where, ": the sphere material '", dem.materials().material(materials.sphere).name, "' has density ",
                                sphere_density, " kg/m3 but the mixed material asks for ", materials.density_kg_per_m3,
                                " kg/m3; rocks and spheres share one particle density"));

    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    MixedFillReport report;

    // what is already there: rocks made by add_rock, and spheres
    std::vector<PlacedRock> placed;
    double largest_class_m = 0.0;
    for (const RockClass& rc : distribution.rocks) largest_class_m = std::max(largest_class_m, rc.size_m);
    RockGrid placed_grid(lo, std::max(largest_class_m, 2.0 * distribution.spheres.radius_m));
    for (const RockRecord& r : world.rocks()) {
        const rigid::BodyState s = world.rigid().state(r.body);
        placed.push_back(place(r.shape, s.rotation, s.position_m));
        placed_grid.add(static_cast<std::uint32_t>(placed.size() - 1), placed.back().centre, placed.back().radius);
    }
    const double rs = distribution.spheres.radius_m;
    SphereGrid grid(lo, hi, 2.0 * std::max(rs, [&] {
                                   double m = 0.0;
                                   for (double r : dem.particles().radius_m) m = std::max(m, r);
                                   return m;
                               }()));
    for (std::size_t i = 0; i < dem.particles().size(); ++i) grid.add(dem.particles().position_m[i], dem.particles().radius_m[i]);

    // rocks, largest class first
    std::vector<std::size_t> order(distribution.rocks.size());
    for (std::size_t c = 0; c < order.size(); ++c) order[c] = c;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return distribution.rocks[a].size_m > distribution.rocks[b].size_m; });
    report.rocks_per_class.assign(distribution.rocks.size(), 0);
    std::uint64_t rock_seed = seed * 7919 + 1;
    for (std::size_t c : order) {
        const RockClass& rc = distribution.rocks[c];
        const double one = materials.density_kg_per_m3 * M_PI / 6.0 * rc.size_m * rc.size_m * rc.size_m;
        const auto count = static_cast<std::size_t>(std::llround(rc.mass_fraction * total_mass_kg / one));
        const rigid::RockShape shape_kind{rc.size_m, distribution.elongation_min, distribution.elongation_max, distribution.rock_point_count};
        for (std::size_t k = 0; k < count; ++k) {
            const rigid::ConvexPolyhedron shape = rigid::generate_rock(shape_kind, rock_seed++, concat(where, ", rock class ", c));
            bool done = false;
            for (int attempt = 0; attempt < attempts && !done; ++attempt) {
                const Mat3 r = random_rotation(rng);
                // centre so that the turned rock lies inside the box
                Vec3 ext_lo{1e300, 1e300, 1e300}, ext_hi{-1e300, -1e300, -1e300};
                for (const Vec3& v : shape.vertices_m()) {
                    const Vec3 w = r * v;
                    ext_lo = {std::min(ext_lo.x, w.x), std::min(ext_lo.y, w.y), std::min(ext_lo.z, w.z)};
                    ext_hi = {std::max(ext_hi.x, w.x), std::max(ext_hi.y, w.y), std::max(ext_hi.z, w.z)};
                }
                const Vec3 c_min = lo - ext_lo, c_max = hi - ext_hi;
                if (c_min.x > c_max.x || c_min.y > c_max.y || c_min.z > c_max.z) continue;
                const Vec3 centre{c_min.x + u(rng) * (c_max.x - c_min.x), c_min.y + u(rng) * (c_max.y - c_min.y),
                                  c_min.z + u(rng) * (c_max.z - c_min.z)};
                PlacedRock candidate = place(shape, r, centre);
                if (keep && !keep(centre, candidate.radius)) continue;
                bool clear = placed_grid.all_of_near(centre, candidate.radius, [&](std::uint32_t q) {
                    const PlacedRock& o = placed[q];
                    return norm(o.centre - centre) > o.radius + candidate.radius || separated_by_faces(o, candidate, 0.0) ||
                           separated_by_faces(candidate, o, 0.0);
                });
                if (!clear) continue;
                // spheres already in the world
                for (std::size_t i = 0; i < dem.particles().size() && clear; ++i)
                    clear = sphere_clear_of(candidate, dem.particles().position_m[i], dem.particles().radius_m[i]);
                if (!clear) continue;
                world.add_rock(shape, materials.density_kg_per_m3, materials.rigid_rock, materials.rock, centre, r);
                placed.push_back(std::move(candidate));
                placed_grid.add(static_cast<std::uint32_t>(placed.size() - 1), placed.back().centre, placed.back().radius);
                report.rock_mass_kg += materials.density_kg_per_m3 * shape.volume_m3();
                ++report.rocks_per_class[c];
                done = true;
            }
            if (!done)
                throw InputError(concat(where, ": no free place for a ", rc.size_m, " m rock (", k + 1, " of ", count,
                                        " in its class) after ", attempts, " tries; the box is too small for ", total_mass_kg,
                                        " kg of this material: make it larger or the mass smaller"));
        }
    }

    // spheres in the gaps; the rocks near each try found through the same grid
    const double sphere_mass = dem::sphere_mass_kg(rs, materials.density_kg_per_m3);
    const auto sphere_count = static_cast<std::size_t>(std::llround(distribution.spheres.mass_fraction * total_mass_kg / sphere_mass));
    const Vec3 s_lo = lo + Vec3{rs, rs, rs}, s_hi = hi - Vec3{rs, rs, rs};
    if (s_lo.x > s_hi.x || s_lo.y > s_hi.y || s_lo.z > s_hi.z)
        throw InputError(concat(where, ": the box is thinner than one sphere of radius ", rs, " m"));
    for (std::size_t k = 0; k < sphere_count; ++k) {
        bool done = false;
        for (int attempt = 0; attempt < attempts && !done; ++attempt) {
            const Vec3 x{s_lo.x + u(rng) * (s_hi.x - s_lo.x), s_lo.y + u(rng) * (s_hi.y - s_lo.y), s_lo.z + u(rng) * (s_hi.z - s_lo.z)};
            if (!grid.free(x, rs) || (keep && !keep(x, rs))) continue;
            if (!placed_grid.all_of_near(x, rs, [&](std::uint32_t q) { return sphere_clear_of(placed[q], x, rs); })) continue;
            dem.add_particle({x, {}, {}, rs, materials.sphere}, where);
            grid.add(x, rs);
            report.sphere_mass_kg += sphere_mass;
            ++report.spheres;
            done = true;
        }
        if (!done)
            throw InputError(concat(where, ": no free place for sphere ", k + 1, " of ", sphere_count, " after ", attempts,
                                    " tries; the box is too small for ", total_mass_kg, " kg of this material"));
    }
    return report;
}

// ---- saved states ------------------------------------------------------------------------------------

namespace {
constexpr const char* kStateMagic = "dipper-state";
constexpr int kStateVersion = 1;
}  // namespace

void save_state(const CoupledWorld& world, const std::string& path, double cut_above_m)
{
    if (std::isnan(cut_above_m)) throw InputError(concat("save_state '", path, "': the cut height is not a number"));
    std::ofstream out = open_for_writing(path);
    out << std::setprecision(17);
    const dem::World& dem = world.dem();
    const auto& p = dem.particles();
    out << kStateMagic << ' ' << kStateVersion << '\n';
    std::vector<std::size_t> by_id(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) by_id[p.id[i]] = i;
    std::vector<std::size_t> kept;
    for (std::size_t i : by_id)
        if (p.position_m[i].z <= cut_above_m) kept.push_back(i);
    std::vector<const RockRecord*> rocks;
    for (const RockRecord& r : world.rocks())
        if (world.rigid().state(r.body).position_m.z <= cut_above_m) rocks.push_back(&r);
    out << "spheres " << kept.size() << '\n';
    for (std::size_t i : kept) {
        const Vec3 x = p.position_m[i], v = p.velocity_m_per_s[i], w = p.angular_velocity_rad_per_s[i];
        out << x.x << ' ' << x.y << ' ' << x.z << ' ' << v.x << ' ' << v.y << ' ' << v.z << ' ' << w.x << ' ' << w.y << ' '
            << w.z << ' ' << p.radius_m[i] << ' ' << dem.materials().material(p.material[i]).name << '\n';
    }
    out << "rocks " << rocks.size() << '\n';
    for (const RockRecord* rock : rocks) {
        const RockRecord& r = *rock;
        const rigid::BodyState s = world.rigid().state(r.body);
        out << "rock " << r.density_kg_per_m3 << ' ' << world.rigid().material_name(r.rigid_material) << ' '
            << dem.materials().material(r.dem_material).name << ' ' << r.shape.vertices_m().size() << ' '
            << r.shape.triangles().size() << '\n';
        out << s.position_m.x << ' ' << s.position_m.y << ' ' << s.position_m.z;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) out << ' ' << s.rotation.m[i][j];
        out << ' ' << s.velocity_m_per_s.x << ' ' << s.velocity_m_per_s.y << ' ' << s.velocity_m_per_s.z << ' '
            << s.angular_velocity_rad_per_s.x << ' ' << s.angular_velocity_rad_per_s.y << ' ' << s.angular_velocity_rad_per_s.z << '\n';
        for (const Vec3& v : r.shape.vertices_m()) out << v.x << ' ' << v.y << ' ' << v.z << '\n';
        for (const auto& t : r.shape.triangles()) out << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
    }
    out << "end\n";
    finish_writing(out, path);
}

namespace {

/// Reads a bed's text file line by line with errors that name the file and line.
class BedFileReader {
public:
    explicit BedFileReader(const std::string& path) : path_(path), in_(path)
    {
        if (!in_) throw InputError(concat("cannot open state file '", path, "'"));
    }
    std::istringstream line(const std::string& expected)
    {
        std::string text;
        if (!std::getline(in_, text))
            throw InputError(concat(path_, ": ends at line ", line_, " where ", expected, " was expected (truncated file?)"));
        ++line_;
        return std::istringstream(text);
    }
    [[noreturn]] void fail(const std::string& what) const { throw InputError(concat(path_, ":", line_, ": ", what)); }
    template <typename T>
    T read(std::istringstream& s, const char* what)
    {
        T v{};
        if (!(s >> v)) fail(concat("expected ", what));
        return v;
    }
    double number(std::istringstream& s, const char* what)
    {
        const double v = read<double>(s, what);
        if (!std::isfinite(v)) fail(concat(what, " is not finite"));
        return v;
    }
    Vec3 vec(std::istringstream& s, const char* what) { return {number(s, what), number(s, what), number(s, what)}; }

private:
    std::string path_;
    std::ifstream in_;
    int line_ = 0;
};

}  // namespace

LoadedState load_state(CoupledWorld& world, const std::string& path, const KeepFilter& keep)
{
    LoadedState loaded;
    BedFileReader in(path);
    {
        auto s = in.line("the header");
        std::string magic;
        int version = 0;
        if (!(s >> magic >> version) || magic != kStateMagic)
            in.fail(concat("not a dipper state file: expected the header '", kStateMagic, " ", kStateVersion, "'"));
        if (version != kStateVersion) in.fail(concat("state version ", version, "; this dipper reads version ", kStateVersion));
    }
    dem::World& dem = world.dem();
    auto dem_material = [&](const std::string& name) {
        try {
            return dem.materials().index_of(name);
        } catch (const InputError& e) {
            in.fail(e.what());
        }
    };
    std::size_t spheres = 0;
    {
        auto s = in.line("'spheres N'");
        if (in.read<std::string>(s, "'spheres'") != "spheres") in.fail("expected 'spheres N'");
        spheres = in.read<std::size_t>(s, "the number of spheres");
    }
    for (std::size_t k = 0; k < spheres; ++k) {
        auto s = in.line("a sphere");
        dem::ParticleSpawn p;
        p.position_m = in.vec(s, "position");
        p.velocity_m_per_s = in.vec(s, "velocity");
        p.angular_velocity_rad_per_s = in.vec(s, "angular velocity");
        p.radius_m = in.number(s, "radius");
        p.material = dem_material(in.read<std::string>(s, "material name"));
        if (keep && !keep(p.position_m, p.radius_m)) {
            ++loaded.spheres_left_out;
            continue;
        }
        dem.add_particle(p, concat(path, ", sphere ", k));
        ++loaded.spheres;
    }
    std::size_t rocks = 0;
    {
        auto s = in.line("'rocks N'");
        if (in.read<std::string>(s, "'rocks'") != "rocks") in.fail("expected 'rocks N'");
        rocks = in.read<std::size_t>(s, "the number of rocks");
    }
    for (std::size_t k = 0; k < rocks; ++k) {
        auto s = in.line("a rock");
        if (in.read<std::string>(s, "'rock'") != "rock") in.fail("expected 'rock density rigid_material dem_material vertices triangles'");
        const double density = in.number(s, "density");
        const std::string rigid_name = in.read<std::string>(s, "rigid material name");
        const dem::MaterialIndex dm = dem_material(in.read<std::string>(s, "DEM material name"));
        const auto nv = in.read<std::size_t>(s, "vertex count"), nt = in.read<std::size_t>(s, "triangle count");
        int rm = 0;
        try {
            rm = world.rigid().material_index(rigid_name);
        } catch (const InputError& e) {
            in.fail(e.what());
        }
        auto ps = in.line("a rock pose");
        const Vec3 position = in.vec(ps, "position");
        Mat3 rotation;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) rotation.m[i][j] = in.number(ps, "rotation entry");
        const Vec3 v = in.vec(ps, "velocity"), w = in.vec(ps, "angular velocity");
        std::vector<Vec3> vertices;
        std::vector<std::array<std::uint32_t, 3>> triangles;
        for (std::size_t i = 0; i < nv; ++i) {
            auto vs = in.line("a vertex");
            vertices.push_back(in.vec(vs, "vertex"));
        }
        for (std::size_t i = 0; i < nt; ++i) {
            auto ts = in.line("a triangle");
            std::array<std::uint32_t, 3> t{};
            for (auto& c : t) {
                c = in.read<std::uint32_t>(ts, "vertex index");
                if (c >= nv) in.fail(concat("vertex index ", c, " out of range (", nv, " vertices)"));
            }
            triangles.push_back(t);
        }
        const rigid::ConvexPolyhedron shape =
            rigid::ConvexPolyhedron::from_mesh(meshes::TriangleMesh(std::move(vertices), std::move(triangles), concat(path, ", rock ", k)));
        if (keep) {
            double bound2 = 0.0;
            for (const Vec3& x : shape.vertices_m()) bound2 = std::max(bound2, norm_squared(x - shape.centroid_m()));
            if (!keep(position, std::sqrt(bound2))) {
                ++loaded.rocks_left_out;
                continue;
            }
        }
        world.add_rock(shape, density, rm, dm, position, rotation, v, w);
        ++loaded.rocks;
    }
    auto s = in.line("'end'");
    if (in.read<std::string>(s, "'end'") != "end") in.fail("expected 'end'");
    return loaded;
}

}  // namespace dipper::coupling
