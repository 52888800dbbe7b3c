// The Fourier representation measured by bench-hair-luts (tools/bench-hair-luts/representation_fourier.hpp:
// C_n(θd, σa) tabulated, β and φ exact) at its nodes, where no interpolation error remains, against
// the adaptive reference N_p: an independent check of its coefficients, of what it stores and
// multiplies back, of its truncation and of its Clenshaw summation.
#include <algorithm>
#include <cmath>
#include <hairlut/physics/attenuation.hpp>
#include <hairlut/physics/azimuthal_fourier.hpp>
#include <hairlut/physics/azimuthal_np.hpp>
#include <hairlut/util/angles.hpp>
#include <vector>

#include "catch.hpp"
#include "representation_fourier.hpp"

using namespace hairlut;
using bench::FourierTable;
using bench::FourierTableConfig;

TEST_CASE("Fourier representation truncates where the library's term count does", "[fourier-representation]") {
  for (double beta_deg : {0.5, 2.0, 7.0, 30.0})
    for (double tol : {1e-3, 1e-6, 1e-12}) {
      const double beta = radians(beta_deg);
      const int N = fourier_terms(beta, tol);
      const int n = bench::fourier_series_terms(beta, tol, 100000);
      CHECK(std::abs(n - N) <= 1);  // the recurrence rounds differently from the direct exponentials
      double tail = 0.0;
      for (int k = n + 1; k < n + 100000; ++k) tail += std::exp(-0.5 * k * k * beta * beta);
      CHECK(2.0 * tail <= tol);
    }
}

TEST_CASE("Fourier representation equals the reference N_p at its nodes", "[fourier-representation]") {
  constexpr double kEta = 1.55;
  std::vector<FourierTableConfig> configs;
  for (auto store : {FourierTableConfig::Store::raw, FourierTableConfig::Store::absorption, FourierTableConfig::Store::ratio}) {
    FourierTableConfig c;
    c.eta = kEta;
    c.lobes = 4;
    c.beta_min = radians(2.0);
    c.tolerance = 1e-12;
    c.theta_count = 4;
    c.theta_max = radians(80.0);
    c.theta_cos = store != FourierTableConfig::Store::raw;
    c.sigma_count = 3;
    c.sigma_max = 4.0;
    c.sigma_sqrt = store != FourierTableConfig::Store::ratio;
    c.store = store;
    configs.push_back(c);
  }
  std::vector<FourierTable<double>> tables;
  for (const FourierTableConfig& c : configs) tables.emplace_back(c);
  double worst = 0.0;
  for (std::size_t ti = 0; ti < tables.size(); ++ti) {
    const FourierTable<double>& t = tables[ti];
    for (int p = 0; p < 4; ++p)
      for (int i = 0; i < 4; i += (ti == 0 ? 1 : 3))
        for (int k = 0; k < 3; ++k) {
          const double theta = t.theta_node(i), sigma = t.sigma_node(k);
          const AttenuationSlice slice(kEta, theta, sigma);
          for (double beta_deg : {2.0, 6.0, 25.0}) {
            const double beta = radians(beta_deg);
            std::vector<double> phis, ref;
            double peak = 0.0;
            for (int j = 0; j <= 16; ++j) {
              phis.push_back(kPi * j / 16.0 + (j % 3 == 1 ? 0.013 : 0.0));
              ref.push_back(azimuthal_np_reference(slice, p, beta, phis.back(), 1e-13).value[0]);
              peak = std::max(peak, ref.back());
            }
            REQUIRE(peak > 0.0);
            for (std::size_t j = 0; j < phis.size(); ++j) {
              const double e = std::abs(t.value(p, beta, sigma, theta, phis[j]) - ref[j]) / peak;
              worst = std::max(worst, e);
              INFO("store " << ti << " p " << p << " theta_d " << theta << " sigma_a " << sigma << " beta " << beta << " phi " << phis[j]);
              CHECK(e <= 1e-10);
            }
          }
        }
  }
  INFO("worst error relative to the peak: " << worst);
  CHECK(worst > 0.0);  // the comparison ran
}

TEST_CASE("Fourier representation rejects a bad config naming the field", "[fourier-representation]") {
  FourierTableConfig c;
  c.beta_min = radians(2.0);
  c.theta_max = radians(89.0);
  c.theta_count = 1;
  CHECK_THROWS_WITH(FourierTable<float>(c), Catch::Matchers::Contains("theta_count"));
  c.theta_count = 8;
  c.theta_max = 2.0;
  CHECK_THROWS_WITH(FourierTable<float>(c), Catch::Matchers::Contains("theta_max"));
}
