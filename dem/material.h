// Materials and per-material-pair contact coefficients (thesis Paper A, Table 2).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace dipper::dem {

using MaterialIndex = std::uint16_t;

/// A named material. Particle materials need density and elastic constants; a surface material (a
/// wall, a bucket plate, the ground) is infinitely stiff and massive in the contact law (r2 -> inf),
/// so its elastic constants are not used.
struct Material {
    std::string name;
    double density_kg_per_m3 = 0.0;
    double youngs_modulus_Pa = 0.0;
    double poisson_ratio = 0.0;
    bool is_surface = false;

    /// Bulk modulus k = E / (3 (1 - 2 nu)), thesis eq. 5.
    double bulk_modulus_Pa() const { return youngs_modulus_Pa / (3.0 * (1.0 - 2.0 * poisson_ratio)); }
};

/// Contact coefficients of one material pair, as in thesis Table 2.
struct PairCoefficients {
    double normal_stiffness_scale = 0.05;      ///< C_norm in Kn = k1 r1 k2 r2 / (k1 r1 + k2 r2) C_norm (eq. 4)
    double tangential_stiffness_scale = 0.27;  ///< C_tan in Kt = C_tan Kn
    double friction = 0.0;                     ///< Coulomb mu, |Ft| <= mu Fn (eq. 7)
    double rolling_friction = 0.0;             ///< mu_roll, |Mr| <= r mu_roll Fn (eq. 8)
    double normal_damping_ratio = 1.0;         ///< D_n: fraction of critical damping, 0..1 (eq. 6)
    double tangential_damping_ratio = 1.0;     ///< D_t: fraction of critical damping, 0..1
};

/// Thesis Paper A Table 2 as dipper's spheres see it, written once: the preset (MaterialTable::aitik_copper_ore),
/// the tests and the benchmarks read these. Damping 1 where Table 2 gives none (the thesis damps fully).
namespace table2 {
/// DE-DE: C_norm 0.05, C_tan 0.27, mu 0.9, mu_roll 0.05, D_n 0.9, D_t 0.75
inline constexpr PairCoefficients ore_ore{0.05, 0.27, 0.9, 0.05, 0.9, 0.75};
/// Ground-DE: mu 0.9, mu_roll 0.3
inline constexpr PairCoefficients ore_ground{0.05, 0.27, 0.9, 0.3, 1.0, 1.0};
/// Bucket-DE: mu 0.53 (pin-on-disc, Hardox against Aitik rock), mu_roll 0.05
inline constexpr PairCoefficients ore_bucket{0.05, 0.27, 0.53, 0.05, 1.0, 1.0};
/// FE rocks-DE: mu 0.85
inline constexpr PairCoefficients ore_rock{0.05, 0.27, 0.85, 0.05, 1.0, 1.0};
/// FE truck-DE: mu 0.85
inline constexpr PairCoefficients ore_truck{0.05, 0.27, 0.85, 0.05, 1.0, 1.0};
/// DE-remaining: mu 0 (the frictionless walls of calibration boxes)
inline constexpr PairCoefficients ore_steel{0.05, 0.27, 0.0, 0.0, 1.0, 1.0};
}  // namespace table2

/// How rolling resistance (thesis eq. 8) acts.
enum class RollingResistance {
    /// An elastic-plastic spring on the pair's relative rolling rotation, |Mr| <= mu_roll R* Fn with R* the
    /// pair's effective radius (Ai, Chen, Rotter & Ooi 2011, type C): a pile at rest stays at rest. The default.
    relative_spring,
    /// Each contact resists the sphere's own spin with a torque mu_roll r Fn, r the sphere's own radius (eq. 8
    /// as the thesis writes it, "a moment for the particle"; the constant-torque rolling friction of Zhou et
    /// al. 1999, which EDEM calls its standard rolling friction). The contacts' torques on a sphere, summed, slow its spin over a
    /// step at most to rest, never past it; walls and bodies feel no reaction to them.
    own_spin,
};

/// The constant material model of a run: materials and a symmetric table of pair coefficients. Built
/// and validated once; read-only (and so thread-safe) during the run.
class MaterialTable {
public:
    /// Adds a material after validating it; returns its index. Names are unique.
    MaterialIndex add(const Material& material);
    /// Sets the coefficients of the pair (a, b) and (b, a) after validating them. `where` names the
    /// source of the values for error messages.
    void set_pair(MaterialIndex a, MaterialIndex b, const PairCoefficients& coefficients,
                  const std::string& where = "set_pair");
    void set_pair(const std::string& a, const std::string& b, const PairCoefficients& coefficients,
                  const std::string& where = "set_pair");

    std::size_t size() const { return materials_.size(); }
    const Material& material(MaterialIndex i) const { return materials_.at(i); }
    MaterialIndex index_of(const std::string& name) const;  ///< throws InputError listing the known names
    bool has_pair(MaterialIndex a, MaterialIndex b) const { return defined_[a * materials_.size() + b]; }
    /// Coefficients of a pair; throws InputError if the pair was never set.
    const PairCoefficients& pair(MaterialIndex a, MaterialIndex b) const;
    /// Same without the check, for hot loops over pairs that were checked at setup.
    const PairCoefficients& pair_unchecked(MaterialIndex a, MaterialIndex b) const
    {
        return pairs_[a * materials_.size() + b];
    }

    /// Aitik copper ore of thesis Paper A Table 2: materials "ore" (spheres), "rock" (polyhedral rocks
    /// seen by spheres), surfaces "ground", "bucket", "truck", and "steel" (any other machine surface,
    /// Table 2's "DE-remaining", frictionless). Where Table 2 is silent the thesis says damping 1 and
    /// stiffness scale 0.05; spheres against rocks take DE-DE rolling friction.
    /// `particle_density_kg_per_m3` replaces Table 2's 3700 for "ore" and "rock" alike (the thesis scales it
    /// to hit the bulk density 1903 kg/m3; coupling/bulk_density.h finds the scaled value).
    static MaterialTable aitik_copper_ore(double particle_density_kg_per_m3 = 3700.0);

    /// The form of rolling resistance of every pair (RollingResistance::relative_spring unless set).
    RollingResistance rolling_resistance() const { return rolling_resistance_; }
    void set_rolling_resistance(RollingResistance form) { rolling_resistance_ = form; }

private:
    void check_index(MaterialIndex i, const std::string& where) const;

    std::vector<Material> materials_;
    std::vector<PairCoefficients> pairs_;
    std::vector<bool> defined_;
    RollingResistance rolling_resistance_ = RollingResistance::relative_spring;
};

/// Throws InputError naming the key and value if a coefficient is outside its range.
void validate(const PairCoefficients& c, const std::string& where);
void validate(const Material& m, const std::string& where);

}  // namespace dipper::dem
