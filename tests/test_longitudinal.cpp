// d'Eon's M_p against a 50-digit evaluation of eq. 7 as printed (csch, exp and I0, no
// rearrangement), its normalization, symmetries and tilt; Marschner's Gaussian against its
// definition.
#include <boost/math/special_functions/bessel.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <cmath>
#include <hairlut/hairlut.hpp>
#include <vector>

#include "catch.hpp"

using namespace hairlut;
using mp = boost::multiprecision::cpp_bin_float_50;

namespace {

// M = csch(1/v)/(2v) · exp(−sin θi sin θr / v) · I0(cos θi cos θr / v), in 50 digits.
double deon_reference(double v, double theta_i, double theta_r) {
  const mp V(v), a(theta_i), b(theta_r);
  const mp x = cos(a) * cos(b) / V;
  const mp m = 1 / sinh(1 / V) / (2 * V) * exp(-sin(a) * sin(b) / V) * boost::math::cyl_bessel_i(0, x);
  return m.convert_to<double>();
}

std::vector<double> angle_grid() {
  std::vector<double> t;
  for (int i = 0; i <= 12; ++i) t.push_back(-kHalfPi + i * kPi / 12.0);
  t.front() = -kHalfPi;
  t.back() = kHalfPi;
  for (double extra : {1.5607963267948966, -1.5707, 0.001, -1e-9, 1.2345}) t.push_back(extra);
  return t;
}

}  // namespace

TEST_CASE("d'Eon M_p matches a high-precision evaluation of eq. 7 to 1e-10", "[mp]") {
  const std::vector<double> vs = {1e-6, 3e-6, 1e-5, 1e-4, 1e-3, 0.0076, 0.03, 0.1, 0.5, 1.0, 4.0, 10.0, 30.0, 100.0};
  const auto angles = angle_grid();
  double worst = 0.0;
  for (double v : vs)
    for (double ti : angles)
      for (double tr : angles) {
        const double got = longitudinal_deon(v, ti, tr);
        const double ref = deon_reference(v, ti, tr);
        INFO("v=" << v << " theta_i=" << ti << " theta_r=" << tr << " got=" << got << " ref=" << ref);
        REQUIRE(std::isfinite(got));
        REQUIRE(got >= 0.0);
        if (ref > 1e-280) {
          const double rel = std::abs(got - ref) / ref;
          worst = std::max(worst, rel);
          CHECK(rel <= 1e-10);
        } else {
          CHECK(got <= 1e-279);  // underflow region: both negligible
        }
      }
  WARN("worst relative error of M_p against 50-digit eq. 7: " << worst);
}

TEST_CASE("d'Eon M_p is normalized: int M cos(theta_r) = 1 within 1e-9", "[mp]") {
  for (double v : {1e-4, 3e-4, 1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0})
    for (double ti : {-kHalfPi, -1.5, -1.0, -0.2, 0.0, 0.5, 1.2, 1.5, 1.5607963, kHalfPi}) {
      const AdaptiveResult r = longitudinal_energy_deon(v, 0.0, ti);
      INFO("v=" << v << " theta_i=" << ti);
      CHECK(r.converged);
      CHECK(std::abs(r.value[0] - 1.0) <= 1e-9);
    }
}

TEST_CASE("d'Eon M_p symmetries", "[mp]") {
  for (double v : {1e-5, 0.01, 2.0})
    for (double ti : angle_grid())
      for (double tr : {-1.4, -0.3, 0.0, 0.8, kHalfPi}) {
        const double m = longitudinal_deon(v, ti, tr);
        CHECK(longitudinal_deon(v, tr, ti) == Approx(m).epsilon(1e-14).margin(1e-300));    // reciprocity
        CHECK(longitudinal_deon(v, -ti, -tr) == Approx(m).epsilon(1e-14).margin(1e-300));  // mirror
      }
}

TEST_CASE("d'Eon M_p limits: wide lobes are uniform in projected solid angle", "[mp]") {
  // v → ∞: csch(1/v)/(2v) → 1/2, the exponential and I0 → 1.
  CHECK(longitudinal_deon(1e8, 0.3, -1.2) == Approx(0.5).epsilon(1e-7));
  CHECK(longitudinal_deon(1e300, 1.0, 1.0) == Approx(0.5).epsilon(1e-15));
  // Tiny v: a narrow lobe at the specular cone, finite everywhere.
  const double v = 1e-300;
  CHECK(std::isfinite(longitudinal_deon(v, 0.4, -0.4)));
  CHECK(longitudinal_deon(v, 0.4, -0.4) > 1e100);
  CHECK(longitudinal_deon(v, 0.4, 0.4) == 0.0);
  CHECK(std::isfinite(longitudinal_deon(2.3e-308, kHalfPi, -kHalfPi)));
}

