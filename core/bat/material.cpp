#include "core/bat/material.hpp"

#include <cmath>

#include "core/geometry_format.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core {
namespace {

// Wood: Forest Products Laboratory, "Wood Handbook: Wood as an Engineering
// Material", General Technical Report FPL-GTR-190, USDA Forest Service (2010).
// Table 5-3a gives specific gravity G (oven-dry weight, volume at 12 %
// moisture) and the modulus of elasticity at 12 % moisture; the density of the
// wood as used (12 % moisture) is G * 1000 kg/m^3 * 1.12. Table 5-1 gives the
// ratio G_LR / E_L and Table 5-2 Poisson's ratio nu_LR.
Material Wood(std::string name, double specific_gravity, double modulus_pa, double g_lr_over_e_l,
              double nu_lr, std::string species) {
  Material m;
  m.name = std::move(name);
  m.density_kg_m3 = specific_gravity * 1000.0 * 1.12;
  m.youngs_modulus_pa = modulus_pa;
  m.shear_modulus_pa = g_lr_over_e_l * modulus_pa;
  m.poissons_ratio = nu_lr;
  m.cor = 0.5;
  m.kind = MaterialKind::kWood;
  m.base = m.name;
  m.source =
      "USDA Forest Products Laboratory, Wood Handbook: Wood as an Engineering Material, "
      "FPL-GTR-190 (2010), " +
      species + " at 12 % moisture: Table 5-3a specific gravity " + FormatNumber(specific_gravity) +
      " and modulus of elasticity " + FormatNumber(modulus_pa / 1e9) +
      " GPa; density = G x 1000 kg/m3 x 1.12 (moisture "
      "included); Table 5-1 G_LR/E_L = " +
      FormatNumber(g_lr_over_e_l) + "; Table 5-2 nu_LR = " + FormatNumber(nu_lr) +
      ". COR 0.5: the value the seed paper uses for a wooden bat against a baseball.";
  return m;
}

// The woods (SI): the Wood Handbook's species, the bat-grade maple billet and the seed paper's
// wood, appended to *out in the catalogue's order.
void AddWoods(std::vector<Material>* out) {
  out->push_back(Wood("ash", 0.60, 12.0e9, 0.109, 0.371, "white ash (Fraxinus americana)"));
  out->push_back(Wood("hard-maple", 0.63, 12.6e9, 0.111, 0.424, "sugar maple (Acer saccharum)"));
  out->push_back(
      Wood("yellow-birch", 0.62, 13.9e9, 0.074, 0.426, "yellow birch (Betula alleghaniensis)"));

  // Bat-grade maple: the properties a finite-element study of MLB bats gives billets of the
  // density MLB approves, from tests (four-point bending, Charpy) of billets by UMass Lowell's
  // Baseball Research Center with the US Forest Products Laboratory. Unlike the Wood
  // Handbook's small clear specimens (hard-maple: 12.6 GPa, 706 kg/m3), these are the wood
  // bats are turned from. The study's pairs (density, E_L) in psi and lb/in3 per profile:
  // (0.0243, 2,250,424), (0.0230, 2,198,507), (0.0236, 2,220,880), (0.0214, 2,135,444);
  // this entry is its "Profile B" pair, the middle of the four.
  constexpr double kPsi = 6894.757293168;  // Pa per psi
  Material billet;
  billet.name = "maple-bat-billet";
  billet.density_kg_m3 = 637.0;  // 0.637 g/cm3 (0.0230 lb/in3)
  billet.density_min_kg_m3 = 592.0;
  billet.density_max_kg_m3 = 673.0;
  billet.youngs_modulus_pa = 2198507.0 * kPsi;  // E_L, 15.16 GPa
  billet.shear_modulus_pa = 244034.0 * kPsi;    // G_LT, 1.683 GPa
  billet.poissons_ratio = 0.476;
  billet.cor = 0.5;
  billet.kind = MaterialKind::kWood;
  // Its species' entry, so league rules (core/optimize/rules.cpp's allowed woods, which read
  // the base) see sugar maple.
  billet.base = "hard-maple";
  billet.source =
      "Bat-grade sugar maple (Acer saccharum): UMass Lowell Baseball Research Center, "
      "'An Investigation of Wood Baseball Bat Durability as a Function of Bat Profile and Slope "
      "of Grain Using Finite Element Modeling and Statistical Analysis', Appl. Sci. 12(7), 3494 "
      "(2022), doi:10.3390/app12073494, Appendix A (its LS-DYNA *MAT_WOOD inputs, from the "
      "group's bend and Charpy tests of MLB-grade billets with the US Forest Products "
      "Laboratory, Appl. Sci. 8(11), 2256 (2018)): its "
      "Profile B column, density 0.637 g/cm3, E_L = 2,198,507 psi (15.16 GPa), "
      "G_LT = 244,034 psi (1.683 GPa), nu = 0.476; density range 0.592-0.673 g/cm3 across the "
      "study's four profiles. COR 0.5 as for the other woods.";
  out->push_back(billet);

  Material paper;
  paper.name = "paper-wood";
  paper.density_kg_m3 = 649.0;
  paper.youngs_modulus_pa = 1.814e10;
  paper.poissons_ratio = 0.25;
  paper.cor = 0.5;
  paper.kind = MaterialKind::kWood;
  paper.base = paper.name;
  paper.source =
      "Seed paper (Mathematical model research of baseball sweet spot based on "
      "mechanical analysis and MATLAB simulation), Table 2: density 649 kg/m3, "
      "E = 1.814e10 N/m2; Poisson's ratio 0.25 from its Hertz-contact section; "
      "e = 0.5 as used with its rigid model (shared/docs/paper-notes.md).";
  out->push_back(paper);
}

// The hollow bats' shell materials (SI): the 7xxx alloys and the carbon/epoxy fabric, each
// with the BBCOR rule as its COR, appended to *out.
void AddShellMaterials(std::vector<Material>* out) {
  const std::string bbcor =
      " COR 0.5: the NCAA/NFHS BBCOR standard limits a certified bat's ball-bat coefficient of "
      "restitution to 0.50; it is a rule for the whole bat, not a property of the alloy.";
  Material al7046;
  al7046.name = "aluminium-7046";
  al7046.density_kg_m3 = 2790.0;
  al7046.youngs_modulus_pa = 71.0e9;
  al7046.poissons_ratio = 0.33;
  al7046.cor = 0.5;
  al7046.source =
      "Aluminum Association, International Alloy Designations and Chemical Composition Limits "
      "(Teal Sheets): 7046 = Al-6.6-7.6Zn-1.0-1.6Mg-0.10-0.18Zr. No public datasheet lists its "
      "physical constants: density 2.79 g/cm3 and E = 71 GPa are taken between the datasheet "
      "values of the neighbouring Al-Zn-Mg alloys 7005 (2.78 g/cm3, 72 GPa) and 7075 "
      "(2.81 g/cm3, 71.7 GPa); nu = 0.33 as for the 7xxx series (ASM Handbook vol. 2)." +
      bbcor;
  al7046.kind = MaterialKind::kMetal;
  al7046.base = al7046.name;
  out->push_back(al7046);

  Material al7050;
  al7050.name = "aluminium-7050";
  al7050.density_kg_m3 = 2830.0;
  al7050.youngs_modulus_pa = 71.7e9;
  al7050.shear_modulus_pa = 26.9e9;
  al7050.poissons_ratio = 0.33;
  al7050.cor = 0.5;
  al7050.source =
      "Aluminum 7050-T7451 typical properties (ASM Aerospace Specification Metals / "
      "MatWeb datasheet; Alcoa 7050 alloy datasheet): density 2.83 g/cm3, "
      "E = 71.7 GPa, G = 26.9 GPa, nu = 0.33." +
      bbcor;
  al7050.kind = MaterialKind::kMetal;
  al7050.base = al7050.name;
  out->push_back(al7050);

  // Issue 35: the catalogue's composite. A bat's lay-up varies along it and between models; this
  // is one laminate, isotropic here with the fabric's in-plane values (the axial modulus the
  // beam bends with and the hoop modulus the barrel rings with are both E1 = E2).
  Material carbon;
  carbon.name = "carbon-epoxy-fabric";
  carbon.density_kg_m3 = 1600.0;
  carbon.youngs_modulus_pa = 70.0e9;
  carbon.shear_modulus_pa = 5.0e9;
  carbon.poissons_ratio = 0.10;
  carbon.cor = 0.5;
  carbon.kind = MaterialKind::kComposite;
  carbon.base = carbon.name;
  carbon.source =
      "Standard carbon fibre 0/90 fabric in epoxy (120 C cure, fibre volume fraction 50 %): "
      "E1 = E2 = 70 GPa, in-plane shear modulus G12 = 5 GPa, major Poisson's ratio 0.10 "
      "(Performance Composites Ltd, 'Mechanical properties of carbon fibre composite "
      "materials', performance-composites.com/carbonfibre/mechanicalproperties_2.asp, column "
      "'Std CF Fabric'); density 1600 kg/m3 (SubsTech, 'Epoxy matrix composite reinforced by 70% "
      "carbon fibers': 1.6e3 kg/m3; a 50 % fabric laminate is a few per cent lighter). One "
      "laminate standing for a composite bat's shell; its lay-up is not modelled." +
      bbcor;
  out->push_back(carbon);
}

// The fill materials (SI, no COR): cork and rubber, appended to *out.
void AddFills(std::vector<Material>* out) {
  Material cork;
  cork.name = "cork";
  cork.density_kg_m3 = 290.0;
  cork.density_min_kg_m3 = 260.0;
  cork.density_max_kg_m3 = 320.0;
  cork.youngs_modulus_pa = 2.0e7;
  cork.poissons_ratio = 0.0;
  cork.source =
      "Density 260-320 kg/m3 (nominal: the midpoint 290) from the seed paper's cork "
      "section; E = 20 MPa and Poisson's ratio close to 0 from L. J. Gibson and "
      "M. F. Ashby, Cellular Solids: Structure and Properties, 2nd ed., Cambridge "
      "University Press (1997), ch. 12, after Gibson, Easterling and Ashby, "
      "Proc. R. Soc. Lond. A 377 (1981) 99-117. A fill material: no COR.";
  cork.kind = MaterialKind::kFill;
  cork.base = cork.name;
  out->push_back(cork);

  Material rubber;
  rubber.name = "rubber";
  rubber.density_kg_m3 = 1100.0;
  rubber.density_min_kg_m3 = 930.0;
  rubber.density_max_kg_m3 = 1250.0;
  rubber.youngs_modulus_pa = 5.0e6;
  rubber.poissons_ratio = 0.499;
  rubber.source =
      "A. N. Gent (ed.), Engineering with Rubber, 3rd ed., Hanser (2012), ch. 1-2: "
      "soft vulcanised rubber has E of about 1-10 MPa and is nearly incompressible "
      "(nu = 0.499); density 930 kg/m3 (unfilled natural rubber) to about "
      "1250 kg/m3 (carbon-black filled). 1100 kg/m3 and 5 MPa are mid-range "
      "values. A fill material: no COR.";
  rubber.kind = MaterialKind::kFill;
  rubber.base = rubber.name;
  out->push_back(rubber);
}

// The whole catalogue, in its order: the woods, the shell materials, the fills.
std::vector<Material> BuildCatalogue() {
  std::vector<Material> out;
  AddWoods(&out);
  AddShellMaterials(&out);
  AddFills(&out);
  return out;
}

// Common names of catalogue entries (alias, entry): the trade's short names.
struct MaterialAlias {
  const char* alias;
  const char* name;
};
constexpr MaterialAlias kMaterialAliases[] = {
    {"maple", "hard-maple"},
    {"sugar-maple", "hard-maple"},
    {"birch", "yellow-birch"},
    {"white-ash", "ash"},
};

}  // namespace

