#include "hairlut/physics/lobe_energy.hpp"

#include <span>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

void check_lobes(LobeSet lobes) {
  if (lobes.count < 1 || lobes.count > 1000)
    throw_domain_error("lobe count", "must lie in [1, 1000]", static_cast<long long>(lobes.count));
}

// Writes A(p, sin γ) cos γ for the lobes of `lobes` into out.
void energy_integrand(const AttenuationSlice& slice, LobeSet lobes, double gamma, std::span<double> out) {
  const PathPoint q = slice.at_gamma(gamma);
  for (int p = 0; p < lobes.count; ++p) out[p] = q.attenuation(p) * q.cos_gamma_i;
  if (lobes.residual) out[lobes.count] = q.residual_attenuation(lobes.count) * q.cos_gamma_i;
}

}  // namespace

std::vector<double> lobe_energies(const AttenuationSlice& slice, LobeSet lobes, const GaussLegendreRule& rule) {
  check_lobes(lobes);
  const auto m = static_cast<std::size_t>(lobes.size());
  std::vector<double> sum(m, 0.0), term(m);
  const auto x = rule.nodes();
  const auto w = rule.weights();
  const double half = 0.25 * kPi;  // [0, π/2] = π/4 (1 + x)
  for (std::size_t i = 0; i < x.size(); ++i) {
    energy_integrand(slice, lobes, half * (1.0 + x[i]), term);
    for (std::size_t c = 0; c < m; ++c) sum[c] += w[i] * term[c];
  }
  for (double& s : sum) s *= half;
  return sum;
}

AdaptiveResult lobe_energies_reference(const AttenuationSlice& slice, LobeSet lobes, double rel_tol) {
  check_lobes(lobes);
  const double bp[2] = {0.0, kHalfPi};
  AdaptiveOptions opt;
  opt.rel_tol = rel_tol;
  // Each entry to rel_tol relative to max(entry, 1e-3): the entries are fractions of unit energy,
  // and one far below that (R as η → 1 is ~1e-8, lit only at grazing incidence) would otherwise
  // demand an absolute error under 1e-21, which the 8000-interval budget cannot reach; 1e-3 x
  // rel_tol absolute is still far below what float32 or half tables of such an entry resolve.
  opt.abs_tol = rel_tol * 1e-3;
  return integrate_adaptive([&](double g, std::span<double> out) { energy_integrand(slice, lobes, g, out); },
                            static_cast<std::size_t>(lobes.size()), bp, opt);
}

}  // namespace hairlut
