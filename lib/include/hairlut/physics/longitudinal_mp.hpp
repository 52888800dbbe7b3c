// Longitudinal scattering functions M_p: d'Eon 2011's energy-conserving M_p (eq. 7) with cuticle
// tilt, and Marschner 2003's Gaussian M_p (eq. 3–4 of d'Eon) kept for comparison.
//
// Tilt convention (hairlut, following ../shared/docs/conventions.md): a lobe's tilt α_p shifts its
// specular cone in θr, M_p(θi, θr) = M(v_p, θi, θr − α_p), so the lobe of incidence θi peaks near
// θr = −θi + α_p. Worked example: α_R = −4° and θi = 30° put the narrow-roughness R peak at
// θr = −34°. Marschner 2003 Table 1 lists shifts of θh (its lobe is g(θh − α)); those convert as
// α_p = 2 α_p^Marschner, e.g. its α_R = −5° is α_R = −10° here. pbrt-v4's scale angle α evaluates R
// at θo − 2α, TT at θo + α and TRT at θo + 4α, i.e. α_R = 2α, α_TT = −α, α_TRT = −4α here
// (when both frames measure θ towards the same end of the fiber).
#pragma once

namespace hairlut {

/// d'Eon 2011 eq. 7 with v = β²:
///   M(v, θi, θr) = csch(1/v)/(2v) · exp(−sin θi sin θr / v) · I0(cos θi cos θr / v),
/// evaluated in the exactly equivalent stable form (conventions.md), with x = cos θi cos θr / v,
///   M = exp(−2 sin²((θi + θr)/2) / v) · I0e(x) / (v · (−expm1(−2/v))).
/// ∫_{−π/2}^{π/2} M cos θr dθr = 1 for every θi and v. Symmetric in θi, θr.
/// Domain: v ≥ 2.2e−308 (every positive normal double), finite; θi, θr in [−π/2, π/2]
/// (end points included). Result finite and ≥ 0 (0 where it underflows). Throws DomainError.
double longitudinal_deon(double v, double theta_i, double theta_r);

/// The tilted lobe M(v, θi, θ*) with θ* = θr − α folded back into [−π/2, π/2] across the pole
/// (θ* = π − (θr − α) above π/2, −π − (θr − α) below −π/2): the inclination of the exit direction
/// rotated by α, as pbrt does with |cos θ|. Only approximately normalized near grazing θr.
/// Domain: as longitudinal_deon, and α in [−π/2, π/2].
double longitudinal_deon_tilted(double v, double alpha, double theta_i, double theta_r);

/// Folds θ in [−π, π] into [−π/2, π/2] across the poles (the inclination of the same direction).
double fold_inclination(double theta);

/// Argument of Marschner's Gaussian M_p.
enum class GaussianArgument {
  theta_h,     ///< g(β; θh − α): Marschner 2003 as published (≈ twice the energy at low roughness)
  two_theta_h  ///< g(β; 2(θh − α)): the θh → 2θh fix of Zinke & Weber (d'Eon §4.1)
};

/// Marschner's Gaussian longitudinal function with the 1/cos²θd factor,
///   M_G(β; θi, θr) = g(β; θh − α) / cos²θd  or  g(β; 2(θh − α)) / cos²θd,
/// g(β; x) = exp(−x²/(2β²)) / (√(2π) β), θh = (θi + θr)/2, θd = (θr − θi)/2, α a shift of θh
/// (Marschner's convention). Its energy measure is cos²θr dθr (see longitudinal_energy_gaussian);
/// NOT energy conserving. Domain: β ≥ 1e−12, |α| ≤ π/2, θi, θr in [−π/2, π/2]. Result finite, ≥ 0.
double longitudinal_gaussian(double beta, double alpha, double theta_i, double theta_r, GaussianArgument argument);

}  // namespace hairlut
