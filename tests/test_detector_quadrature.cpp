// The Gaussian detector against a long-double image sum, and the quadrature rules against
// closed-form integrals and Boost's tabulated rule.
#include <boost/math/quadrature/gauss.hpp>
#include <cmath>
#include <hairlut/hairlut.hpp>

#include "catch.hpp"

using namespace hairlut;

namespace {
// Σ_{|k|≤200} exp(−(φ − 2πk)²/2β²)/(√(2π)β) in long double (no truncation rule, no Fourier form).
// The period is the double nearest 2π, the period the library wraps φ with.
long double detector_reference(long double beta, long double phi) {
  const long double two_pi = kTwoPi;
  long double sum = 0.0L;
  for (int k = -200; k <= 200; ++k) {
    const long double x = phi - two_pi * k;
    sum += std::exp(-x * x / (2 * beta * beta));
  }
  return sum / (std::sqrt(two_pi) * beta);
}
}  // namespace

TEST_CASE("Gaussian detector matches a long-double image sum", "[detector]") {
  for (double beta : {1e-4, 0.01, 0.1, 0.5, 1.0, 2.0, 2.4999, 2.5, 3.0, 5.0, 10.0, 50.0})
    for (double phi : {0.0, 1e-3, 0.3, 1.0, 2.0, 3.0, kPi, 4.0, -2.5, 7.0, 100.0}) {
      INFO("beta=" << beta << " phi=" << phi);
      const double ref = static_cast<double>(detector_reference(beta, phi));
      const double got = gaussian_detector(beta, phi);
      REQUIRE(got >= 0.0);
      CHECK(got == Approx(ref).epsilon(1e-13).margin(1e-300));
    }
}

TEST_CASE("Gaussian detector is even, periodic and normalized", "[detector]") {
  for (double beta : {0.002, 0.05, 0.7, 2.5, 8.0}) {
    for (double phi : {0.1, 1.7, 3.0}) {
      CHECK(gaussian_detector(beta, phi) == gaussian_detector(beta, -phi));
      CHECK(gaussian_detector(beta, phi + kTwoPi) == Approx(gaussian_detector(beta, phi)).epsilon(1e-12).margin(1e-280));
    }
    const double bp[] = {-kPi, 0.0, kPi};
    const AdaptiveResult r = integrate_adaptive([&](double x, std::span<double> out) { out[0] = gaussian_detector(beta, x); },
                                                1, bp, {1e-13, 1e-300, 8000});
    CHECK(r.converged);
    CHECK(r.value[0] == Approx(1.0).epsilon(1e-12));
  }
}

TEST_CASE("Gauss-Legendre rules integrate polynomials exactly", "[quadrature]") {
  for (int n : {1, 2, 3, 8, 35, 64, 128, 140, 512, 1024}) {
    const GaussLegendreRule rule(n);
    REQUIRE(rule.order() == n);
    double wsum = 0.0;
    for (int i = 0; i < n; ++i) {
      wsum += rule.weights()[i];
      CHECK(rule.nodes()[i] == -rule.nodes()[n - 1 - i]);
      if (i > 0) CHECK(rule.nodes()[i] > rule.nodes()[i - 1]);
    }
    CHECK(wsum == Approx(2.0).epsilon(1e-14));
    // ∫_0^1 x^k dx = 1/(k + 1) for k ≤ 2n − 1 (up to degree 60 to stay well conditioned).
    for (int k = 0; k <= std::min(2 * n - 1, 60); ++k) {
      INFO("n=" << n << " k=" << k);
      CHECK(rule.integrate([&](double x) { return std::pow(x, k); }, 0.0, 1.0) == Approx(1.0 / (k + 1)).epsilon(1e-13));
    }
  }
  // ∫_0^π sin = 2 converges geometrically.
  CHECK(GaussLegendreRule(20).integrate([](double x) { return std::sin(x); }, 0.0, kPi) == Approx(2.0).epsilon(1e-15));
}

TEST_CASE("Gauss-Legendre nodes agree with Boost's tabulated 20-point rule", "[quadrature]") {
  using G = boost::math::quadrature::gauss<double, 20>;
  const GaussLegendreRule rule(20);
  for (std::size_t j = 0; j < G::abscissa().size(); ++j) {
    CHECK(rule.nodes()[10 + j] == Approx(G::abscissa()[j]).epsilon(1e-15));
    CHECK(rule.weights()[10 + j] == Approx(G::weights()[j]).epsilon(1e-14));
  }
}

TEST_CASE("Adaptive integration reaches its tolerance and says when it cannot", "[quadrature]") {
  // A narrow Gaussian with its centre as a breakpoint (the first Kronrod node sits 2.2 widths
  // from it, so the panels see the peak and refine towards it).
  const double s = 1e-3;
  auto g = [&](double x, std::span<double> out) {
    out[0] = std::exp(-x * x / (2 * s * s)) / (std::sqrt(2 * kPi) * s);
    out[1] = x * x;
  };
  const double bp[] = {-1.0, 0.0, 2.0};
  const AdaptiveResult r = integrate_adaptive(g, 2, bp, {1e-12, 1e-300, 8000});
  CHECK(r.converged);
  CHECK(r.value[0] == Approx(1.0).epsilon(1e-12));
  CHECK(r.value[1] == Approx(3.0).epsilon(1e-14));  // ∫_{−1}^{2} x² = 3
  // With too small a budget it reports failure instead of a wrong "converged" value.
  const AdaptiveResult bad = integrate_adaptive_scalar([](double x) { return std::sqrt(std::abs(std::sin(50 * x))); }, 0.0, 3.0,
                                                       {1e-14, 1e-300, 3});
  CHECK_FALSE(bad.converged);
  CHECK(bad.intervals <= 3);
}