TEST_CASE("Cuticle tilt: worked example and folding at the pole", "[mp]") {
  // α_R = −4°, θi = 30°: the narrow R lobe peaks at θr = −34°.
  const double v = radians(0.5) * radians(0.5), alpha = radians(-4.0), ti = radians(30.0);
  double best = -kHalfPi, best_m = -1.0;
  for (double t = -kHalfPi; t <= kHalfPi; t += radians(0.01)) {
    const double m = longitudinal_deon_tilted(v, alpha, ti, t);
    if (m > best_m) best_m = m, best = t;
  }
  CHECK(degrees(best) == Approx(-34.0).margin(0.02));
  CHECK(longitudinal_deon_tilted(v, alpha, ti, radians(-34.0)) == longitudinal_deon(v, ti, radians(-30.0)));
  // Folding: θr − α = 93° reads as 87°.
  CHECK(fold_inclination(radians(93.0)) == Approx(radians(87.0)).epsilon(1e-15));
  CHECK(fold_inclination(radians(-95.0)) == Approx(radians(-85.0)).epsilon(1e-15));
  CHECK(longitudinal_deon_tilted(0.01, radians(-4.0), 0.2, radians(89.0)) ==
        Approx(longitudinal_deon(0.01, 0.2, radians(87.0))).epsilon(1e-13));
  // A tilt moves the lobe but not the cos θr weight: a narrow lobe's energy becomes
  // cos(−θi + α)/cos θi (d'Eon: "only approximate").
  for (double a : {-6.0, 3.0, 6.0})
    for (double t : {0.0, 0.3, -1.0})
      CHECK(longitudinal_energy_deon(1e-5, radians(a), t).value[0] ==
            Approx(std::cos(-t + radians(a)) / std::cos(t)).epsilon(1e-4));
}

TEST_CASE("Marschner's Gaussian M_p follows its definition", "[mp]") {
  const double beta = 0.1, alpha = radians(-5.0), ti = 0.4, tr = -0.2;
  const double th = 0.5 * (ti + tr), td = 0.5 * (tr - ti);
  const double g1 = std::exp(-std::pow(th - alpha, 2) / (2 * beta * beta)) / (std::sqrt(2 * kPi) * beta);
  const double g2 = std::exp(-std::pow(2 * (th - alpha), 2) / (2 * beta * beta)) / (std::sqrt(2 * kPi) * beta);
  CHECK(longitudinal_gaussian(beta, alpha, ti, tr, GaussianArgument::theta_h) == Approx(g1 / std::pow(std::cos(td), 2)).epsilon(1e-14));
  CHECK(longitudinal_gaussian(beta, alpha, ti, tr, GaussianArgument::two_theta_h) == Approx(g2 / std::pow(std::cos(td), 2)).epsilon(1e-14));
  CHECK(std::isfinite(longitudinal_gaussian(1e-12, 0.0, kHalfPi, -kHalfPi, GaussianArgument::theta_h)));
}

TEST_CASE("d'Eon 2011 Fig. 3: Gaussian M_p gains and loses energy, d'Eon's does not", "[mp][paper]") {
  using GA = GaussianArgument;
  // Low roughness: energy near 2 with θh (normalized over θ but evaluated over θh), near 1 with 2θh.
  for (double ti : {0.0, 0.5, 1.0}) {
    CHECK(longitudinal_energy_gaussian(radians(2.0), 0.0, ti, GA::theta_h).value[0] == Approx(2.0).epsilon(0.01));
    CHECK(longitudinal_energy_gaussian(radians(2.0), 0.0, ti, GA::two_theta_h).value[0] == Approx(1.0).epsilon(0.005));
  }
  // Grazing illumination gains energy, even with 2θh.
  CHECK(longitudinal_energy_gaussian(radians(2.0), 0.0, radians(89.0), GA::two_theta_h).value[0] > 1.05);
  CHECK(longitudinal_energy_gaussian(radians(10.0), 0.0, radians(89.0), GA::two_theta_h).value[0] > 1.3);
  // High roughness loses energy away from grazing.
  CHECK(longitudinal_energy_gaussian(radians(30.0), 0.0, 0.0, GA::two_theta_h).value[0] < 0.85);
  CHECK(longitudinal_energy_gaussian(radians(30.0), 0.0, radians(45.0), GA::two_theta_h).value[0] < 0.85);
  // d'Eon's M_p: 1 in every one of these cases.
  for (double b : {2.0, 10.0, 30.0})
    for (double ti : {0.0, 45.0, 89.0})
      CHECK(longitudinal_energy_deon(radians(b) * radians(b), 0.0, radians(ti)).value[0] == Approx(1.0).epsilon(1e-10));
}
