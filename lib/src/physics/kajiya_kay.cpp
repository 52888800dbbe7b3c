#include "hairlut/physics/kajiya_kay.hpp"

#include <algorithm>
#include <cmath>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/util/quadrature.hpp"

namespace hairlut {
namespace {

double check_incidence(double theta_i) {
  theta_i = checked_inclination("theta_i", theta_i);
  if (!(std::abs(theta_i) < kHalfPi)) throw_domain_error("theta_i", "must lie in (-pi/2, pi/2): Kajiya-Kay diverges at grazing incidence", theta_i);
  return theta_i;
}

}  // namespace

void KajiyaKayParams::validate() const {
  require_non_negative("kd", kd);
  require_non_negative("ks", ks);
  require_positive("exponent", exponent);
}

double KajiyaKayParams::exponent_for_width(double beta) {
  require_positive("beta", beta);
  return 1.0 / (4.0 * beta * beta);
}

double kajiya_kay_longitudinal(const KajiyaKayParams& params, double theta_i, double theta_r) {
  params.validate();
  theta_i = check_incidence(theta_i);
  theta_r = checked_inclination("theta_r", theta_r);
  const double c = std::max(0.0, std::cos(theta_r + theta_i));
  return params.kd + params.ks * std::pow(c, params.exponent) / std::cos(theta_i);
}

double kajiya_kay_energy(const KajiyaKayParams& params, double theta_i) {
  params.validate();
  theta_i = check_incidence(theta_i);
  std::vector<double> bp = {-kHalfPi, kHalfPi};
  if (std::abs(theta_i) < kHalfPi) bp.insert(bp.begin() + 1, -theta_i);
  AdaptiveOptions opt;
  opt.rel_tol = 1e-10;
  opt.abs_tol = 1e-15;
  const AdaptiveResult r = integrate_adaptive(
      [&](double tr, std::span<double> out) {
        const double c = std::cos(tr);
        out[0] = kajiya_kay_longitudinal(params, theta_i, tr) * c * c;
      },
      1, bp, opt);
  return kTwoPi * r.value[0];
}

}  // namespace hairlut
