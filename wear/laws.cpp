#include "wear/laws.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>

namespace dipper::wear {

double archard_volume_m3(double coefficient_m3_per_N_m, double normal_force_N, double sliding_distance_m)
{
    return coefficient_m3_per_N_m * normal_force_N * sliding_distance_m;
}

double finnie_angle_function(double impact_angle_rad, double force_ratio_K)
{
    const double a = impact_angle_rad;
    const double s = std::sin(a);
    if (std::tan(a) <= force_ratio_K / 6.0) return std::sin(2.0 * a) - 6.0 / force_ratio_K * s * s;
    const double c = std::cos(a);
    return force_ratio_K / 6.0 * c * c;
}

double finnie_volume_m3(double mass_kg, double speed_m_per_s, double impact_angle_rad, double flow_stress_Pa,
                        double force_ratio_K, double depth_ratio_psi, double cutting_fraction)
{
    return cutting_fraction * mass_kg * speed_m_per_s * speed_m_per_s /
           (flow_stress_Pa * depth_ratio_psi * force_ratio_K) * finnie_angle_function(impact_angle_rad, force_ratio_K);
}

double force_work_volume_m3(double phi_m3_per_J, double normal_force_N, double tangential_force_N,
                            double displacement_m)
{
    return phi_m3_per_J * std::sqrt(normal_force_N * normal_force_N + tangential_force_N * tangential_force_N) *
           displacement_m;
}

double impact_energy_volume_m3(double coefficient_m3_per_J, double mass_kg, double speed_m_per_s)
{
    return coefficient_m3_per_J * mass_kg * speed_m_per_s * speed_m_per_s;
}

const std::vector<std::string>& WearLaw::names()
{
    static const std::vector<std::string> list{"archard", "finnie", "force_work", "impact_energy"};
    return list;
}

std::string WearLaw::name() const
{
    return names()[static_cast<std::size_t>(kind)];
}

WearLaw WearLaw::from_name(const std::string& name, double constant, const std::string& where)
{
    const auto& list = names();
    const auto it = std::find(list.begin(), list.end(), name);
    if (it == list.end()) {
        std::string valid;
        for (const auto& n : list) valid += (valid.empty() ? "" : ", ") + n;
        throw InputError(concat(where, ": unknown wear law '", name, "'; expected one of: ", valid));
    }
    WearLaw law;
    law.kind = static_cast<Kind>(it - list.begin());
    if (law.kind == Kind::Finnie) {
        require_positive(constant, "finnie flow stress (Pa)", where);
        law.flow_stress_Pa = constant;
    } else {
        require_positive(constant, "wear constant", where);
        law.constant = constant;
    }
    return law;
}

WearLaw WearLaw::scaled(double factor) const
{
    WearLaw law = *this;
    if (kind == Kind::Finnie) law.flow_stress_Pa /= factor;
    else law.constant *= factor;
    return law;
}

double WearLaw::volume_m3(const ContactRecord& c, double dt_s) const
{
    switch (kind) {
    case Kind::Archard: {
        const Vec3& d = c.relative_displacement_m;
        const Vec3 slip = d - c.normal_world * dot(d, c.normal_world);
        return archard_volume_m3(constant, c.normal_force_N, norm(slip));
    }
    case Kind::ForceWork:
        return force_work_volume_m3(constant, c.normal_force_N, norm(c.tangential_force_N), norm(c.relative_displacement_m));
    case Kind::ImpactEnergy:
        if (!c.first_step) return 0.0;
        return impact_energy_volume_m3(constant, c.particle_mass_kg, norm(c.relative_displacement_m) * (1.0 / dt_s));
    case Kind::Finnie: {
        if (!c.first_step) return 0.0;
        const Vec3 v = c.relative_displacement_m * (1.0 / dt_s);
        const double speed = norm(v);
        if (speed == 0.0) return 0.0;
        const double approach = std::clamp(-dot(v, c.normal_world) / speed, 0.0, 1.0);
        return finnie_volume_m3(c.particle_mass_kg, speed, std::asin(approach), flow_stress_Pa, finnie_K, finnie_psi,
                                finnie_fraction);
    }
    }
    return 0.0;
}

}  // namespace dipper::wear
