#include "dem/particle_store.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>

namespace dipper::dem {

double sphere_mass_kg(double radius_m, double density_kg_per_m3)
{
    return density_kg_per_m3 * 4.0 / 3.0 * M_PI * radius_m * radius_m * radius_m;
}

void ParticleStore::reserve(std::size_t n)
{
    for (auto* v : {&position_m, &velocity_m_per_s, &angular_velocity_rad_per_s, &force_N, &torque_N_m}) v->reserve(n);
    for (auto* v : {&radius_m, &mass_kg, &inverse_mass_per_kg, &inverse_inertia_per_kg_m2}) v->reserve(n);
    material.reserve(n);
    id.reserve(n);
    frozen.reserve(n);
}

std::uint32_t ParticleStore::add(const ParticleSpawn& s, const MaterialTable& materials, const std::string& where)
{
    require_positive(s.radius_m, "radius_m", where);
    if (!is_finite(s.position_m)) throw InputError(concat("position_m must be finite (", where, ")"));
    if (!is_finite(s.velocity_m_per_s)) throw InputError(concat("velocity_m_per_s must be finite (", where, ")"));
    if (!is_finite(s.angular_velocity_rad_per_s))
        throw InputError(concat("angular_velocity_rad_per_s must be finite (", where, ")"));
    // A particle's centre or rim faster than kMaxSpeed_m_per_s is a corrupt value, not a state of a mine: at
    // 1e300 m/s the kinetic energy overflows to inf and the outputs would carry it on
    const Vec3& v = s.velocity_m_per_s;
    const Vec3& w = s.angular_velocity_rad_per_s;
    if (!(norm(v) <= kMaxSpeed_m_per_s))
        throw InputError(concat("velocity_m_per_s (", v.x, ", ", v.y, ", ", v.z, "): expected a speed of at most ",
                                kMaxSpeed_m_per_s, " m/s (", where, ")"));
    if (!(norm(w) * s.radius_m <= kMaxSpeed_m_per_s))
        throw InputError(concat("angular_velocity_rad_per_s (", w.x, ", ", w.y, ", ", w.z, ") at radius ", s.radius_m,
                                " m: expected a rim speed of at most ", kMaxSpeed_m_per_s, " m/s (", where, ")"));
    if (s.material >= materials.size())
        throw InputError(concat("material index ", s.material, " does not exist; the table has ", materials.size(),
                                " materials (", where, ")"));
    const Material& m = materials.material(s.material);
    if (m.is_surface)
        throw InputError(concat("material '", m.name, "' is a surface material and cannot make a particle (", where, ")"));

    const double mass = sphere_mass_kg(s.radius_m, m.density_kg_per_m3);
    const double inertia = 0.4 * mass * s.radius_m * s.radius_m;  // solid sphere, 2/5 m r^2
    position_m.push_back(s.position_m);
    velocity_m_per_s.push_back(s.velocity_m_per_s);
    angular_velocity_rad_per_s.push_back(s.angular_velocity_rad_per_s);
    force_N.push_back({});
    torque_N_m.push_back({});
    radius_m.push_back(s.radius_m);
    mass_kg.push_back(mass);
    inverse_mass_per_kg.push_back(1.0 / mass);
    inverse_inertia_per_kg_m2.push_back(1.0 / inertia);
    material.push_back(s.material);
    id.push_back(next_id_);
    frozen.push_back(0);
    return next_id_++;
}

namespace {
template <typename T>
void apply_order(std::vector<T>& v, const std::vector<std::uint32_t>& order, std::vector<T>& scratch)
{
    scratch.resize(v.size());
    for (std::size_t k = 0; k < order.size(); ++k) scratch[k] = v[order[k]];
    v.swap(scratch);
}
}  // namespace

void ParticleStore::permute(const std::vector<std::uint32_t>& order)
{
    std::vector<Vec3> s3;
    std::vector<double> s1;
    for (auto* v : {&position_m, &velocity_m_per_s, &angular_velocity_rad_per_s, &force_N, &torque_N_m})
        apply_order(*v, order, s3);
    for (auto* v : {&radius_m, &mass_kg, &inverse_mass_per_kg, &inverse_inertia_per_kg_m2}) apply_order(*v, order, s1);
    std::vector<MaterialIndex> sm;
    apply_order(material, order, sm);
    std::vector<std::uint32_t> si;
    apply_order(id, order, si);
    std::vector<std::uint8_t> sf;
    apply_order(frozen, order, sf);
}

template <class IO, class Self>
void ParticleStore::state_fields(IO& io, Self& s)
{
    io.tag("particles");
    io(s.position_m, s.velocity_m_per_s, s.angular_velocity_rad_per_s, s.force_N, s.torque_N_m);
    io(s.radius_m, s.mass_kg, s.inverse_mass_per_kg, s.inverse_inertia_per_kg_m2);
    io(s.material, s.id, s.frozen, s.next_id_);
}

void ParticleStore::write_state(StateWriter& out) const { state_fields(out, *this); }

void ParticleStore::read_state(StateReader& in, const MaterialTable& materials)
{
    state_fields(in, *this);
    const std::size_t n = position_m.size();
    for (const auto* v : {&velocity_m_per_s, &angular_velocity_rad_per_s, &force_N, &torque_N_m})
        if (v->size() != n) in.fail("particle arrays of different lengths");
    for (const auto* v : {&radius_m, &mass_kg, &inverse_mass_per_kg, &inverse_inertia_per_kg_m2})
        if (v->size() != n) in.fail("particle arrays of different lengths");
    if (material.size() != n || id.size() != n || frozen.size() != n) in.fail("particle arrays of different lengths");
    for (std::uint8_t f : frozen)
        if (f > 1) in.fail(concat("a particle's frozen flag of ", int(f), "; expected 0 or 1"));
    for (MaterialIndex m : material)
        if (m >= materials.size()) in.fail(concat("particle material ", m, " beyond the ", materials.size(), " materials"));
    // what a run wrote is finite and physical; a file changed behind its checksum must not reach the grid
    // (a NaN position made the neighbour grid's size undefined)
    for (const auto* v : {&position_m, &velocity_m_per_s, &angular_velocity_rad_per_s, &force_N, &torque_N_m})
        for (const Vec3& x : *v)
            if (!is_finite(x)) in.fail("a particle vector that is not finite");
    for (const auto* v : {&radius_m, &mass_kg, &inverse_mass_per_kg, &inverse_inertia_per_kg_m2})
        for (double x : *v)
            if (!(x > 0.0 && std::isfinite(x))) in.fail(concat("a particle radius, mass or inverse of ", x, "; expected a finite value > 0"));
    // unique and below the next id, checked on a sorted copy: memory of the particle count, whatever next_id_ says
    std::vector<std::uint32_t> sorted(id);
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t k = 0; k < sorted.size(); ++k)
        if (sorted[k] >= next_id_ || (k > 0 && sorted[k] == sorted[k - 1]))
            in.fail(concat("particle id ", sorted[k], " repeated or not below the next id ", next_id_));
}

}  // namespace dipper::dem
