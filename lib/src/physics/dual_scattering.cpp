#include "hairlut/physics/dual_scattering.hpp"

#include <algorithm>
#include <cmath>

#include "hairlut/util/angles.hpp"
#include "hairlut/physics/azimuthal_fourier.hpp"
#include "hairlut/physics/azimuthal_np.hpp"
#include "hairlut/physics/directional_albedo.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/fresnel.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"

namespace hairlut {
namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440;

// P(a ≤ Z ≤ b) for a standard normal Z and a ≤ b, from the smaller tail(s) so that no digits cancel.
double normal_mass(double a, double b) {
  if (!(b > a)) return 0.0;
  if (a >= 0.0) return 0.5 * (std::erfc(a * kInvSqrt2) - std::erfc(b * kInvSqrt2));
  if (b <= 0.0) return 0.5 * (std::erfc(-b * kInvSqrt2) - std::erfc(-a * kInvSqrt2));
  return 1.0 - 0.5 * std::erfc(b * kInvSqrt2) - 0.5 * std::erfc(-a * kInvSqrt2);
}

// Σ_{n odd} (−1)^{(n−1)/2} e^{−n²β²/2} cos(n x) / n, the φ-dependent part of the half masses.
double half_mass_series(double beta, double x) {
  double s = 0.0;
  for (int n = 1;; n += 2) {
    const double g = std::exp(-0.5 * static_cast<double>(n) * n * beta * beta);
    if (g < 1e-19) break;
    s += ((n / 2) % 2 == 0 ? 1.0 : -1.0) * g * std::cos(n * x) / n;
  }
  return s;
}

// Σ_k P(lo ≤ x + 2πk + βZ ≤ hi) over the images whose interval lies within 40 standard deviations.
double image_mass(double beta, double x, double lo, double hi) {
  double sum = 0.0;
  for (int k = -3; k <= 3; ++k) {
    const double c = x + kTwoPi * k;
    if (c < lo - 40.0 * beta || c > hi + 40.0 * beta) continue;
    sum += normal_mass((lo - c) / beta, (hi - c) / beta);
  }
  return std::clamp(sum, 0.0, 1.0);
}

void check_beta(double beta) { require_positive("beta", beta); }

// Breakpoints of a half-range integrand over γ in [0, π/2]: the γ where Φ(p, γ) ≡ ±π/2 (the edges
// of the halves, where W_b and W_f step over a width δ = β/|dΦ/dγ|), refined at δ·4^k on both sides
// so that no panel next to an edge is much wider than the edge, and the caustic.
std::vector<double> half_range_breakpoints(const FiberGeometry& g, int p, double beta) {
  const double edges[2] = {kHalfPi, -kHalfPi};
  return detector_breakpoints(g, p, beta, edges);
}

}  // namespace

double detector_mass_backward(double beta, double Phi) {
  check_beta(beta);
  if (!std::isfinite(Phi)) throw_domain_error("Phi", "must be finite", Phi);
  const double x = wrap_azimuth(Phi);
  if (beta > 1.5) return std::clamp(0.5 + (2.0 / kPi) * half_mass_series(beta, x), 0.0, 1.0);
  return image_mass(beta, x, -kHalfPi, kHalfPi);
}

double detector_mass_forward(double beta, double Phi) {
  check_beta(beta);
  if (!std::isfinite(Phi)) throw_domain_error("Phi", "must be finite", Phi);
  const double x = wrap_azimuth(Phi);
  if (beta > 1.5) return std::clamp(0.5 - (2.0 / kPi) * half_mass_series(beta, x), 0.0, 1.0);
  return image_mass(beta, x, kHalfPi, 1.5 * kPi);
}

HalfRangeEnergy half_range_fourier(std::span<const double> c, std::size_t stride, double beta, double tolerance) {
  if (c.empty() || stride == 0) throw DomainError("half_range_fourier needs at least C_0");
  const std::size_t available = (c.size() - 1) / stride;  // highest n present
  const auto terms = std::min<std::size_t>(available, static_cast<std::size_t>(fourier_terms(beta, tolerance)));
  double s = 0.0;
  for (std::size_t n = 1; n <= terms; n += 2) {
    const double dn = static_cast<double>(n);
    s += (((n - 1) / 2) % 2 == 0 ? 1.0 : -1.0) * std::exp(-0.5 * dn * dn * beta * beta) * c[n * stride] / dn;
  }
  const double c0 = c[0];
  return {std::max(0.0, 0.5 * c0 + (2.0 / kPi) * s), std::max(0.0, 0.5 * c0 - (2.0 / kPi) * s)};
}

