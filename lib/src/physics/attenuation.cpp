#include "hairlut/physics/attenuation.hpp"

#include <cmath>
#include <string>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/fresnel.hpp"

namespace hairlut {

std::string_view to_string(AbsorptionPath path) {
  return path == AbsorptionPath::chord ? "chord" : "papers";
}

AbsorptionPath parse_absorption_path(std::string_view text, std::string_view what) {
  if (text == "chord") return AbsorptionPath::chord;
  if (text == "papers") return AbsorptionPath::papers;
  throw DomainError(std::string(what) + " must be \"chord\" or \"papers\" (got \"" + std::string(text) + "\")");
}

double PathPoint::attenuation(int p) const {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  if (p == 0) return f;
  // (1 − f)² f^{p−1} T^p; std::pow with an integral exponent is exact enough and gives 0^0 = 1.
  return one_minus_f * one_minus_f * std::pow(f, p - 1) * std::pow(T, p);
}

double PathPoint::residual_attenuation(int P) const {
  if (P < 1) throw_domain_error("P", "must be >= 1", static_cast<long long>(P));
  const double denom = one_minus_f + f * one_minus_T;  // 1 − fT without cancellation
  if (denom <= 0.0) return 0.0;                        // f = 1 and T = 1: the numerator is 0 too
  const double value = one_minus_f * one_minus_f * std::pow(f, P - 1) * std::pow(T, P) / denom;
  return std::min(value, 1.0);
}

AttenuationSlice::AttenuationSlice(double eta, double theta_d, double sigma_a, AbsorptionPath path)
    : geometry_(FiberGeometry::make(eta, theta_d)), sigma_a_(sigma_a), path_(path) {
  require_non_negative("sigma_a", sigma_a);
  sigma_a_prime_ = reduced_absorption(sigma_a, geometry_);
}

PathPoint AttenuationSlice::at_gamma(double gamma_i) const {
  gamma_i = checked_inclination("gamma_i", gamma_i);
  return evaluate(std::sin(gamma_i), gamma_i, std::cos(gamma_i));
}

PathPoint AttenuationSlice::at_h(double h) const {
  require_in_range("h", h, -1.0, 1.0, "must lie in [-1, 1]");
  return evaluate(h, std::asin(h), std::sqrt((1.0 - h) * (1.0 + h)));
}

PathPoint AttenuationSlice::evaluate(double h, double gamma_i, double cos_gamma_i) const {
  PathPoint q;
  const double a = geometry_.inv_eta_prime;
  q.gamma_i = gamma_i;
  q.cos_gamma_i = cos_gamma_i;
  const double s = h * a;  // sin γt, |s| ≤ 1/η' < 1
  q.gamma_t = std::asin(s);
  q.cos_gamma_t = std::sqrt((1.0 - s) * (1.0 + s));
  const double c = geometry_.cos_theta_d * cos_gamma_i;  // cos of the angle of incidence (eq. 14)
  q.f = fresnel_reflectance(geometry_.eta, c);
  q.one_minus_f = fresnel_transmittance(geometry_.eta, c);
  const double length = path_ == AbsorptionPath::chord ? 2.0 * q.cos_gamma_t
                                                       : 4.0 * q.cos_gamma_t * q.cos_gamma_t;
  const double tau = sigma_a_prime_ * length;
  q.T = std::exp(-tau);
  q.one_minus_T = -std::expm1(-tau);
  return q;
}

}  // namespace hairlut

namespace hairlut {

double edge_segment_length(const FiberGeometry& g, AbsorptionPath path) {
  const double a = g.inv_eta_prime;  // sin γt at h = 1, as AttenuationSlice::at_h(1) evaluates it
  const double ct = std::sqrt((1.0 - a) * (1.0 + a));
  return path == AbsorptionPath::chord ? 2.0 * ct : 4.0 * ct * ct;
}

double least_absorption(const AttenuationSlice& slice, int p) {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  if (p == 0 || slice.sigma_a() == 0.0) return 1.0;
  return std::pow(slice.at_h(1.0).T, p);  // T(−1) = T(1): the segment length depends on |h|
}

}  // namespace hairlut
