// Dual-scattering results (dual_scattering.hpp) on a grid of absorptions, roughnesses and incident
// inclinations, as the baker needs them: the azimuthal halves b_p, f_p and the lobe energies e_p are
// computed once per (θd, σa, lobe width) on a θd grid and shared by every θi and longitudinal width;
// each θr integral then interpolates them. The grid is θd_j = (π/2) sin((π/2) j/J), j = 0 … J: uniform in
// u = (2/π) asin(2θd/π), denser towards grazing θd = π/2 where the halves change fastest; interpolation
// is cubic Lagrange in u (even about u = 0).
//
// Exact and approximate: b_p and f_p come from the Fourier coefficients of N_p (half_range_fourier)
// for widths that need at most `fourier_max_terms` terms, and from half_range_direct for narrower
// detectors (any β > 0, no lower limit); the θd interpolation error is measured by the tests against
// dual_scattering() (which interpolates nothing). Every cell is computed from the request alone, so the
// result does not depend on the thread count.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "hairlut/bake/bake.hpp"
#include "hairlut/physics/dual_scattering.hpp"

namespace hairlut {

struct DualScatteringGridRequest {
  double eta = 1.55;
  AbsorptionPath path = AbsorptionPath::chord;
  int lobes = 3;                 ///< explicit lobes P (R, TT, TRT, ...)
  bool residual = true;          ///< include the residual p ≥ P (uniform in φ)
  std::vector<double> sigmas;    ///< σa of each absorption node (≥ 0)
  /// Per roughness node: the parameters of the P explicit lobes, then the residual's if included.
  std::vector<std::vector<LobeParams>> roughness;
  std::vector<double> thetas;    ///< θi of each incidence node, in [−π/2, π/2]
  DualScatteringOptions options;
  int theta_d_intervals = 512;   ///< J, intervals of the θd grid over [0, π/2]
  double fourier_tolerance = 1e-11;
  int fourier_max_terms = 320;   ///< widths needing more Fourier terms use half_range_direct
  std::shared_ptr<GaussLegendreCache> rules;  ///< optional, shared Gauss–Legendre rules
};

/// Receives every cell: out(k, r, t, point) for absorption k, roughness r and incidence t. Called
/// concurrently for distinct cells.
using DualScatteringGridOutput = std::function<void(std::size_t k, std::size_t r, std::size_t t, const DualScatteringPoint& point)>;

struct DualScatteringGridStats {
  std::size_t cells = 0;
  std::size_t unconverged = 0;     ///< θr integrals or direct half-range integrals that missed their tolerance
  std::size_t fourier_widths = 0;  ///< distinct (lobe, β_n) evaluated by the Fourier form
  std::size_t direct_widths = 0;   ///< distinct (lobe, β_n) evaluated by direct quadrature
};

/// Evaluates the grid in parallel (options.threads, progress under `stage`, cancellation).
/// Throws DomainError for an invalid request, BakeCancelled when cancelled.
DualScatteringGridStats dual_scattering_grid(const DualScatteringGridRequest& request, const BakeOptions& options,
                                             const std::string& stage, const DualScatteringGridOutput& out);

}  // namespace hairlut
