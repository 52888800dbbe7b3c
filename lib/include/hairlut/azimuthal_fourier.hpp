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
#include <vector>

#include "hairlut/attenuation.hpp"
#include "hairlut/quadrature.hpp"

namespace hairlut {

/// Smallest N with 2 Σ_{n>N} e^{−n²β²/2} ≤ tolerance. Domain: β > 0, 0 < tolerance < 1.
int fourier_terms(double beta, double tolerance);

/// Gauss–Legendre nodes on γ ∈ [0, π/2] for C_n, n ≤ terms, of lobe p: with the largest phase
/// rate k = terms · max|dΦ/dγ| · π/4 on the rule's [−1, 1], m = 0.52 k + 6 k^{1/3} + 20 (measured:
/// cos(kx) integrates to 1e−14 with fewer) plus nodes for the Fresnel edge of an η close to 1.
int fourier_nodes(int terms, int p, const FiberGeometry& geometry);

/// C_n for n = 0 … terms of lobe p at the geometry's θd, for each σa in `sigmas`, written to
/// out[n · sigmas.size() + k]. `rule` is a Gauss–Legendre rule on [−1, 1] (mapped to [0, π/2]).
void fourier_coefficients(const FiberGeometry& geometry, AbsorptionPath path, int p, std::span<const double> sigmas, int terms,
                          const GaussLegendreRule& rule, std::vector<double>& out);

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

/// N_p(φ; β) from coefficients C_0 … C_N of one σa (stride between consecutive n), by the direct
/// series (for tests and single points); the terms beyond fourier_terms(β, tolerance) are dropped.
double fourier_np(std::span<const double> coefficients, std::size_t stride, double beta, double phi, double tolerance);

}  // namespace hairlut
