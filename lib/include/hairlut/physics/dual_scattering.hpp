// Mean energy per lobe and the dual-scattering quantities of Zinke, Yuksel, Weber and Keyser 2008
// ("Dual scattering approximation for fast multiple scattering in hair"), computed from hairlut's
// own M_p and N_p by deterministic quadrature. docs/dual-scattering.md states every definition.
//
// Normalisation: hairlut's S integrates to the directional albedo, E(θi) = ∫∫ S cos θr dφ dθr.
// Zinke's eq. 6 writes ā_f(θ) = (1/π) ∫ ∫_{Ω_f} f_s cos θ' dω' dφ, an average over a half-turn of
// incident azimuths; for a circular fiber S depends only on φ = φr − φi, so that average is the
// integrand itself and ā_f, ā_b below are Zinke's with hairlut's S for f_s: ā_f + ā_b = E(θi).
//
// Halves of the azimuth circle: backward |φ| ≤ π/2 (the light returns to the side it came from),
// forward π/2 < |φ| ≤ π.
//
//   E_p(θi)   = ∫ M_p(θi, θr) e_p(θd) cos θr dθr,  e_p = ½∫A(p, h) dh          (mean energy of lobe p)
//   a_{b,p}   = ∫ M_p(θi, θr) b_p(θd) cos θr dθr,  b_p = ∫_{|φ|≤π/2} N_p dφ     (Zinke eq. 11, per lobe)
//   a_{f,p}   = ∫ M_p(θi, θr) f_p(θd) cos θr dθr,  f_p = ∫_{|φ|>π/2} N_p dφ     (Zinke eq. 6, per lobe)
//   ā_f = Σ_p a_{f,p},  ā_b = Σ_p a_{b,p}
//   α_f = Σ_p a_{f,p} α_p / ā_f,  β_f² = Σ_p a_{f,p} β_{m,p}² / ā_f  (and b)      (Zinke eq. 12–13)
//   A_b = ā_b ā_f²/(1 − ā_f²) + ā_b³ ā_f²/(1 − ā_f²)³                           (Zinke eq. 14)
//   Δ_b = α_b (1 − 2ā_b²/(1 − ā_f²)²) + α_f (2(1 − ā_f²)² + 4ā_f² ā_b²)/(1 − ā_f²)³  (Zinke eq. 16)
//   σ_b = (1 + d_b ā_f²) (ā_b √(2β_f² + β_b²) + ā_b³ √(2β_f² + 3β_b²)) / (ā_b + ā_b³)  (Zinke eq. 17,
//         with the dimensionally consistent denominator; see docs/dual-scattering.md)
// α_p is hairlut's tilt (a shift of the cone in θr) and β_{m,p} the longitudinal width in θr, so α_f,
// α_b, Δ_b and σ_b are shifts and widths in θr; Zinke's θh convention (Marschner's M_p(θh − α)) is
// half of each (a quarter of each β²).
//
// The residual lobe p ≥ P is uniform in φ (conventions.md), so b = f = e/2 for it exactly.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "hairlut/physics/attenuation.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/util/quadrature.hpp"