const char* MaterialKindName(MaterialKind kind) {
  switch (kind) {
    case MaterialKind::kWood:
      return "wood";
    case MaterialKind::kMetal:
      return "metal";
    case MaterialKind::kComposite:
      return "composite";
    case MaterialKind::kFill:
      return "fill";
  }
  return "wood";
}

bool Material::Validate(Refusal* why) const {
  if (!std::isfinite(density_kg_m3))
    return Refuse(why, "density_kg_m3", density_kg_m3, "must be finite");
  if (!(density_kg_m3 > 0.0))
    return Refuse(why, "density_kg_m3", density_kg_m3, "must be positive");
  if (!std::isfinite(youngs_modulus_pa)) {
    return Refuse(why, "youngs_modulus_pa", youngs_modulus_pa, "must be finite");
  }
  if (!(youngs_modulus_pa > 0.0)) {
    return Refuse(why, "youngs_modulus_pa", youngs_modulus_pa, "must be positive");
  }
  if (!std::isfinite(shear_modulus_pa)) {
    return Refuse(why, "shear_modulus_pa", shear_modulus_pa, "must be finite");
  }
  if (shear_modulus_pa < 0.0) {
    return Refuse(why, "shear_modulus_pa", shear_modulus_pa,
                  "must be non-negative (0 = derive from poissons_ratio)");
  }
  if (!std::isfinite(poissons_ratio)) {
    return Refuse(why, "poissons_ratio", poissons_ratio, "must be finite");
  }
  if (!(poissons_ratio > -1.0 && poissons_ratio < 0.5)) {
    return Refuse(why, "poissons_ratio", poissons_ratio,
                  "must be greater than -1 and less than 0.5");
  }
  if (cor.has_value()) {
    if (!std::isfinite(*cor)) return Refuse(why, "cor", *cor, "must be finite");
    if (*cor < 0.0 || *cor > 1.0) return Refuse(why, "cor", *cor, "must be between 0 and 1");
  }
  if (!std::isfinite(density_min_kg_m3)) {
    return Refuse(why, "density_min_kg_m3", density_min_kg_m3, "must be finite");
  }
  if (density_min_kg_m3 < 0.0) {
    return Refuse(why, "density_min_kg_m3", density_min_kg_m3, "must be non-negative (0 = none)");
  }
  if (!std::isfinite(density_max_kg_m3)) {
    return Refuse(why, "density_max_kg_m3", density_max_kg_m3, "must be finite");
  }
  if (density_max_kg_m3 < 0.0) {
    return Refuse(why, "density_max_kg_m3", density_max_kg_m3, "must be non-negative (0 = none)");
  }
  if (density_min_kg_m3 > 0.0 && density_max_kg_m3 > 0.0 && density_min_kg_m3 > density_max_kg_m3) {
    return Refuse(why, "density_min_kg_m3", density_min_kg_m3,
                  "must not exceed density_max_kg_m3 = " + FormatNumber(density_max_kg_m3));
  }
  return true;
}

