// The fast N_p methods of the baker (azimuthal_fourier.hpp) against the adaptive reference, over
// the stress set and on coarse and fine grids, and their building blocks against closed forms.
#include <cmath>
#include <hairlut/physics/azimuthal_fourier.hpp>
#include <hairlut/report/benchmark.hpp>
#include <hairlut/hairlut.hpp>

#include "catch.hpp"

using namespace hairlut;

TEST_CASE("Fourier terms meet the truncation bound", "[fourier]") {
  for (double beta : {0.002, 0.0087, 0.035, 0.3, 1.5})
    for (double tol : {1e-6, 1e-10, 1e-12}) {
      const int N = fourier_terms(beta, tol);
      double tail = 0.0;
      for (int n = N + 1; n < N + 100000; ++n) tail += std::exp(-0.5 * n * n * beta * beta);
      CHECK(2.0 * tail <= tol);
      // Not wasteful: at most 5% + 3 more terms than the smallest N with 2 · tail ≤ tolerance.
      int n_min = 0;
      double rest = 0.0;
      for (int n = 1; n < N + 100000; ++n) rest += std::exp(-0.5 * n * n * beta * beta);
      for (int n = 1; 2.0 * rest > tol; ++n) rest -= std::exp(-0.5 * n * n * beta * beta), n_min = n;
      CHECK(N <= 1.05 * n_min + 3);
    }
}

TEST_CASE("Cosine series folding on periodic grids equals the direct sum", "[fourier]") {
  for (bool centres : {false, true})
    for (int M : {5, 17, 64}) {
      std::vector<double> phis;
      for (int j = 0; j < M; ++j) phis.push_back(centres ? (j + 0.5) * kPi / M : j * kPi / (M - 1));
      const CosineSeries series(phis, 900);
      std::vector<double> v(901), out(static_cast<std::size_t>(M));
      for (std::size_t n = 0; n < v.size(); ++n) v[n] = std::exp(-1e-5 * static_cast<double>(n * n)) * std::cos(0.37 * static_cast<double>(n));
      series.evaluate(v, out);
      for (int j = 0; j < M; ++j) {
        double direct = 0.0;
        for (std::size_t n = 0; n < v.size(); ++n) direct += v[n] * std::cos(static_cast<double>(n) * phis[static_cast<std::size_t>(j)]);
        CHECK(out[static_cast<std::size_t>(j)] == Approx(direct).epsilon(1e-11).margin(1e-11));
      }
    }
}

TEST_CASE("Fourier coefficients and spreading match the adaptive reference on the stress set", "[fourier]") {
  const auto slices = stress_slices(40, 3);
  double worst_fourier = 0.0, worst_spread = 0.0;
  for (bool centres : {false, true})
    for (const StressSlice& s : slices) {
      if (s.beta < radians(0.5)) continue;  // below the target domain
      const int M = centres ? 64 : 33;
      std::vector<double> phis;
      for (int j = 0; j < M; ++j) phis.push_back(centres ? (j + 0.5) * kPi / M : j * kPi / (M - 1));
      const FiberGeometry g = FiberGeometry::make(s.eta, s.theta_d);
      const AttenuationSlice slice(s.eta, s.theta_d, s.sigma_a);
      std::vector<double> ref;
      double peak = 0.0;
      for (double ph : phis) ref.push_back(azimuthal_np_reference(slice, s.p, s.beta, ph, 1e-13).value[0]), peak = std::max(peak, ref.back());
      if (peak < 1e-250) continue;
      const double tol = 1e-12;
      const int N = fourier_terms(s.beta, tol);
      const GaussLegendreRule rf(fourier_nodes(N, s.p, g, tol)), rs(spread_nodes(s.beta, s.p, g, tol));
      std::vector<double> C;
      const double sigma[1] = {s.sigma_a};
      fourier_coefficients(g, AbsorptionPath::chord, s.p, sigma, N, rf, C);
      std::vector<std::vector<double>> spread;
      const SpreadLobe lobe{s.p, s.beta};
      spread_np(FiberNodes::make(g, AbsorptionPath::chord, rs), g, std::span<const SpreadLobe>(&lobe, 1), sigma, PeriodicGrid::of(phis), tol, spread);
      for (std::size_t j = 0; j < phis.size(); ++j) {
        worst_fourier = std::max(worst_fourier, std::abs(fourier_np(C, 1, s.beta, phis[j], tol) - ref[j]) / peak);
        worst_spread = std::max(worst_spread, std::abs(spread[0][j] - ref[j]) / peak);
      }
    }
  WARN("largest error / slice peak: Fourier " << worst_fourier << ", spreading " << worst_spread);
  CHECK(worst_fourier < 1e-10);
  CHECK(worst_spread < 1e-10);
}

TEST_CASE("Spreading is exact on grids far coarser than the detector", "[fourier]") {
  std::vector<double> phis;
  for (int j = 0; j < 9; ++j) phis.push_back(j * kPi / 8);
  const double beta = radians(0.5), tol = 1e-12;
  const FiberGeometry g = FiberGeometry::make(1.55, radians(30.0));
  const GaussLegendreRule rule(spread_nodes(beta, 2, g, tol));
  const std::vector<SpreadLobe> lobes = {{0, beta}, {2, beta}};
  const double sigma[1] = {0.7};
  std::vector<std::vector<double>> out;
  spread_np(FiberNodes::make(g, AbsorptionPath::chord, rule), g, lobes, sigma, PeriodicGrid::of(phis), tol, out);
  const AttenuationSlice slice(1.55, radians(30.0), 0.7);
  for (std::size_t l = 0; l < lobes.size(); ++l)
    for (std::size_t j = 0; j < phis.size(); ++j) {
      const double ref = azimuthal_np_reference(slice, lobes[l].p, beta, phis[j], 1e-13).value[0];
      CHECK(out[l][j] == Approx(ref).epsilon(1e-10).margin(1e-14));
    }
  CHECK(PeriodicGrid::of(std::vector<double>{0.0, 0.3, 0.7}).period == 0);  // not uniform
}