bool half_range_direct(const FiberGeometry& g, AbsorptionPath path, int p, std::span<const double> sigmas, double beta,
                       std::span<double> out, double rel_tol) {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  check_beta(beta);
  if (out.size() != 2 * sigmas.size()) throw DomainError("half_range_direct: out must hold 2 values per sigma_a");
  const std::size_t K = sigmas.size();
  std::vector<double> sigma_prime(K);
  for (std::size_t k = 0; k < K; ++k) {
    require_non_negative("sigma_a", sigmas[k]);
    sigma_prime[k] = reduced_absorption(sigmas[k], g);
  }
  const std::vector<double> bp = half_range_breakpoints(g, p, beta);
  // A(p, sin γ) cos γ W(Φ(p, γ)) for every σa: backward in even slots, forward in odd slots.
  auto integrand = [&](double gamma, std::span<double> v) {
    const double ci = std::cos(gamma), sg = std::sin(gamma);
    const double st = sg * g.inv_eta_prime;
    const double ct = std::sqrt((1.0 - st) * (1.0 + st));
    const double cosine = g.cos_theta_d * ci;
    const double f = detail::fresnel_reflectance_unchecked(g.eta, cosine);
    const double omf = detail::fresnel_transmittance_unchecked(g.eta, cosine);
    double base = p == 0 ? f : omf * omf;
    for (int q = 1; q < p; ++q) base *= f;
    base *= ci;
    if (base == 0.0) {
      std::fill(v.begin(), v.end(), 0.0);
      return;
    }
    const double Phi = exit_azimuth(p, gamma, std::asin(st));
    const double wb = detector_mass_backward(beta, Phi), wf = detector_mass_forward(beta, Phi);
    const double length = path == AbsorptionPath::chord ? 2.0 * ct : 4.0 * ct * ct;
    for (std::size_t k = 0; k < K; ++k) {
      const double a = p == 0 ? base : base * std::exp(-static_cast<double>(p) * sigma_prime[k] * length);
      v[2 * k] = a * wb;
      v[2 * k + 1] = a * wf;
    }
  };
  AdaptiveOptions opt;
  opt.rel_tol = rel_tol;
  opt.abs_tol = 1e-15;
  const AdaptiveResult r = integrate_adaptive(integrand, 2 * K, bp, opt);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = std::max(0.0, r.value[i]);
  return r.converged;
}

HalfRangeEnergy half_range_direct(const AttenuationSlice& slice, int p, double beta, double rel_tol) {
  double out[2];
  const double sigma[1] = {slice.sigma_a()};
  half_range_direct(slice.geometry(), slice.path(), p, sigma, beta, out, rel_tol);
  return {out[0], out[1]};
}

ZinkeBackscatter zinke_backscatter(double a_f, double a_b, double alpha_f, double alpha_b, double beta_f2, double beta_b2,
                                   double d_b) {
  require_in_range("a_f", a_f, 0.0, 1.0, "must lie in [0, 1]");
  require_in_range("a_b", a_b, 0.0, 1.0, "must lie in [0, 1]");
  require_non_negative("beta_f2", beta_f2);
  require_non_negative("beta_b2", beta_b2);
  require_in_range("density_factor", d_b, 0.0, 1.0, "must lie in [0, 1]");
  ZinkeBackscatter z;
  const double af2 = a_f * a_f, ab2 = a_b * a_b, ab3 = ab2 * a_b;
  const double one = std::max((1.0 - a_f) * (1.0 + a_f), 1e-12);  // 1 − ā_f²
  const double one2 = one * one, one3 = one2 * one;
  z.A_b = a_b * af2 / one + ab3 * af2 / one3;                                                       // eq. 14
  z.delta_b = alpha_b * (1.0 - 2.0 * ab2 / one2) + alpha_f * (2.0 * one2 + 4.0 * af2 * ab2) / one3;  // eq. 16
  const double spread1 = std::sqrt(2.0 * beta_f2 + beta_b2), spread3 = std::sqrt(2.0 * beta_f2 + 3.0 * beta_b2);
  const double scale = 1.0 + d_b * af2;
  const double num = a_b * spread1 + ab3 * spread3;
  z.sigma_b = a_b + ab3 > 0.0 ? scale * num / (a_b + ab3) : scale * spread1;  // eq. 17
  const double mixed = a_b + ab3 * (2.0 * std::sqrt(beta_f2) + 3.0 * std::sqrt(beta_b2));
  z.sigma_b_mixed = mixed > 0.0 ? scale * num / mixed : scale * spread1;
  return z;
}

