// Fresnel reflectance and Bravais indices against closed forms and an independent long-double
// evaluation from the angles themselves.
#include <cmath>
#include <hairlut/physics/fresnel.hpp>

#include "catch.hpp"

using namespace hairlut;

namespace {
// Fresnel from the angles (not the cosines), in long double: r_s = −sin(θi − θt)/sin(θi + θt),
// r_p = tan(θi − θt)/tan(θi + θt).
long double fresnel_from_angles(long double eta, long double theta_i) {
  if (theta_i == 0.0L) return std::pow((eta - 1) / (eta + 1), 2.0L);
  const long double st = std::sin(theta_i) / eta;
  if (st >= 1.0L) return 1.0L;
  const long double theta_t = std::asin(st);
  const long double rs = -std::sin(theta_i - theta_t) / std::sin(theta_i + theta_t);
  const long double rp = std::tan(theta_i - theta_t) / std::tan(theta_i + theta_t);
  return 0.5L * (rs * rs + rp * rp);
}
}  // namespace

TEST_CASE("Fresnel reflectance matches closed forms", "[fresnel]") {
  for (double eta : {1.01, 1.33, 1.55, 2.0, 3.0}) {
    const double r0 = (eta - 1) / (eta + 1);
    CHECK(fresnel_reflectance(eta, 1.0) == Approx(r0 * r0).epsilon(1e-14));
    CHECK(fresnel_reflectance(eta, 0.0) == 1.0);
    CHECK(fresnel_transmittance(eta, 0.0) == 0.0);
    // Brewster's angle: r_p = 0 and r_s = (1 − η²)/(1 + η²).
    const double cos_b = 1.0 / std::sqrt(1.0 + eta * eta);
    const double rs = (1 - eta * eta) / (1 + eta * eta);
    CHECK(fresnel_reflectance(eta, cos_b) == Approx(0.5 * rs * rs).epsilon(1e-13));
  }
}

TEST_CASE("Fresnel reflectance matches an evaluation from the angles", "[fresnel]") {
  for (double eta : {0.5, 0.75, 1.01, 1.55, 3.0})
    for (int i = 0; i <= 90; ++i) {
      const long double theta = i * 3.14159265358979323846264L / 180.0L * (i == 90 ? 0.999999L : 1.0L);
      const double c = static_cast<double>(std::cos(theta));
      const double expected = static_cast<double>(fresnel_from_angles(eta, theta));
      INFO("eta=" << eta << " theta_deg=" << i);
      CHECK(fresnel_reflectance(eta, c) == Approx(expected).epsilon(1e-12).margin(1e-15));
      CHECK(fresnel_reflectance(eta, c) + fresnel_transmittance(eta, c) == Approx(1.0).epsilon(1e-15));
    }
}

TEST_CASE("Fresnel: total internal reflection and reciprocity", "[fresnel]") {
  const double eta = 1.0 / 1.5;  // leaving glass
  const double critical_cos = std::sqrt(1.0 - eta * eta);
  CHECK(fresnel_reflectance(eta, critical_cos * 0.999) == 1.0);
  CHECK(fresnel_transmittance(eta, 0.3) == 0.0);
  CHECK(fresnel_reflectance(eta, critical_cos * 1.001) < 1.0);
  // F(η, cos θi) = F(1/η, cos θt): the interface reflects equally from both sides.
  for (double ci : {0.05, 0.3, 0.7, 0.99}) {
    const double n = 1.55;
    const double ct = std::sqrt(1.0 - (1.0 - ci * ci) / (n * n));
    CHECK(fresnel_reflectance(n, ci) == Approx(fresnel_reflectance(1.0 / n, ct)).epsilon(1e-13));
  }
}

TEST_CASE("Bravais indices", "[fresnel]") {
  for (double eta : {1.01, 1.55, 3.0})
    for (double td : {0.0, 0.3, 1.0, 1.5, 1.5707})
      {
        const double ep = bravais_eta_prime(eta, td), epp = bravais_eta_double_prime(eta, td);
        CHECK(ep * epp == Approx(eta * eta).epsilon(1e-13));  // η' η'' = η²
        CHECK(ep >= eta);
        CHECK(inverse_bravais_eta_prime(eta, td) == Approx(1.0 / ep).epsilon(1e-14));
        // Definition: η'² cos²θd = η² − sin²θd.
        CHECK(ep * ep * std::cos(td) * std::cos(td) == Approx(eta * eta - std::sin(td) * std::sin(td)).epsilon(1e-12));
      }
  CHECK(bravais_eta_prime(1.55, 0.0) == 1.55);
  CHECK(inverse_bravais_eta_prime(1.55, 1.5707963267948966) < 1e-15);
}
