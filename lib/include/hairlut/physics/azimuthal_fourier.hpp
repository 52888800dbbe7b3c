// The Fourier method for d'Eon's N_p, used by the baker.
//
// The Gaussian detector's Fourier series D_β(φ) = (1/2π) Σ_n e^{−n²β²/2} e^{inφ} turns eq. 10 into
//   N_p(φ; β) = (1/2π) [C_0 + 2 Σ_{n≥1} e^{−n²β²/2} C_n cos nφ],
//   C_n = ½ ∫_{−1}^{1} A(p, h) cos(n Φ(p, h)) dh = ∫_0^{π/2} A(p, sin γ) cos γ cos(n Φ(p, γ)) dγ
// (the sine terms vanish because A is even and Φ(p, −h) ≡ −Φ(p, h)). Every β shares the C_n, and
// the C_n of every σa share the nodes, Φ and Fresnel factors: only T^p depends on σa.
//
// Exact and approximate: the identity is exact; the series is truncated after N terms, where
// 2 Σ_{n>N} e^{−n²β²/2} ≤ tolerance (so the truncation error is below tolerance × the lobe's mean
// height C_0/2π, itself below its peak), and the C_n are integrated by Gauss–Legendre with enough
// nodes for the fastest phase n Φ' (an error bound for oscillatory integrands, checked against the
// adaptive reference in the tests and in bench-hair-luts).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "hairlut/physics/attenuation.hpp"
#include "hairlut/util/quadrature.hpp"

namespace hairlut {

/// N with 2 Σ_{n>N} e^{−n²β²/2} ≤ tolerance / 2, from the ratio bound of the tail (a term or two
/// more than strictly needed). Domain: β > 0, 0 < tolerance < 1.
int fourier_terms(double beta, double tolerance);

/// Gauss–Legendre nodes on γ ∈ [0, π/2] for C_n, n ≤ terms, of lobe p, from an error bound: the
/// phase n Φ(γ) oscillates at most at k_n = n · max|dΦ/dγ| · π/4 on the rule's [−1, 1], where
/// m ≥ 0.5 k + (0.35 log10(1/ε) + 0.6) k^{1/3} + 4 integrates cos(kx) to ε (measured), and C_n needs
/// only ε_n = tolerance / (10 N e^{−n²β²/2}); plus nodes for the Fresnel edge of an η close to 1.
int fourier_nodes(int terms, int p, const FiberGeometry& geometry, double tolerance);

/// C_n for n = 0 … terms of lobe p at the geometry's θd, for each σa in `sigmas`, written to
/// out[n · sigmas.size() + k]. `rule` is a Gauss–Legendre rule on [−1, 1] (mapped to [0, π/2]).
void fourier_coefficients(const FiberGeometry& geometry, AbsorptionPath path, int p, std::span<const double> sigmas, int terms,
                          const GaussLegendreRule& rule, std::vector<double>& out);
struct FiberNodes;
/// The same from precomputed node factors. With length_offset = ℓ_min (edge_segment_length,
/// attenuation.hpp) the result is C_n / F, F = e^{−p σa′ ℓ_min} the lobe's least absorption, taken
/// inside the integral (each node's T^p as e^{−p σa′ (ℓ − ℓ_min)}), so that it keeps its digits
/// where C_n and F underflow.
void fourier_coefficients(const FiberNodes& nodes, const FiberGeometry& geometry, int p, std::span<const double> sigmas, int terms,
                          std::vector<double>& out, double length_offset = 0.0);

/// Σ_{n=0}^{N} v_n cos(n φ_j) on a fixed grid of φ_j, for any N up to max_terms. On a uniform
/// grid whose step divides 2π (every hairlut φ axis) terms beyond the grid's period are folded
/// onto it exactly (aliasing is an identity at the grid points), so the cost per evaluation is at
/// most (period × points); otherwise the sum is direct.
class CosineSeries {
 public:
  CosineSeries(std::span<const double> phis, int max_terms);
  /// out[j] = Σ_n v[n] cos(n φ_j), n < v.size() ≤ max_terms + 1.
  void evaluate(std::span<const double> v, std::span<double> out) const;