void finish_dual_scattering(DualScatteringPoint& pt, std::span<const LobeParams> lobes, double d_b) {
  if (pt.energy.size() != lobes.size() || pt.forward.size() != lobes.size() || pt.backward.size() != lobes.size())
    throw DomainError("finish_dual_scattering: one energy, forward and backward value per lobe required");
  pt.energy_total = pt.a_f = pt.a_b = 0.0;
  double sa_f = 0.0, sa_b = 0.0, sb_f = 0.0, sb_b = 0.0;
  for (std::size_t l = 0; l < lobes.size(); ++l) {
    pt.energy_total += pt.energy[l];
    pt.a_f += pt.forward[l];
    pt.a_b += pt.backward[l];
    const double v = lobes[l].beta_m * lobes[l].beta_m;
    sa_f += pt.forward[l] * lobes[l].alpha, sb_f += pt.forward[l] * v;  // eq. 12–13 numerators
    sa_b += pt.backward[l] * lobes[l].alpha, sb_b += pt.backward[l] * v;
  }
  pt.alpha_f = pt.a_f > 0.0 ? sa_f / pt.a_f : 0.0;
  pt.beta_f2 = pt.a_f > 0.0 ? sb_f / pt.a_f : 0.0;
  pt.alpha_b = pt.a_b > 0.0 ? sa_b / pt.a_b : 0.0;
  pt.beta_b2 = pt.a_b > 0.0 ? sb_b / pt.a_b : 0.0;
  pt.backscatter = zinke_backscatter(std::min(pt.a_f, 1.0), std::min(pt.a_b, 1.0), pt.alpha_f, pt.alpha_b, pt.beta_f2, pt.beta_b2, d_b);
}

DualScatteringPoint dual_scattering(const HairModel& model, double theta_i, const DualScatteringOptions& opt) {
  model.validate();
  theta_i = checked_inclination("theta_i", theta_i);
  const GaussLegendreRule rule(opt.energy_order);
  const int P = static_cast<int>(model.lobes.size());
  const LobeSet lobes{P, model.residual.has_value()};
  std::vector<LobeParams> params = model.lobes;
  if (model.residual) params.push_back(*model.residual);
  const std::size_t L = params.size();

  std::vector<double> bp;
  for (const LobeParams& l : params) add_longitudinal_breakpoints(bp, l.beta_m, l.alpha, theta_i);
  std::erase_if(bp, [](double t) { return !(t > -kHalfPi && t < kHalfPi); });
  bp.push_back(-kHalfPi);
  bp.push_back(kHalfPi);
  std::sort(bp.begin(), bp.end());
  bp.erase(std::unique(bp.begin(), bp.end()), bp.end());

  bool inner_converged = true;
  // Components per lobe l: 3l energy, 3l + 1 forward, 3l + 2 backward.
  auto integrand = [&](double theta_r, std::span<double> out) {
    const AttenuationSlice slice(model.eta, 0.5 * (theta_r - theta_i), model.sigma_a, model.path);
    const std::vector<double> e = lobe_energies(slice, lobes, rule);
    const double c = std::cos(theta_r);
    for (std::size_t l = 0; l < L; ++l) {
      const double M = longitudinal_deon_tilted(params[l].beta_m * params[l].beta_m, params[l].alpha, theta_i, theta_r) * c;
      HalfRangeEnergy h{0.5 * e[l], 0.5 * e[l]};  // the residual is uniform in φ
      if (static_cast<int>(l) < P && M != 0.0) {
        double v[2];
        const double sigma[1] = {model.sigma_a};
        inner_converged &= half_range_direct(slice.geometry(), model.path, static_cast<int>(l), sigma, params[l].beta_n, v, 1e-11);
        h = {v[0], v[1]};
      }
      out[3 * l] = M * e[l];
      out[3 * l + 1] = M * h.forward;
      out[3 * l + 2] = M * h.backward;
    }
  };
  AdaptiveOptions ao;
  ao.rel_tol = opt.rel_tol;
  ao.abs_tol = 1e-14;
  const AdaptiveResult r = integrate_adaptive(integrand, 3 * L, bp, ao);

  DualScatteringPoint pt;
  pt.theta_i = theta_i;
  for (std::size_t l = 0; l < L; ++l) {
    pt.energy.push_back(r.value[3 * l]);
    pt.forward.push_back(std::max(0.0, r.value[3 * l + 1]));
    pt.backward.push_back(std::max(0.0, r.value[3 * l + 2]));
  }
  finish_dual_scattering(pt, params, opt.density_factor);
  pt.converged = r.converged && inner_converged;
  return pt;
}

}  // namespace hairlut
