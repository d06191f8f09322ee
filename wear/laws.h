// Wear laws: the volume one contact removes from a surface. Each law is a small pure function with its
// source; `WearLaw` selects one per surface and applies it to a contact record.
#pragma once

#include "core/contact_record.h"

#include <string>
#include <vector>

namespace dipper::wear {

/// Archard (1953): V = K Fn s, with s the sliding distance and K = k/H the dimensional wear coefficient,
/// m^3/(N m). Thesis §1.4.2 / Paper B eq. 1.
double archard_volume_m3(double coefficient_m3_per_N_m, double normal_force_N, double sliding_distance_m);

/// The angle term of Finnie's model (thesis eq. 2.3), impact angle a measured from the surface:
///   g = sin 2a - (6/K) sin^2 a   for tan a <= K/6,
///   g = (K/6) cos^2 a            above.
/// For K = 2 this is eq. 2.4's bracket: sin 2a - 3 sin^2 a up to atan(1/3) = 18.43 deg, cos^2 a / 3 above;
/// it peaks at 0.3028 at 16.85 deg, is continuous at the switch, and is 0 at 0 and 90 deg.
double finnie_angle_function(double impact_angle_rad, double force_ratio_K);

/// Finnie's erosion volume (thesis eq. 2.3): V = fraction * M v^2 / (p psi K) * g(a, K), M the impacting
/// mass, v the impact speed, p the plastic flow stress. With psi = 2, K = 2 and a cutting fraction of 0.5
/// it is eq. 2.4: M v^2/(8p) (sin 2a - 3 sin^2 a) below 18.43 deg and M v^2/(24p) cos^2 a above.
double finnie_volume_m3(double mass_kg, double speed_m_per_s, double impact_angle_rad, double flow_stress_Pa,
                        double force_ratio_K = 2.0, double depth_ratio_psi = 2.0, double cutting_fraction = 0.5);

/// The thesis' model (thesis eq. 2.8, Paper B eq. 6): W = phi sqrt(Fn^2 + Ft^2) d, with d the magnitude of
/// the relative displacement of the contact point over the step; phi in m^3/J. Non-zero for sliding
/// (0 deg) and for normal impact (90 deg).
double force_work_volume_m3(double phi_m3_per_J, double normal_force_N, double tangential_force_N,
                            double displacement_m);

/// The thesis' impact-energy form (Paper B eq. 5): W = K m v^2, K in m^3/J (per unit of m v^2).
double impact_energy_volume_m3(double coefficient_m3_per_J, double mass_kg, double speed_m_per_s);

/// Which law a surface uses, with its constant. How each applies to the contacts of a step:
/// - archard:        every step, V = K Fn s with s the tangential (sliding) part of the displacement;
/// - force_work:     every step, the thesis' W = phi |F| d with d the full displacement;
/// - impact_energy:  once per contact, on its first step, with v the relative speed at that step;
/// - finnie:         once per contact, on its first step, with the impact speed and angle.
struct WearLaw {
    enum class Kind { Archard, Finnie, ForceWork, ImpactEnergy };
    Kind kind = Kind::ForceWork;
    double constant = 1e-12;          ///< K or phi (units above); for finnie, unused (set flow_stress_Pa)
    double flow_stress_Pa = 1e9;      ///< finnie: plastic flow stress p of the surface
    double finnie_K = 2.0;            ///< finnie: ratio of normal to shear force on the grain
    double finnie_psi = 2.0;          ///< finnie: ratio of contact depth to cut depth
    double finnie_fraction = 0.5;     ///< finnie: share of grains that cut

    /// Builds a law from its name (archard, finnie, force_work, impact_energy); an unknown name is an
    /// InputError that lists the valid ones. `where` names the source (file and key).
    static WearLaw from_name(const std::string& name, double constant, const std::string& where);
    static const std::vector<std::string>& names();
    std::string name() const;

    /// The volume this contact removes during a step of dt_s, m^3 (>= 0).
    double volume_m3(const ContactRecord& contact, double dt_s) const;
    /// The same law with its constant scaled (calibration). For finnie the flow stress is divided.
    WearLaw scaled(double factor) const;
};

}  // namespace dipper::wear
