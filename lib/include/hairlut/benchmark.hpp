// Pieces of bench-hair-luts that tests also use: the stress set of N_p inputs with their
// reference values, and the per-material baseline of renderers that bake d'Eon's N_p.
#pragma once

#include <cstdint>
#include <vector>

#include "hairlut/attenuation.hpp"
#include "hairlut/quadrature.hpp"

namespace hairlut {

/// One N_p slice of the stress set: everything but φ.
struct StressSlice {
  double beta, theta_d, sigma_a, eta;
  int p;
};

/// A deterministic sample of `count` slices from the product of the stress values (β 0.25°–90°,
/// θd 0°–89.9°, σa 0–1e3, η 1.01–3, p 0–8), always including the corners of the target domain.
std::vector<StressSlice> stress_slices(std::size_t count, std::uint64_t seed = 1);

/// Renderers' per-material bake (the baseline of bench-hair-luts): N_p over `phis` × `cos_thetas`
/// for lobes R, TT, TRT and three colour channels, each entry integrated by 140-point
/// Gauss–Legendre in h, in single precision, against a 2048-sample tabulated detector with linear
/// interpolation. out[((p · n_cos + t) · n_phi + j) · 3 + c]. betas[p] per lobe, sigma_a[c].
/// `rule` is the 140-point Gauss–Legendre rule (built once by the caller, as a renderer's table).
void renderer_baseline_material(double eta, const double (&sigma_a)[3], const double (&betas)[3], const std::vector<double>& phis,
                                const std::vector<double>& cos_thetas, const GaussLegendreRule& rule, std::vector<float>& out);

}  // namespace hairlut
