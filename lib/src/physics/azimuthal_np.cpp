#include "hairlut/physics/azimuthal_np.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/gaussian_detector.hpp"
#include "monotone_roots.hpp"

namespace hairlut {
namespace {

void check_np_args(int p, double beta, double phi) {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  require_positive("beta", beta);
  if (!std::isfinite(phi)) throw_domain_error("phi", "must be finite", phi);
}

// ½ A(p) cos γ [D(φ − Φ) + D(φ + Φ)] at γ in [0, π/2]: the integrand of N_p folded onto h ≥ 0.
double folded_integrand(const AttenuationSlice& slice, int p, double beta, double phi, double gamma) {
  const PathPoint q = slice.at_gamma(gamma);
  const double a = q.attenuation(p);
  if (a == 0.0) return 0.0;
  const double Phi = q.exit_azimuth(p);
  return 0.5 * a * q.cos_gamma_i * (gaussian_detector(beta, phi - Phi) + gaussian_detector(beta, phi + Phi));
}

// Φ(p, γ) for the geometry, unwrapped.
double exit_azimuth_at(const FiberGeometry& g, int p, double gamma) {
  return exit_azimuth(p, gamma, std::asin(std::sin(gamma) * g.inv_eta_prime));
}

}  // namespace

std::string_view to_string(IntegrationVariable v) { return v == IntegrationVariable::gamma ? "gamma" : "h"; }

IntegrationVariable parse_integration_variable(std::string_view text, std::string_view what) {
  if (text == "gamma") return IntegrationVariable::gamma;
  if (text == "h") return IntegrationVariable::h;
  throw DomainError(std::string(what) + " must be \"gamma\" or \"h\" (got \"" + std::string(text) + "\")");
}

NpQuadratureSlab::NpQuadratureSlab(const AttenuationSlice& slice, int p, const GaussLegendreRule& rule,
                                   IntegrationVariable variable) {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  const auto x = rule.nodes();
  const auto w = rule.weights();
  const std::size_t n = x.size();
  // Nodes n/2 … n−1 are the non-negative ones; their mirror images contribute D(φ + Φ). An odd
  // rule's centre node is its own mirror and counts half in the pair.
  for (std::size_t i = n / 2; i < n; ++i) {
    const bool centre = (n % 2 == 1) && i == n / 2;
    const PathPoint q = variable == IntegrationVariable::gamma ? slice.at_gamma(kHalfPi * x[i]) : slice.at_h(x[i]);
    const double jacobian = variable == IntegrationVariable::gamma ? kHalfPi * q.cos_gamma_i : 1.0;  // dh/dx
    const double a = q.attenuation(p);
    if (a == 0.0) continue;
    weight_.push_back((centre ? 0.5 : 1.0) * w[i] * 0.5 * a * jacobian);
    phi_.push_back(q.exit_azimuth(p));
  }
}

double NpQuadratureSlab::operator()(double beta, double phi) const {
  check_np_args(0, beta, phi);
  double sum = 0.0;
  for (std::size_t i = 0; i < weight_.size(); ++i)
    sum += weight_[i] * (gaussian_detector(beta, phi - phi_[i]) + gaussian_detector(beta, phi + phi_[i]));
  return sum;
}

double azimuthal_np(const AttenuationSlice& slice, int p, double beta, double phi, const GaussLegendreRule& rule,
                    IntegrationVariable variable) {
  check_np_args(p, beta, phi);
  return NpQuadratureSlab(slice, p, rule, variable)(beta, phi);
}

AdaptiveResult azimuthal_np_reference(const AttenuationSlice& slice, int p, double beta, double phi, double rel_tol) {
  check_np_args(p, beta, phi);
  // Each peak of the integrand sits at a root γ0 of Φ ≡ ±φ and is about w = β/|dΦ/dγ| wide
  // (√β near a caustic). Breakpoints at γ0 ± w·4^k make every panel next to a peak no more than
  // four times wider than the peak, so no panel can miss a narrow peak between its nodes.
  const std::vector<double> bp = detector_breakpoints(slice.geometry(), p, beta, std::span<const double>(&phi, 1));
  AdaptiveOptions opt;
  opt.rel_tol = rel_tol;
  return integrate_adaptive(
      [&](double g, std::span<double> out) { out[0] = folded_integrand(slice, p, beta, phi, g); }, 1, bp, opt);
}

std::vector<double> detector_breakpoints(const FiberGeometry& geometry, int p, double beta, std::span<const double> phis) {
  std::vector<double> bp = {0.0, kHalfPi};
  for (double phi : phis)
    for (double g : azimuthal_roots(geometry, p, phi)) {
      const double centre = std::abs(g);
      const double st = std::sin(centre) * geometry.inv_eta_prime;
      const double slope =
          std::abs(exit_azimuth_derivative(p, std::cos(centre), std::sqrt((1.0 - st) * (1.0 + st)), geometry.inv_eta_prime));
      bp.push_back(centre);
      for (double w = beta / std::max(slope, 2.0 * std::sqrt(beta)); w < kHalfPi; w *= 4.0) {
        bp.push_back(centre - w);
        bp.push_back(centre + w);
      }
    }
  if (const double gc = caustic_gamma(p, geometry); gc > 0.0) bp.push_back(gc);
  std::erase_if(bp, [](double x) { return !(x >= 0.0 && x <= kHalfPi); });
  std::sort(bp.begin(), bp.end());
  bp.erase(std::unique(bp.begin(), bp.end()), bp.end());
  return bp;
}

std::vector<double> azimuthal_roots(const FiberGeometry& geometry, int p, double phi) {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  if (!std::isfinite(phi)) throw_domain_error("phi", "must be finite", phi);
  std::vector<double> edges = {-kHalfPi, kHalfPi};
  if (const double gc = caustic_gamma(p, geometry); gc > 0.0) edges = {-kHalfPi, -gc, gc, kHalfPi};
  return detail::monotone_piece_roots([&](double g) { return exit_azimuth_at(geometry, p, g); }, edges, phi);
}

double azimuthal_np_smooth(const AttenuationSlice& slice, int p, double phi) {
  double sum = 0.0;
  const FiberGeometry& g = slice.geometry();
  for (double gamma : azimuthal_roots(g, p, phi)) {
    const PathPoint q = slice.at_gamma(gamma);
    const double a = q.attenuation(p) * q.cos_gamma_i;
    if (a == 0.0) continue;
    const double d = std::abs(exit_azimuth_derivative(p, q.cos_gamma_i, q.cos_gamma_t, g.inv_eta_prime));
    if (d == 0.0) return std::numeric_limits<double>::infinity();
    sum += a / (2.0 * d);
  }
  return sum;
}

double azimuthal_residual_np(const AttenuationSlice& slice, int P, const GaussLegendreRule& energy_rule) {
  const std::vector<double> e = lobe_energies(slice, LobeSet{P, true}, energy_rule);
  return e.back() / kTwoPi;
}

}  // namespace hairlut
