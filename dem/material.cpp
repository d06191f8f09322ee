#include "dem/material.h"

#include "core/errors.h"

namespace dipper::dem {

void validate(const Material& m, const std::string& where)
{
    const std::string at = "material '" + m.name + "', " + where;
    if (m.name.empty()) throw InputError(concat("material name must not be empty (", where, ")"));
    if (m.is_surface) return;
    require_positive(m.density_kg_per_m3, "density_kg_per_m3", at);
    require_positive(m.youngs_modulus_Pa, "youngs_modulus_Pa", at);
    // nu < 0.5 keeps the bulk modulus finite; nu > -1 keeps it positive.
    if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
        throw InputError(concat("poisson_ratio must be in (-1, 0.5); got ", m.poisson_ratio, " (", at, ")"));
}

void validate(const PairCoefficients& c, const std::string& where)
{
    require_positive(c.normal_stiffness_scale, "normal_stiffness_scale (C_norm)", where);
    require_positive(c.tangential_stiffness_scale, "tangential_stiffness_scale (C_tan)", where);
    require_non_negative(c.friction, "friction (mu)", where);
    require_non_negative(c.rolling_friction, "rolling_friction (mu_roll)", where);
    require_in_range(c.normal_damping_ratio, 0.0, 1.0, "normal_damping_ratio (D_n)", where);
    require_in_range(c.tangential_damping_ratio, 0.0, 1.0, "tangential_damping_ratio (D_t)", where);
}

MaterialIndex MaterialTable::add(const Material& material)
{
    validate(material, "MaterialTable::add");
    for (const Material& m : materials_)
        if (m.name == material.name) throw InputError(concat("material '", material.name, "' is defined twice"));
    if (materials_.size() >= 65535) throw InputError("too many materials (at most 65535)");

    // grow the square pair table, keeping what was set
    const std::size_t n = materials_.size(), n1 = n + 1;
    std::vector<PairCoefficients> pairs(n1 * n1);
    std::vector<bool> defined(n1 * n1, false);
    for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = 0; b < n; ++b) {
            pairs[a * n1 + b] = pairs_[a * n + b];
            defined[a * n1 + b] = defined_[a * n + b];
        }
    pairs_.swap(pairs);
    defined_.swap(defined);
    materials_.push_back(material);
    return static_cast<MaterialIndex>(n);
}

void MaterialTable::check_index(MaterialIndex i, const std::string& where) const
{
    if (i >= materials_.size())
        throw InputError(concat("material index ", i, " does not exist; the table has ", materials_.size(),
                                " materials (", where, ")"));
}

void MaterialTable::set_pair(MaterialIndex a, MaterialIndex b, const PairCoefficients& c, const std::string& where)
{
    check_index(a, where);
    check_index(b, where);
    const std::string at = "pair '" + materials_[a].name + "'-'" + materials_[b].name + "', " + where;
    validate(c, at);
    if (materials_[a].is_surface && materials_[b].is_surface)
        throw InputError(concat("pair coefficients between two surface materials are not used (", at, ")"));
    const std::size_t n = materials_.size();
    pairs_[a * n + b] = pairs_[b * n + a] = c;
    defined_[a * n + b] = defined_[b * n + a] = true;
}

void MaterialTable::set_pair(const std::string& a, const std::string& b, const PairCoefficients& c,
                             const std::string& where)
{
    set_pair(index_of(a), index_of(b), c, where);
}

MaterialIndex MaterialTable::index_of(const std::string& name) const
{
    std::string known;
    for (std::size_t i = 0; i < materials_.size(); ++i) {
        if (materials_[i].name == name) return static_cast<MaterialIndex>(i);
        known += (i ? ", " : "") + materials_[i].name;
    }
    throw InputError(concat("unknown material '", name, "'; known: ", known.empty() ? "(none)" : known));
}

const PairCoefficients& MaterialTable::pair(MaterialIndex a, MaterialIndex b) const
{
    check_index(a, "pair lookup");
    check_index(b, "pair lookup");
    if (!has_pair(a, b))
        throw InputError(concat("no contact coefficients for material pair '", materials_[a].name, "'-'",
                                materials_[b].name, "'"));
    return pairs_[a * materials_.size() + b];
}

MaterialTable MaterialTable::aitik_copper_ore(double particle_density_kg_per_m3)
{
    MaterialTable t;
    // Table 2, "for all rocks": rho 3700 kg/m3 (to be scaled to bulk density 1903 kg/m3), E 45 GPa, nu 0.3
    t.add({"ore", particle_density_kg_per_m3, 45e9, 0.3, false});
    t.add({"rock", particle_density_kg_per_m3, 45e9, 0.3, false});
    t.add({"ground", 0.0, 0.0, 0.0, true});
    t.add({"bucket", 0.0, 0.0, 0.0, true});
    t.add({"truck", 0.0, 0.0, 0.0, true});
    t.add({"steel", 0.0, 0.0, 0.0, true});

    const std::string src = "Aitik copper ore preset (thesis Table 2)";
    t.set_pair("ore", "ore", table2::ore_ore, src);
    t.set_pair("ore", "ground", table2::ore_ground, src);
    t.set_pair("ore", "bucket", table2::ore_bucket, src);
    t.set_pair("ore", "rock", table2::ore_rock, src);
    t.set_pair("ore", "truck", table2::ore_truck, src);
    t.set_pair("ore", "steel", table2::ore_steel, src);
    return t;
}

}  // namespace dipper::dem