 private:
  std::size_t points_ = 0;
  int max_terms_ = 0;
  int period_ = 0;            // P > 0 when φ_j = φ_0 + 2πj/P; 0 otherwise
  double phi0_ = 0.0;
  std::vector<double> cos_;   // cos(n φ_j) as [j][n], n ≤ min(max_terms, P − 1)
  std::vector<double> sin_;   // sin(n φ_j) as [j][n] (folded evaluation only)
};

/// The factors of A(p, h) at the nodes of a rule on γ ∈ [0, π/2] that do not depend on p or σa,
/// computed once per θd and shared by every lobe and absorption.
struct FiberNodes {
  std::vector<double> weight;  ///< rule weight × π/4 × cos γ (dh = cos γ dγ)
  std::vector<double> gamma_i, gamma_t, f, one_minus_f, length;  ///< length: σa'-free path of one segment
  std::size_t size() const { return weight.size(); }
  /// Evaluates the nodes of `rule` (on [−1, 1], mapped to [0, π/2]) at the geometry's θd.
  static FiberNodes make(const FiberGeometry& geometry, AbsorptionPath path, const GaussLegendreRule& rule);
};

/// Gauss–Legendre nodes on γ ∈ [0, π/2] for evaluating N_p directly (spreading, below) with a
/// detector of width β to the tolerance: the detector is a Gaussian of width σ = β / max|dΦ/dγ|
/// in γ, which the rule resolves to ε once its widest spacing (π²/4m at the centre) is below
/// π σ √(2 / ln(1/ε)) (the trapezoid-rule bound for a Gaussian); plus the Fresnel-edge nodes.
int spread_nodes(double beta, int p, const FiberGeometry& geometry, double tolerance);

/// A uniform φ grid whose step divides 2π and that is symmetric about φ = 0 on the circle:
/// φ_j = φ_0 + 2πj/P for j < points ≤ P + 1 (with P + 1 points both ends are present, 0 and 2π or
/// −π and π, the last repeating the first) and 2φ_0 a multiple of 2π/P.
struct PeriodicGrid {
  double phi0 = 0.0;
  int period = 0;   ///< P
  int points = 0;   ///< how many circle points the table keeps (point j is circle point j mod P)
  /// The grid of `phis`, or period = 0 when they are not such a grid.
  static PeriodicGrid of(std::span<const double> phis);
  /// Why `phis` is not such a grid, with what that costs (empty when it is).
  static std::string why_not(std::span<const double> phis);
};

/// One (lobe, detector width) evaluated by spread_np.
struct SpreadLobe {
  int p;
  double beta;
};

/// N_p on a periodic φ grid for several (lobe, β) and every σa, by direct quadrature over the
/// nodes: each node adds ½ W A(p) [g(φ − Φ) + g(φ + Φ)], the Gaussians summed over the grid points
/// within √(2 ln(2/ε)) β of their centre (all images of the wrapped detector included) with a
/// two-exponential recurrence; g(φ + Φ) is the mirror image of g(φ − Φ) on the (symmetric) grid.
/// The same quadrature as the Fourier form with the same nodes. out[l][k · points + j].
void spread_np(const FiberNodes& nodes, const FiberGeometry& geometry, std::span<const SpreadLobe> lobes,
               std::span<const double> sigmas, const PeriodicGrid& grid, double tolerance, std::vector<std::vector<double>>& out);

/// Work estimates used to choose between the Fourier form and spreading for one (θd, lobe).
double fourier_cost(int terms, int nodes, std::size_t sigmas, std::size_t betas, std::size_t points);
double spread_cost(double beta, int nodes, std::size_t sigmas, const PeriodicGrid& grid, double tolerance);

/// N_p(φ; β) from coefficients C_0 … C_N of one σa (stride between consecutive n), by the direct
/// series (for tests and single points); the terms beyond fourier_terms(β, tolerance) are dropped.
double fourier_np(std::span<const double> coefficients, std::size_t stride, double beta, double phi, double tolerance);

}  // namespace hairlut
