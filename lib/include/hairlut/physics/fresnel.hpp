// Exact unpolarized dielectric Fresnel reflectance and the Bravais indices of a circular fiber.
#pragma once

#include <algorithm>
#include <cmath>

namespace hairlut {

/// Unpolarized Fresnel reflectance F(η, cos θi) of a smooth dielectric interface, for light
/// arriving at angle θi in a medium of index n_i on a medium of index n_t, with η = n_t / n_i:
///   F = ½ (r_s² + r_p²),  r_s = (cos θi − η cos θt)/(cos θi + η cos θt),
///   r_p = (η cos θi − cos θt)/(η cos θi + cos θt),  η² sin²θt = sin²θi   (Snell).
/// Total internal reflection (η < 1 and sin θi > η) gives 1.
/// Domain: η > 0, cos θi in [0, 1]. Result in [0, 1]; F(η, 0) = 1.
double fresnel_reflectance(double eta, double cos_theta_i);

/// 1 − F(η, cos θi), evaluated without cancellation (accurate when F is close to 1):
///   1 − r_s² = 4η cos θi cos θt / (cos θi + η cos θt)²,  1 − r_p² = 4η cos θi cos θt / (η cos θi + cos θt)².
/// Same domain as fresnel_reflectance; result in [0, 1].
double fresnel_transmittance(double eta, double cos_theta_i);

namespace detail {
/// fresnel_reflectance and fresnel_transmittance without argument checks, for inner loops whose
/// arguments are in the domain by construction.
inline double fresnel_reflectance_unchecked(double eta, double ci) {
  const double sin2_t = (1.0 - ci) * (1.0 + ci) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;
  const double ct = std::sqrt(1.0 - sin2_t);
  const double rs = (ci - eta * ct) / (ci + eta * ct), rp = (eta * ci - ct) / (eta * ci + ct);
  const double F = 0.5 * (rs * rs + rp * rp);
  return F < 1.0 ? F : 1.0;
}
inline double fresnel_transmittance_unchecked(double eta, double ci) {
  const double sin2_t = (1.0 - ci) * (1.0 + ci) / (eta * eta);
  if (sin2_t >= 1.0) return 0.0;
  const double ct = std::sqrt(1.0 - sin2_t);
  const double num = 4.0 * eta * ci * ct, ds = ci + eta * ct, dp = eta * ci + ct;
  const double T = 0.5 * (num / (ds * ds) + num / (dp * dp));
  return T < 1.0 ? T : 1.0;
}
/// fresnel_bravais without argument checks: F and 1 − F (the latter without cancellation,
/// 1 − F_s² = 4 a cos γi cos γt/(a cos γi + cos γt)², 1 − F_p² = 4 η'' cos γi cos γt/(η'' cos γi + cos γt)²).
inline void fresnel_bravais_unchecked(double inv_eta_prime, double eta_double_prime, double ci, double& F, double& one_minus_F) {
  const double a = inv_eta_prime;
  const double ct = std::sqrt(1.0 - a * a * (1.0 - ci) * (1.0 + ci));  // cos γt ≥ √(1 − a²) > 0
  const double ds = a * ci + ct, dp = eta_double_prime * ci + ct;
  const double fs = (a * ci - ct) / ds, fp = (eta_double_prime * ci - ct) / dp;
  F = std::min(1.0, 0.5 * (fs * fs + fp * fp));
  one_minus_F = std::min(1.0, 2.0 * ci * ct * (a / (ds * ds) + eta_double_prime / (dp * dp)));
}
}  // namespace detail

/// η² − sin²θd for a fiber of index η, evaluated as (η − 1)(η + 1) + cos²θd so that it keeps its
/// digits for η close to 1 and θd close to π/2.
inline double eta_squared_minus_sin2(double eta, double cos_theta_d) {
  return (eta - 1.0) * (eta + 1.0) + cos_theta_d * cos_theta_d;
}

/// Bravais index for the azimuthal (normal-plane) problem: η' = √(η² − sin²θd) / cos θd.
/// Domain: η > 1, θd in [−π/2, π/2]; returns +∞ at |θd| = π/2 (use inverse_bravais_eta_prime there).
double bravais_eta_prime(double eta, double theta_d);

/// 1/η' = cos θd / √(η² − sin²θd); finite on the whole domain (0 at |θd| = π/2).
double inverse_bravais_eta_prime(double eta, double theta_d);

/// Bravais index for the polarization-mixing Fresnel factor of Marschner 2003:
/// η'' = η² cos θd / √(η² − sin²θd). Domain: η > 1, θd in [−π/2, π/2]; 0 at |θd| = π/2.
double bravais_eta_double_prime(double eta, double theta_d);

/// Fresnel reflectance of the normal-plane problem with the two Bravais indices (Marschner 2003
/// Appendix B, Khungurn 2013 §1.1): F = ½ (F_s² + F_p²),
///   F_s = (cos γi − η' cos γt)/(cos γi + η' cos γt),  F_p = (η'' cos γi − cos γt)/(η'' cos γi + cos γt),
///   sin γt = sin γi / η'.
/// Evaluated with 1/η' (finite at grazing θd) as F_s = (cos γi/η' − cos γt)/(cos γi/η' + cos γt).
/// It equals the 3D reflectance F(η, cos θd cos γi) exactly when η' and η'' belong to η and θd
/// (multiply F_s and F_p through by cos θd and √(η² − sin²θd) respectively), which the tests
/// check; the internal reflections of Marschner's A(p, h), F(1/η', 1/η'', γt), equal it too.
/// Domain: 1/η' in [0, 1), η'' ≥ 0 finite, cos γi in [0, 1]. Result in [0, 1]; 1 at cos γi = 0.
double fresnel_bravais(double inv_eta_prime, double eta_double_prime, double cos_gamma_i);

}  // namespace hairlut
