#include "hairlut/physics/directional_albedo.hpp"

#include <algorithm>
#include <cmath>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/util/quadrature.hpp"

namespace hairlut {
namespace {

std::vector<double> finish_breakpoints(std::vector<double> bp) {
  std::erase_if(bp, [](double t) { return !(t > -kHalfPi && t < kHalfPi); });
  bp.push_back(-kHalfPi);
  bp.push_back(kHalfPi);
  std::sort(bp.begin(), bp.end());
  bp.erase(std::unique(bp.begin(), bp.end()), bp.end());
  return bp;
}

}  // namespace

void add_longitudinal_breakpoints(std::vector<double>& bp, double beta, double alpha, double theta_i) {
  // The lobe peaks where fold(θr − α) = −θi: θr − α = −θi, or π + θi / −π + θi folded over a pole.
  for (double c : {-theta_i + alpha, kPi + theta_i + alpha, -kPi + theta_i + alpha}) {
    if (!(c > -kHalfPi - 8.0 * beta && c < kHalfPi + 8.0 * beta)) continue;
    bp.push_back(c);
    for (double w = beta; w < kHalfPi; w *= 4.0) {
      bp.push_back(c - w);
      bp.push_back(c + w);
    }
  }
  bp.push_back(alpha - kHalfPi);  // where θr − α crosses a pole: the fold makes a kink
  bp.push_back(alpha + kHalfPi);
}

AlbedoResult directional_albedo(const HairModel& model, double theta_i, double rel_tol, int energy_order) {
  model.validate();
  theta_i = checked_inclination("theta_i", theta_i);
  const GaussLegendreRule rule(energy_order);
  const LobeSet lobes{static_cast<int>(model.lobes.size()), model.residual.has_value()};
  std::vector<LobeParams> params = model.lobes;
  if (model.residual) params.push_back(*model.residual);

  std::vector<double> bp;
  for (const LobeParams& l : params) add_longitudinal_breakpoints(bp, l.beta_m, l.alpha, theta_i);
  bp = finish_breakpoints(std::move(bp));

  auto integrand = [&](double theta_r, std::span<double> out) {
    const AttenuationSlice slice(model.eta, 0.5 * (theta_r - theta_i), model.sigma_a, model.path);
    const std::vector<double> e = lobe_energies(slice, lobes, rule);
    const double c = std::cos(theta_r);
    for (std::size_t p = 0; p < params.size(); ++p)
      out[p] = longitudinal_deon_tilted(params[p].beta_m * params[p].beta_m, params[p].alpha, theta_i, theta_r) * e[p] * c;
  };
  AdaptiveOptions opt;
  opt.rel_tol = rel_tol;
  opt.abs_tol = kAlbedoAbsTol;  // a lobe of (almost) no energy is done at the noise floor
  const AdaptiveResult r = integrate_adaptive(integrand, params.size(), bp, opt);

  AlbedoResult a;
  a.theta_i = theta_i;
  a.per_lobe = r.value;
  for (std::size_t p = 0; p < params.size(); ++p) a.total += r.value[p], a.error += r.error[p];
  a.converged = r.converged;
  return a;
}

AdaptiveResult longitudinal_energy_deon(double v, double alpha, double theta_i, double rel_tol) {
  (void)longitudinal_deon_tilted(v, alpha, theta_i, 0.0);  // validates the arguments
  std::vector<double> bp;
  add_longitudinal_breakpoints(bp, std::sqrt(v), alpha, theta_i);
  bp = finish_breakpoints(std::move(bp));
  AdaptiveOptions opt;
  opt.rel_tol = rel_tol;
  return integrate_adaptive(
      [&](double t, std::span<double> out) { out[0] = longitudinal_deon_tilted(v, alpha, theta_i, t) * std::cos(t); },
      1, bp, opt);
}

AdaptiveResult longitudinal_energy_gaussian(double beta, double alpha, double theta_i, GaussianArgument argument,
                                            double rel_tol) {
  (void)longitudinal_gaussian(beta, alpha, theta_i, 0.0, argument);  // validates the arguments
  std::vector<double> bp;
  if (const double centre = 2.0 * alpha - theta_i; centre > -kHalfPi && centre < kHalfPi) bp.push_back(centre);
  bp = finish_breakpoints(std::move(bp));
  AdaptiveOptions opt;
  opt.rel_tol = rel_tol;
  return integrate_adaptive(
      [&](double t, std::span<double> out) {
        const double c = std::cos(t);
        out[0] = longitudinal_gaussian(beta, alpha, theta_i, t, argument) * c * c;
      },
      1, bp, opt);
}

}  // namespace hairlut