namespace hairlut {

/// Mass of the wrapped-normal detector D_β on the backward half,
///   W_b(Φ; β) = ∫_{−π/2}^{π/2} D_β(φ − Φ) dφ = Σ_k P(−π/2 ≤ Φ + 2πk + βZ ≤ π/2),  Z ~ N(0, 1),
/// evaluated as differences of normal tails (erfc) over the images that matter (β ≤ 1.5) or by its
/// Fourier series ½ + (2/π) Σ_{n odd} (−1)^{(n−1)/2} e^{−n²β²/2} cos(nΦ)/n (β > 1.5).
/// Domain: β > 0 finite, Φ finite. Result in [0, 1].
double detector_mass_backward(double beta, double Phi);

/// The forward half, W_f(Φ; β) = ∫_{π/2 < |φ| ≤ π} D_β(φ − Φ) dφ = Σ_k P(π/2 ≤ Φ + 2πk + βZ ≤ 3π/2),
/// by its own sum (not 1 − W_b). Domain and result as detector_mass_backward.
double detector_mass_forward(double beta, double Phi);

/// The two halves of ∫ N_p dφ: backward ∫_{|φ|≤π/2} N_p dφ and forward ∫_{|φ|>π/2} N_p dφ.
struct HalfRangeEnergy {
  double backward = 0.0;
  double forward = 0.0;
};

/// Half-range integrals from the Fourier coefficients C_n of N_p (azimuthal_fourier.hpp):
///   backward = C_0/2 + (2/π) Σ_{n odd} (−1)^{(n−1)/2} e^{−n²β²/2} C_n / n,  forward = C_0/2 − (2/π) Σ (…),
/// from ∫_{|φ|≤π/2} cos nφ dφ = 2 sin(nπ/2)/n. `coefficients` holds C_0 … C_N with `stride` between
/// consecutive n; the sum stops at fourier_terms(β, tolerance) (truncation below tolerance · C_0).
/// Domain: β > 0, 0 < tolerance < 1. Results clamped to ≥ 0 (roundoff only).
HalfRangeEnergy half_range_fourier(std::span<const double> coefficients, std::size_t stride, double beta, double tolerance);

/// Half-range integrals by direct quadrature, for any β > 0 (the small-β method of the baker and
/// the reference of the tests): backward = ∫_0^{π/2} A(p, sin γ) W_b(Φ(p, γ); β) cos γ dγ, forward the
/// same with W_f (A is even in h and W_b, W_f are even in Φ, and Φ(p, −h) ≡ −Φ(p, h)), by adaptive
/// Gauss–Kronrod split at every γ where Φ(p, γ) ≡ ±π/2 (the edges of the halves) and at the caustic,
/// for all σa of `sigmas` at once. out[2k] = backward, out[2k + 1] = forward of sigmas[k].
/// Returns whether every component met rel_tol (absolute floor 1e−15).
/// Domain: η > 1, θd in [−π/2, π/2], p ≥ 0, β > 0, σa ≥ 0.
bool half_range_direct(const FiberGeometry& geometry, AbsorptionPath path, int p, std::span<const double> sigmas, double beta,
                       std::span<double> out, double rel_tol = 1e-11);

/// One slice (η, θd, σa, path) and lobe: the convenience form of half_range_direct.
HalfRangeEnergy half_range_direct(const AttenuationSlice& slice, int p, double beta, double rel_tol = 1e-11);

/// Zinke 2008's backscattering terms (up to three scattering events) from the averages.
struct ZinkeBackscatter {
  double A_b = 0.0;            ///< eq. 14
  double delta_b = 0.0;        ///< eq. 16 (same units as α_f, α_b)
  double sigma_b = 0.0;        ///< eq. 17 with the denominator ā_b + ā_b³
  double sigma_b_mixed = 0.0;  ///< eq. 17 with the denominator ā_b + ā_b³(2β_f + 3β_b) of public implementations
};

/// The terms above from ā_f, ā_b ∈ [0, 1], α_f, α_b (radians), β_f², β_b² ≥ 0 and the density factor
/// d_b ∈ [0, 1]. 1 − ā_f² is evaluated as (1 − ā_f)(1 + ā_f) and floored at 1e−12, so the terms stay
/// finite as ā_f → 1; σ_b takes its limit √(2β_f² + β_b²)(1 + d_b ā_f²) as ā_b → 0.
ZinkeBackscatter zinke_backscatter(double a_f, double a_b, double alpha_f, double alpha_b, double beta_f2, double beta_b2,
                                   double density_factor);

/// Everything at one incident inclination θi.
struct DualScatteringPoint {
  double theta_i = 0.0;
  std::vector<double> energy;    ///< E_p per explicit lobe, then the residual if the model has one
  std::vector<double> forward;   ///< a_{f,p}, same order
  std::vector<double> backward;  ///< a_{b,p}, same order
  double energy_total = 0.0;     ///< Σ_p E_p
  double a_f = 0.0, a_b = 0.0;
  double alpha_f = 0.0, alpha_b = 0.0;  ///< radians (shift of θr)
  double beta_f2 = 0.0, beta_b2 = 0.0;  ///< radians² (longitudinal variance in θr)
  ZinkeBackscatter backscatter;
  bool converged = false;  ///< every quadrature met its tolerance
};

struct DualScatteringOptions {
  double density_factor = 0.7;  ///< d_b of eq. 17 (Zinke: d_b = d_f = 0.7)
  double rel_tol = 1e-9;        ///< θr integrals
  int energy_order = 128;       ///< Gauss–Legendre order of the lobe energies e_p
};

/// The averages above from per-lobe results (explicit lobes then the residual) and each lobe's
/// parameters: fills a_f, a_b, α, β², the totals and the backscatter terms. When a half carries no
/// energy its α and β² are 0.
void finish_dual_scattering(DualScatteringPoint& point, std::span<const LobeParams> lobes, double density_factor);

/// All of the above at θi for a model, with no interpolation anywhere: every θr node of the adaptive
/// θr integral evaluates e_p by Gauss–Legendre and b_p, f_p by half_range_direct. The reference for
/// the tables (slow: use dual_scattering_grid (dual_scattering_grid.hpp) for grids). Domain: a valid model, θi in [−π/2, π/2].
DualScatteringPoint dual_scattering(const HairModel& model, double theta_i, const DualScatteringOptions& options = {});

}  // namespace hairlut
