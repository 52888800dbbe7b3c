// Kajiya and Kay 1989, as the survey of hair shading models (../shared/seeds) writes it in the
// factored form: the baseline that model comparisons start from.
//   f_s = M_KK(θi, θr) N_KK(φ),  M_KK = K_d + k_s cos^n(θr + θi) / cos θi,  N_KK = 1,
// a diffuse term from a Lambertian cylinder and an ad hoc specular lobe on the mirror cone
// θr = −θi; it has no azimuthal structure and is not energy conserving (with the energy measure
// of curve scattering functions, cos²θr dθr dφ, a narrow specular lobe carries E(0) cos θi and
// the diffuse term π² K_d at every θi). cos^n is taken of max(0, cos(θr + θi)).
#pragma once

namespace hairlut {

struct KajiyaKayParams {
  double kd = 0.0;        ///< diffuse coefficient K_d ≥ 0
  double ks = 1.0;        ///< specular coefficient k_s ≥ 0
  double exponent = 50;   ///< Phong-like exponent n > 0
  /// Throws DomainError naming the first bad field.
  void validate() const;
  /// The exponent whose lobe cos^n(θr + θi) ≈ exp(−n (2θh)²/2) has the width of a Gaussian of
  /// standard deviation β in θh (Marschner's R lobe): n = 1/(4β²). Domain: β > 0.
  static double exponent_for_width(double beta);
};

/// M_KK(θi, θr) = K_d + k_s max(0, cos(θr + θi))^n / cos θi. Domain: |θi| < π/2 (the specular
/// term diverges at grazing incidence: DomainError there), θr in [−π/2, π/2]. Result finite, ≥ 0.
double kajiya_kay_longitudinal(const KajiyaKayParams& params, double theta_i, double theta_r);

/// N_KK(φ) = 1 (the survey's normalization: no azimuthal dependence).
inline double kajiya_kay_azimuthal(double /*phi*/) { return 1.0; }

/// E(θi) = ∫_{−π}^{π} ∫ M_KK N_KK cos²θr dθr dφ = 2π ∫ M_KK cos²θr dθr, with the energy measure of
/// Marschner-style curve scattering functions (d'Eon 2011 eq. 5). Adaptive quadrature to 1e−10.
/// Domain: |θi| < π/2.
double kajiya_kay_energy(const KajiyaKayParams& params, double theta_i);

}  // namespace hairlut
