// Geometry of refraction through a smooth circular fiber (Marschner 2003 §4, d'Eon 2011 eq. 8):
// the azimuthal offsets γi, γt, the exit azimuth Φ(p, h), its derivative and caustics, and the
// longitudinal refraction angle θt.
#pragma once

#include <cmath>
#include <numbers>

namespace hairlut {

/// Quantities of the fiber's cross-section that depend on η and θd only (not on h, p or φ).
struct FiberGeometry {
  double eta = 1.55;          ///< index of refraction η > 1
  double theta_d = 0.0;       ///< longitudinal difference angle θd in [−π/2, π/2] (radians)
  double cos_theta_d = 1.0;   ///< cos θd
  double inv_eta_prime = 0.0; ///< 1/η' = cos θd / √(η² − sin²θd), in [0, 1/η]
  double sin_theta_t = 0.0;   ///< sin θt = sin θd / η (longitudinal refraction)
  double cos_theta_t = 1.0;   ///< cos θt = √(η² − sin²θd) / η

  /// Builds the geometry, validating η > 1 and θd in [−π/2, π/2] (throws DomainError).
  static FiberGeometry make(double eta, double theta_d);
};

/// γi = asin(h): azimuthal angle of incidence at offset h in [−1, 1].
inline double gamma_incident(double h) { return std::asin(h); }

/// γt = asin(h/η'): azimuthal refraction angle (Snell's law in the normal plane with the Bravais
/// index η'). Domain: h in [−1, 1], 1/η' in [0, 1).
inline double gamma_transmitted(double h, double inv_eta_prime) { return std::asin(h * inv_eta_prime); }

/// Φ(p, h) = 2pγt − 2γi + pπ (d'Eon 2011 eq. 8): exit azimuth relative to the incident azimuth of
/// the path with p internal segments, not wrapped to [−π, π].
inline double exit_azimuth(int p, double gamma_i, double gamma_t) {
  return 2.0 * p * gamma_t - 2.0 * gamma_i + p * std::numbers::pi;
}

/// dΦ/dγi = 2p (cos γi / (η' cos γt)) − 2, the derivative of Φ with respect to γi (h = sin γi).
/// dΦ/dh is this divided by cos γi.
inline double exit_azimuth_derivative(int p, double cos_gamma_i, double cos_gamma_t, double inv_eta_prime) {
  return 2.0 * p * inv_eta_prime * cos_gamma_i / cos_gamma_t - 2.0;
}

/// The caustic offset of lobe p: the γi ≥ 0 where dΦ/dγi = 0, from
/// sin²γc = (p² − η'²)/(p² − 1) (for p = 2 this is Descartes' h_c² = (4 − η'²)/3).
/// Returns a negative value when lobe p has no caustic (p < 2 or η' ≥ p).
double caustic_gamma(int p, const FiberGeometry& g);

/// Reduced absorption σa' = σa / cos θt: a path segment of azimuthal length ℓ has
/// transmittance exp(−σa' ℓ). Domain: σa ≥ 0.
inline double reduced_absorption(double sigma_a, const FiberGeometry& g) { return sigma_a / g.cos_theta_t; }

}  // namespace hairlut
