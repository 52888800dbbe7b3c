#include "hairlut/physics/fresnel.hpp"

#include <algorithm>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

void check_fresnel_args(double eta, double cos_theta_i) {
  require_positive("eta", eta);
  require_in_range("cos_theta_i", cos_theta_i, 0.0, 1.0, "must lie in [0, 1]");
}

}  // namespace

double fresnel_reflectance(double eta, double cos_theta_i) {
  check_fresnel_args(eta, cos_theta_i);
  return detail::fresnel_reflectance_unchecked(eta, cos_theta_i);
}

double fresnel_transmittance(double eta, double cos_theta_i) {
  check_fresnel_args(eta, cos_theta_i);
  return detail::fresnel_transmittance_unchecked(eta, cos_theta_i);
}

double bravais_eta_prime(double eta, double theta_d) {
  require_greater("eta", eta, 1.0, "must be a finite number > 1");
  theta_d = checked_inclination("theta_d", theta_d);
  const double c = std::cos(theta_d);
  return std::sqrt(eta_squared_minus_sin2(eta, c)) / c;
}

double inverse_bravais_eta_prime(double eta, double theta_d) {
  require_greater("eta", eta, 1.0, "must be a finite number > 1");
  theta_d = checked_inclination("theta_d", theta_d);
  const double c = std::cos(theta_d);
  return c / std::sqrt(eta_squared_minus_sin2(eta, c));
}

double bravais_eta_double_prime(double eta, double theta_d) {
  require_greater("eta", eta, 1.0, "must be a finite number > 1");
  theta_d = checked_inclination("theta_d", theta_d);
  const double c = std::cos(theta_d);
  return eta * eta * c / std::sqrt(eta_squared_minus_sin2(eta, c));
}

double fresnel_bravais(double inv_eta_prime, double eta_double_prime, double cos_gamma_i) {
  require_in_range("inv_eta_prime", inv_eta_prime, 0.0, 1.0, "must lie in [0, 1)");
  if (inv_eta_prime >= 1.0) throw_domain_error("inv_eta_prime", "must lie in [0, 1)", inv_eta_prime);
  require_non_negative("eta_double_prime", eta_double_prime);
  require_in_range("cos_gamma_i", cos_gamma_i, 0.0, 1.0, "must lie in [0, 1]");
  double F = 0.0, T = 0.0;
  detail::fresnel_bravais_unchecked(inv_eta_prime, eta_double_prime, cos_gamma_i, F, T);
  return F;
}

}  // namespace hairlut