bool Material::ValidateSize(Refusal* why) const {
  if (!Validate(why)) return false;
  return CheckInRange(why, "density_kg_m3", density_kg_m3, 0.0, kMaxDensityKgM3,
                      /*lo_open=*/true) &&
         CheckInRange(why, "youngs_modulus_pa", youngs_modulus_pa, 0.0, kMaxModulusPa, true) &&
         CheckInRange(why, "shear_modulus_pa", shear_modulus_pa, 0.0, kMaxModulusPa, false,
                      " (0 = derive from poissons_ratio)");
}

double Material::EffectiveShearModulusPa() const {
  if (shear_modulus_pa > 0.0) return shear_modulus_pa;
  return youngs_modulus_pa / (2.0 * (1.0 + poissons_ratio));
}

const std::vector<Material>& MaterialCatalogue() {
  static const std::vector<Material> catalogue = BuildCatalogue();
  return catalogue;
}

std::optional<Material> FindMaterial(std::string_view name) {
  for (const MaterialAlias& a : kMaterialAliases) {
    if (name == a.alias) name = a.name;
  }
  for (const Material& m : MaterialCatalogue()) {
    if (m.name == name) return m;
  }
  return std::nullopt;
}

std::vector<std::string> MaterialAliases(std::string_view name) {
  std::vector<std::string> out;
  for (const MaterialAlias& a : kMaterialAliases) {
    if (name == a.name) out.emplace_back(a.alias);
  }
  return out;
}

std::string MaterialNamesList() {
  std::string out;
  for (const Material& m : MaterialCatalogue()) {
    out += (out.empty() ? "" : ", ") + m.name;
    const auto aliases = MaterialAliases(m.name);
    for (std::size_t i = 0; i < aliases.size(); ++i) {
      out += (i == 0 ? " (" : ", ") + aliases[i] + (i + 1 == aliases.size() ? ")" : "");
    }
  }
  return out;
}

Material EmptyFillMaterial() {
  Material m;
  m.name = "empty";
  m.poissons_ratio = 0.0;
  m.source = "An empty bore: no material.";
  return m;
}

}  // namespace sweetspot::core
