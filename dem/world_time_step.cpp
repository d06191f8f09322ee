// dem::World: the time step, from the stiffest contact each particle can have (DESIGN 1.2).
#include "dem/world.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace dipper::dem {

double World::reference_step_s() const
{
    const std::size_t i = step_setting_particle();
    if (i >= particles_.size()) return std::numeric_limits<double>::infinity();
    return std::sqrt(particles_.mass_kg[i] / stiffest_contact_N_per_m(i));
}

double World::stiffest_contact_N_per_m(std::size_t i) const
{
    return stiffest_contact_N_per_m(particles_.radius_m[i], particles_.material[i]);
}

double World::stiffest_contact_N_per_m(double radius_m, MaterialIndex a) const
{
    // The stiffest contact a particle can have is against a wall (eq. 4 with r2 -> inf): k_i r_i C,
    // with C the largest C_norm of any pair its material has. A sphere pair has m* K <= m_i k_i r_i C.
    double max_scale = 0.0;
    for (std::size_t b = 0; b < materials_.size(); ++b)
        if (materials_.has_pair(a, static_cast<MaterialIndex>(b)))
            max_scale = std::max(max_scale, materials_.pair_unchecked(a, static_cast<MaterialIndex>(b)).normal_stiffness_scale);
    return materials_.material(a).bulk_modulus_Pa() * radius_m * max_scale;
}

double World::default_step_s(double radius_m, MaterialIndex material) const
{
    const double k = stiffest_contact_N_per_m(radius_m, material);
    if (!(k > 0.0)) return std::numeric_limits<double>::infinity();
    return kDefaultStepFactor * std::sqrt(sphere_mass_kg(radius_m, materials_.material(material).density_kg_per_m3) / k);
}

std::size_t World::step_setting_particle() const
{
    std::vector<double> max_scale(materials_.size(), 0.0);
    for (std::size_t a = 0; a < materials_.size(); ++a)
        for (std::size_t b = 0; b < materials_.size(); ++b)
            if (materials_.has_pair(static_cast<MaterialIndex>(a), static_cast<MaterialIndex>(b)))
                max_scale[a] = std::max(max_scale[a], materials_.pair_unchecked(static_cast<MaterialIndex>(a),
                                                                                static_cast<MaterialIndex>(b))
                                                          .normal_stiffness_scale);
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_i = particles_.size();
    for (std::size_t i = 0; i < particles_.size(); ++i) {
        const MaterialIndex a = particles_.material[i];
        const double k = materials_.material(a).bulk_modulus_Pa() * particles_.radius_m[i] * max_scale[a];
        if (k > 0.0 && std::sqrt(particles_.mass_kg[i] / k) < best) {
            best = std::sqrt(particles_.mass_kg[i] / k);
            best_i = i;
        }
    }
    return best_i;
}

double World::step_s() const
{
    // resolved by validate_step, which runs again after any particle, wall or material is added (the
    // default is a minimum over the particles: at full size 146,000 square roots per call)
    if (step_checked_) return step_s_;
    if (settings_.step_s > 0.0) return settings_.step_s;
    return kDefaultStepFactor * reference_step_s();
}

void World::validate_step()
{
    // every material pair that can meet must have coefficients
    std::vector<bool> present(materials_.size(), false);
    for (MaterialIndex m : particles_.material) present[m] = true;
    for (std::size_t a = 0; a < materials_.size(); ++a) {
        if (!present[a]) continue;
        for (std::size_t b = 0; b < materials_.size(); ++b)
            if (present[b]) materials_.pair(static_cast<MaterialIndex>(a), static_cast<MaterialIndex>(b));
        for (const PlaneWall& p : planes_) materials_.pair(static_cast<MaterialIndex>(a), p.material);
        for (const MeshWall& m : meshes_) materials_.pair(static_cast<MaterialIndex>(a), m.material());
    }

    const double reference = reference_step_s();
    const double limit = kStableStepFactor * reference;
    if (settings_.step_s > 0.0) {
        if (settings_.step_s > limit)
            throw InputError(concat("step_s = ", settings_.step_s, " s exceeds the stable limit ", limit, " s (",
                                    kStableStepFactor, " x sqrt(m/K) = ", kStableStepFactor, " x ", reference,
                                    " s for the smallest, stiffest particle); use step_s <= ", limit,
                                    " s or leave it 0 for the default ", kDefaultStepFactor * reference, " s"));
        step_s_ = settings_.step_s;
    } else {
        step_s_ = std::isfinite(reference) ? kDefaultStepFactor * reference : 0.0;
    }
    step_checked_ = true;
}

}  // namespace dipper::dem
