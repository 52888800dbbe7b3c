// Out-of-domain arguments give a DomainError whose one-line message names the argument.
#include <cmath>
#include <hairlut/hairlut.hpp>
#include <string>

#include "catch.hpp"

using namespace hairlut;

namespace {
template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const DomainError& e) {
    return e.what();
  }
  return "(no error)";
}
bool names(const std::string& msg, const std::string& field) {
  return msg.rfind(field, 0) == 0 && msg.find('\n') == std::string::npos;
}
}  // namespace

TEST_CASE("Roughness must be positive", "[domain]") {
  const AttenuationSlice s(1.55, 0.1, 0.1);
  const GaussLegendreRule rule(16);
  CHECK(names(message_of([&] { azimuthal_np(s, 1, 0.0, 0.3, rule); }), "beta must be"));
  CHECK(names(message_of([&] { azimuthal_np(s, 1, -0.1, 0.3, rule); }), "beta must be"));
  CHECK(names(message_of([&] { azimuthal_np_reference(s, 1, NAN, 0.3); }), "beta must be"));
  CHECK(names(message_of([&] { gaussian_detector(0.0, 0.3); }), "beta must be"));
  CHECK(names(message_of([&] { longitudinal_deon(0.0, 0.1, 0.1); }), "v must be"));
  CHECK(names(message_of([&] { longitudinal_deon(-1e-3, 0.1, 0.1); }), "v must be"));
  CHECK(names(message_of([&] { longitudinal_deon(INFINITY, 0.1, 0.1); }), "v must be"));
  CHECK(names(message_of([&] { longitudinal_gaussian(0.0, 0.0, 0.1, 0.1, GaussianArgument::theta_h); }), "beta must be"));
  CHECK(names(message_of([&] { HairModel::uniform(1.55, 0.0, 0.0, 3, true); }), "lobes[0].beta_m must be"));
}

TEST_CASE("Index of refraction must exceed 1", "[domain]") {
  CHECK(names(message_of([&] { AttenuationSlice(1.0, 0.1, 0.1); }), "eta must be"));
  CHECK(names(message_of([&] { AttenuationSlice(0.9, 0.1, 0.1); }), "eta must be"));
  CHECK(names(message_of([&] { bravais_eta_prime(1.0, 0.1); }), "eta must be"));
  CHECK(names(message_of([&] { fresnel_reflectance(0.0, 0.5); }), "eta must be"));
  CHECK(names(message_of([&] { fresnel_reflectance(1.5, 1.5); }), "cos_theta_i must lie"));
}

TEST_CASE("Inclinations must lie in [-pi/2, pi/2]", "[domain]") {
  CHECK(names(message_of([&] { longitudinal_deon(0.1, 1.6, 0.1); }), "theta_i must lie"));
  CHECK(names(message_of([&] { longitudinal_deon(0.1, 0.1, -1.6); }), "theta_r must lie"));
  CHECK(names(message_of([&] { longitudinal_deon(0.1, NAN, 0.1); }), "theta_i must lie"));
  CHECK(names(message_of([&] { AttenuationSlice(1.55, 2.0, 0.1); }), "theta_d must lie"));
  CHECK(names(message_of([&] { directional_albedo(HairModel::uniform(1.55, 0.0, 0.1, 3, true), -2.0); }), "theta_i must lie"));
  // The rounded end points themselves are in the domain.
  CHECK(std::isfinite(longitudinal_deon(0.1, radians(90.0), radians(-90.0))));
  CHECK(std::isfinite(longitudinal_deon(0.1, M_PI / 2, -M_PI / 2)));
}

TEST_CASE("Absorption must be non-negative and lobes p >= 0", "[domain]") {
  CHECK(names(message_of([&] { AttenuationSlice(1.55, 0.1, -0.1); }), "sigma_a must be"));
  CHECK(names(message_of([&] { AttenuationSlice(1.55, 0.1, INFINITY); }), "sigma_a must be"));
  const AttenuationSlice s(1.55, 0.1, 0.1);
  const GaussLegendreRule rule(16);
  CHECK(names(message_of([&] { azimuthal_np(s, -1, 0.1, 0.3, rule); }), "p must be"));
  CHECK(names(message_of([&] { s.at_h(0.5).attenuation(-2); }), "p must be"));
  CHECK(names(message_of([&] { s.at_h(0.5).residual_attenuation(0); }), "P must be"));
  CHECK(names(message_of([&] { s.at_h(1.5); }), "h must lie"));
  CHECK(names(message_of([&] { azimuthal_roots(s.geometry(), -1, 0.0); }), "p must be"));
  CHECK(names(message_of([&] { lobe_energies(s, {0, true}, rule); }), "lobe count must"));
  CHECK(names(message_of([&] { GaussLegendreRule(0); }), "quadrature order must"));
  CHECK(names(message_of([&] { azimuthal_np(s, 1, 0.1, INFINITY, rule); }), "phi must be"));
}
