// Fiber geometry (Φ, caustics, roots) and attenuation A(p, h) against closed forms and
// conservation laws.
#include <cmath>
#include <hairlut/hairlut.hpp>

#include "catch.hpp"

using namespace hairlut;

TEST_CASE("Exit azimuth: symmetry and derivative", "[geometry]") {
  const FiberGeometry g = FiberGeometry::make(1.55, 0.4);
  for (int p : {0, 1, 2, 3, 7})
    for (double gamma : {-1.5, -0.7, 0.0, 0.3, 1.2}) {
      const double gt = std::asin(std::sin(gamma) * g.inv_eta_prime);
      const double gtm = std::asin(-std::sin(gamma) * g.inv_eta_prime);
      // Φ(p, −h) = −Φ(p, h) + 2pπ.
      CHECK(exit_azimuth(p, -gamma, gtm) == Approx(-exit_azimuth(p, gamma, gt) + 2 * p * kPi).margin(1e-13));
      // dΦ/dγ against a central difference.
      const double d = 1e-6;
      auto Phi = [&](double x) { return exit_azimuth(p, x, std::asin(std::sin(x) * g.inv_eta_prime)); };
      const double numeric = (Phi(gamma + d) - Phi(gamma - d)) / (2 * d);
      CHECK(exit_azimuth_derivative(p, std::cos(gamma), std::cos(gt), g.inv_eta_prime) == Approx(numeric).margin(1e-7));
    }
}

TEST_CASE("Caustics: Descartes' formula and a zero of dPhi/dgamma", "[geometry]") {
  for (double eta : {1.2, 1.55, 1.9})
    for (double td : {0.0, 0.5}) {
      const FiberGeometry g = FiberGeometry::make(eta, td);
      const double ep = 1.0 / g.inv_eta_prime;
      CHECK(caustic_gamma(1, g) < 0.0);  // TT has none
      const double gc = caustic_gamma(2, g);
      if (ep < 2.0) {
        REQUIRE(gc > 0.0);
        CHECK(std::sin(gc) * std::sin(gc) == Approx((4.0 - ep * ep) / 3.0).epsilon(1e-12));  // h_c² = (4 − η'²)/3
        const double gt = std::asin(std::sin(gc) * g.inv_eta_prime);
        CHECK(exit_azimuth_derivative(2, std::cos(gc), std::cos(gt), g.inv_eta_prime) == Approx(0.0).margin(1e-12));
      } else {
        CHECK(gc < 0.0);
      }
    }
}

TEST_CASE("Azimuthal roots solve Phi = phi and switch count at the TRT caustic", "[geometry]") {
  const FiberGeometry g = FiberGeometry::make(1.55, 0.2);
  for (int p : {0, 1, 2, 3, 5})
    for (double phi = -kPi; phi <= kPi; phi += 0.05) {
      const auto roots = azimuthal_roots(g, p, phi);
      // R: one root (two at φ = ±π, the fiber's two edges); TT: one, or none for |φ| < 2 asin(1/η')
      // (a smooth fiber sends no TT light straight back).
      if (p == 0) CHECK(roots.size() == (std::abs(phi) > kPi - 1e-12 ? 2u : 1u));
      if (p == 1) CHECK(roots.size() == (std::abs(phi) > 2.0 * std::asin(g.inv_eta_prime) ? 1u : 0u));
      for (double r : roots) {
        const double Phi = exit_azimuth(p, r, std::asin(std::sin(r) * g.inv_eta_prime));
        CHECK(std::abs(std::remainder(Phi - phi, kTwoPi)) < 1e-12);
      }
    }
  // TRT: φc = Φ(2, γc) (mod 2π); three roots for |φ| < |φc|, one beyond.
  const double gc = caustic_gamma(2, g);
  const double phic = std::abs(std::remainder(exit_azimuth(2, gc, std::asin(std::sin(gc) * g.inv_eta_prime)), kTwoPi));
  CHECK(azimuthal_roots(g, 2, 0.98 * phic).size() == 3);
  CHECK(azimuthal_roots(g, 2, -0.98 * phic).size() == 3);
  CHECK(azimuthal_roots(g, 2, 1.02 * phic).size() == 1);
}

TEST_CASE("Attenuation: white fibers conserve energy pointwise", "[attenuation]") {
  for (double eta : {1.01, 1.55, 3.0})
    for (double td : {0.0, 0.7, 1.4, 1.5706})
      for (double gamma : {0.0, 0.5, 1.2, 1.5707963}) {
        const PathPoint q = AttenuationSlice(eta, td, 0.0).at_gamma(gamma);
        for (int P : {1, 2, 3, 4, 8, 20}) {
          double sum = q.residual_attenuation(P);
          for (int p = 0; p < P; ++p) sum += q.attenuation(p);
          CHECK(sum == Approx(1.0).epsilon(1e-14));
        }
      }
}

TEST_CASE("Attenuation: the residual equals the sum of the lobes it replaces", "[attenuation]") {
  for (double sigma : {0.01, 0.3, 2.0})
    for (double gamma : {0.1, 0.9, 1.5}) {
      const PathPoint q = AttenuationSlice(1.55, 0.3, sigma).at_gamma(gamma);
      for (int P : {1, 3, 4}) {
        double explicit_sum = 0.0;
        for (int p = P; p < P + 4000; ++p) explicit_sum += q.attenuation(p);
        CHECK(q.residual_attenuation(P) == Approx(explicit_sum).epsilon(1e-12));
      }
    }
}

TEST_CASE("Attenuation: absorption path options", "[attenuation]") {
  const double sigma = 0.7, td = 0.5, eta = 1.55;
  const AttenuationSlice chord(eta, td, sigma, AbsorptionPath::chord);
  const AttenuationSlice papers(eta, td, sigma, AbsorptionPath::papers);
  const double cos_t = std::sqrt(eta * eta - std::sin(td) * std::sin(td)) / eta;
  // At h = 0 the chord is the diameter 2, the papers' path 2(1 + cos 0) = 4.
  CHECK(chord.at_h(0.0).T == Approx(std::exp(-2.0 * sigma / cos_t)).epsilon(1e-14));
  CHECK(papers.at_h(0.0).T == Approx(std::exp(-4.0 * sigma / cos_t)).epsilon(1e-14));
  for (double h : {0.2, 0.6, 0.95}) {
    const PathPoint c = chord.at_h(h), p = papers.at_h(h);
    CHECK(p.T == Approx(std::pow(c.T, 2.0 * c.cos_gamma_t)).epsilon(1e-13));  // 4cos²γt = 2cosγt · 2cosγt
    // (1 − f)² T for TT, with the independent Fresnel formula.
    CHECK(c.attenuation(1) == Approx(c.one_minus_f * c.one_minus_f * c.T).epsilon(1e-15));
    CHECK(c.one_minus_T == Approx(1.0 - c.T).epsilon(1e-12));
  }
  CHECK(parse_absorption_path("papers") == AbsorptionPath::papers);
  CHECK_THROWS_AS(parse_absorption_path("diameter"), DomainError);
}

TEST_CASE("Lobe names", "[attenuation]") {
  CHECK(lobe_name(0) == "R");
  CHECK(lobe_name(1) == "TT");
  CHECK(lobe_name(3) == "TRRT");
  for (int p = 0; p < 30; ++p) CHECK(parse_lobe(lobe_name(p)) == p);
  CHECK(parse_lobe("p12") == 12);
  CHECK_THROWS_AS(parse_lobe("TRX"), DomainError);
  CHECK_THROWS_AS(parse_lobe("T"), DomainError);
}
