#include "hairlut/physics/fiber_geometry.hpp"

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/fresnel.hpp"

namespace hairlut {

FiberGeometry FiberGeometry::make(double eta, double theta_d) {
  require_greater("eta", eta, 1.0, "must be a finite number > 1");
  theta_d = checked_inclination("theta_d", theta_d);
  FiberGeometry g;
  g.eta = eta;
  g.theta_d = theta_d;
  g.cos_theta_d = std::cos(theta_d);
  const double root = std::sqrt(eta_squared_minus_sin2(eta, g.cos_theta_d));  // √(η² − sin²θd)
  g.inv_eta_prime = g.cos_theta_d / root;
  g.sin_theta_t = std::sin(theta_d) / eta;
  g.cos_theta_t = root / eta;
  return g;
}

double caustic_gamma(int p, const FiberGeometry& g) {
  if (p < 2) return -1.0;
  // η'² = 1/inv²; sin²γc = (p² − η'²)/(p² − 1) needs η' ≤ p, i.e. p·(1/η') ≥ 1.
  const double pa = p * g.inv_eta_prime;
  if (pa <= 1.0) return -1.0;
  const double p2 = static_cast<double>(p) * p;
  // (p² − η'²)/(p² − 1) = (p²a² − 1) / (a²(p² − 1)) with a = 1/η'.
  const double s2 = (pa - 1.0) * (pa + 1.0) / (g.inv_eta_prime * g.inv_eta_prime * (p2 - 1.0));
  return std::asin(std::sqrt(std::min(1.0, s2)));
}

}  // namespace hairlut
