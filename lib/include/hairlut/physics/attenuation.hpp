// Attenuation A(p, h) of the internal paths of a smooth circular fiber (d'Eon 2011 eq. 12–14, in
// the form of ../shared/docs/conventions.md): Fresnel at each interface and absorption along each
// internal segment, for every lobe p ≥ 0, plus the closed-form residual of all lobes p ≥ P.
#pragma once

#include <string_view>

#include "hairlut/physics/fiber_geometry.hpp"

namespace hairlut {

/// Length of one internal segment used for absorption.
enum class AbsorptionPath {
  chord,  ///< 2 cos γt: the chord of the unit circle at refraction angle γt (default; pbrt, Tungsten)
  papers  ///< 2 (1 + cos 2γt) = 4 cos²γt, as printed in Marschner 2003 and d'Eon 2011
};

std::string_view to_string(AbsorptionPath path);
/// Parses "chord" or "papers"; throws DomainError naming `what` otherwise.
AbsorptionPath parse_absorption_path(std::string_view text, std::string_view what = "absorption_path");

/// Fresnel and absorption factors of the paths entering at one offset h = sin γi.
struct PathPoint {
  double gamma_i = 0.0;      ///< γi = asin h
  double cos_gamma_i = 1.0;  ///< cos γi = √(1 − h²)
  double gamma_t = 0.0;      ///< γt = asin(h/η')
  double cos_gamma_t = 1.0;  ///< cos γt
  double f = 0.0;            ///< Fresnel reflectance f = F(η, cos θd cos γi) (d'Eon eq. 14)
  double one_minus_f = 1.0;  ///< 1 − f, evaluated without cancellation
  double T = 1.0;            ///< one-segment transmittance T = exp(−σa' ℓ(γt))
  double one_minus_T = 0.0;  ///< 1 − T = −expm1(−σa' ℓ(γt))

  /// A(0, h) = f;  A(p, h) = (1 − f)² f^{p−1} T^p for p ≥ 1. Domain p ≥ 0; result in [0, 1].
  double attenuation(int p) const;
  /// A_{≥P}(h) = Σ_{p≥P} A(p, h) = (1 − f)² f^{P−1} T^P / (1 − f T), with 1 − fT evaluated as
  /// (1 − f) + f(1 − T); 0 where f = 1 and T = 1 (the limit along the fiber's edge).
  /// Domain P ≥ 1; result in [0, 1].
  double residual_attenuation(int P) const;
  /// Φ(p, h) = 2pγt − 2γi + pπ.
  double exit_azimuth(int p) const { return hairlut::exit_azimuth(p, gamma_i, gamma_t); }
};

/// Everything A(p, h) needs that does not depend on h: the geometry at θd, σa' and the path.
class AttenuationSlice {
 public:
  /// Validates η > 1, θd in [−π/2, π/2], σa ≥ 0 (throws DomainError).
  AttenuationSlice(double eta, double theta_d, double sigma_a, AbsorptionPath path = AbsorptionPath::chord);

  const FiberGeometry& geometry() const { return geometry_; }
  double sigma_a() const { return sigma_a_; }
  double sigma_a_prime() const { return sigma_a_prime_; }
  AbsorptionPath path() const { return path_; }

  /// The path factors at γi in [−π/2, π/2] (h = sin γi). Preferred inside integrals over γ:
  /// cos γi keeps its digits at the fiber's edge.
  PathPoint at_gamma(double gamma_i) const;
  /// The path factors at offset h in [−1, 1].
  PathPoint at_h(double h) const;

 private:
  PathPoint evaluate(double h, double gamma_i, double cos_gamma_i) const;

  FiberGeometry geometry_;
  double sigma_a_;
  double sigma_a_prime_;
  AbsorptionPath path_;
};

/// ℓ_min: the length of the shortest internal segment, at the fiber's edge h = ±1 where
/// sin γt = 1/η' (2 cos γt for the chord, 4 cos²γt for the papers' form). Exact.
double edge_segment_length(const FiberGeometry& geometry, AbsorptionPath path);

/// F = T(h = ±1)^p: lobe p's least absorption, along its shortest internal segments (at the fiber's
/// edge, where cos γt is smallest), so that A(p, h) / F ≤ (1 − f)² f^{p−1} at every h (and the
/// residual's A_{≥P} / T(±1)^P likewise). Exact; 1 for p = 0 or σa = 0. Domain p ≥ 0.
double least_absorption(const AttenuationSlice& slice, int p);

}  // namespace hairlut
