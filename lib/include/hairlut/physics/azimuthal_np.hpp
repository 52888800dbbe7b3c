// d'Eon 2011's roughened azimuthal scattering function N_p (eq. 10):
//   N_p(φ) = ½ ∫_{−1}^{1} A(p, h) D_β(φ − Φ(p, h)) dh,
// by Gauss–Legendre quadrature of a chosen order, by an adaptive reference integrator, and its
// smooth-fiber limit β → 0 by root solving (Marschner 2003: Σ_roots A / |2 dΦ/dh|).
//
// Exact and approximate: the reference integrator is exact to its reported error estimate; the
// Gauss–Legendre form is exact only when its order resolves the detector's width (β/|dΦ/dγ|).
// All forms use the symmetry Φ(p, −h) ≡ −Φ(p, h) (mod 2π) to integrate over h ≥ 0 against
// D(φ − Φ) + D(φ + Φ), which makes N_p(−φ) = N_p(φ) hold exactly.
#pragma once

#include <span>
#include <string_view>
#include <vector>

#include "hairlut/physics/attenuation.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/util/quadrature.hpp"

namespace hairlut {

/// Integration variable of the Gauss–Legendre form.
enum class IntegrationVariable {
  gamma,  ///< γ = asin h: the integrand is smooth (default)
  h       ///< h itself, as d'Eon 2011 integrates (√ end-point behaviour; slower convergence)
};
std::string_view to_string(IntegrationVariable v);
IntegrationVariable parse_integration_variable(std::string_view text, std::string_view what = "variable");

/// N_p(φ) by the Gauss–Legendre rule of the given order over the whole fiber (h in [−1, 1] or γ in
/// [−π/2, π/2]), evaluated in mirror pairs. Domain: p ≥ 0, β > 0 (radians), φ finite (wrapped).
/// Result finite and ≥ 0.
double azimuthal_np(const AttenuationSlice& slice, int p, double beta, double phi, const GaussLegendreRule& rule,
                    IntegrationVariable variable = IntegrationVariable::gamma);

/// N_p(φ) at many (β, φ) for one slice and lobe by the Gauss–Legendre rule: the node factors
/// (which depend on neither β nor φ) are computed once. azimuthal_np() is this with one call.
class NpQuadratureSlab {
 public:
  /// Domain: p ≥ 0. Throws DomainError.
  NpQuadratureSlab(const AttenuationSlice& slice, int p, const GaussLegendreRule& rule,
                   IntegrationVariable variable = IntegrationVariable::gamma);
  /// N_p(φ) for detector width β > 0 (radians) and finite φ.
  double operator()(double beta, double phi) const;

 private:
  std::vector<double> weight_;  // ½ w_i A(p, h_i) (dh/dx)_i, mirror pairs folded
  std::vector<double> phi_;     // Φ(p, h_i)
};

/// Reference value of N_p(φ): adaptive Gauss–Kronrod over γ in [0, π/2], split at every γ where
/// Φ(p, ±γ) ≡ φ (the centres of the detector's peaks) and at the caustic. Tolerance rel_tol
/// relative to N_p(φ) (default 1e−12); converged = false says when it could not reach it.
AdaptiveResult azimuthal_np_reference(const AttenuationSlice& slice, int p, double beta, double phi,
                                      double rel_tol = 1e-12);

/// Breakpoints in γ ∈ [0, π/2] for integrating a detector of width β over the fiber: 0, π/2, the
/// caustic, and at every |γ0| with Φ(p, γ0) ≡ φ for each φ of `phis` the points |γ0| ± w·4^k, where
/// w = β/max(|dΦ/dγ|, 2√β) is the detector's width in γ (√β near a caustic), so that no panel next
/// to a peak or step is more than four times wider than it. Sorted, without duplicates.
std::vector<double> detector_breakpoints(const FiberGeometry& geometry, int p, double beta, std::span<const double> phis);

/// Every γi in [−π/2, π/2] with Φ(p, sin γi) ≡ φ (mod 2π), ascending: one per monotone piece of Φ
/// and multiple of 2π (one or three for TRT, one for R and TT). Found by bracketed TOMS 748 on the
/// pieces between the caustics ±γc, so |Φ − φ − 2πk| is at rounding level.
std::vector<double> azimuthal_roots(const FiberGeometry& geometry, int p, double phi);

/// The smooth-fiber limit of N_p as β → 0: Σ_roots A(p, h) / |2 dΦ/dh| = Σ A cos γ / (2 |dΦ/dγ|).
/// Finite and ≥ 0 except exactly at a caustic azimuth, where the smooth fiber's intensity is
/// infinite (returns +∞).
double azimuthal_np_smooth(const AttenuationSlice& slice, int p, double phi);

/// The residual lobe p ≥ P spread uniformly over φ: N_{≥P} = ½ ∫ A_{≥P} dh / 2π, with the energy
/// integrated by the given rule (see lobe_energies).
double azimuthal_residual_np(const AttenuationSlice& slice, int P, const GaussLegendreRule& energy_rule);

}  // namespace hairlut
