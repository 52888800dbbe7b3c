#include "hairlut/resolution.hpp"

#include <algorithm>
#include <cmath>

#include "hairlut/angles.hpp"
#include "hairlut/bake.hpp"
#include "hairlut/error.hpp"
#include "hairlut/sampled_error.hpp"
#include "hairlut/table_truth.hpp"

namespace hairlut {
namespace {

// Exact N_p of lobe p over the cartesian product of the four lists (Fourier method, 1e−12),
// as out[((b · ns + k) · nt + t) · nphi + j].
std::vector<double> exact_grid(double eta, AbsorptionPath path, int p, const std::vector<double>& betas, const std::vector<double>& sigmas,
                               const std::vector<double>& thetas, const std::vector<double>& phis, const std::shared_ptr<GaussLegendreCache>& rules) {
  NpGridRequest r;
  r.eta = eta;
  r.path = path;
  r.quadrature.method = NpQuadratureConfig::Method::fourier;
  r.quadrature.tolerance = 1e-12;
  r.lobes = p + 1;
  r.sigmas = sigmas;
  r.thetas = thetas;
  r.phis = phis;
  r.betas_of = [&](int) { return betas; };
  r.rules = rules;
  std::vector<double> out(betas.size() * sigmas.size() * thetas.size() * phis.size());
  const std::size_t ns = sigmas.size(), nt = thetas.size(), nphi = phis.size();
  BakeOptions o;
  bake_np_grid(r, o, "", [&](int q, std::size_t k, std::size_t t, std::size_t b, std::size_t j, double v) {
    if (q == p) out[((b * ns + k) * nt + t) * nphi + j] = v;
  });
  return out;
}

// The midpoint of cell i in the axis's mapped coordinate.
double midpoint(const GridAxis& a, int i) {
  const double t0 = sampler::mapped(a.spacing, sampler::node(a.view(), i)), t1 = sampler::mapped(a.spacing, sampler::node(a.view(), i + 1));
  return sampler::unmapped(a.spacing, 0.5 * (t0 + t1));
}

std::uint64_t next_random(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

AxisErrorProbe::AxisErrorProbe(std::vector<GridAxis> axes, double eta, AbsorptionPath path, int lobes, int probes)
    : axes_(std::move(axes)), eta_(eta), path_(path), lobes_(std::min(lobes, 3)), rules_(std::make_shared<GaussLegendreCache>()) {
  if (axes_.size() != 4 || axes_[0].name != "beta" || axes_[1].name != "sigma_a" || axes_[2].name != "theta_d" || axes_[3].name != "phi")
    throw DomainError("the N_p resolution needs the axes beta, sigma_a, theta_d, phi");
  // Probes: fixed points over the domain (deterministic).
  std::uint64_t state = 12345;
  auto uniform = [&]() { return static_cast<double>(next_random(state) >> 11) * 0x1.0p-53; };
  for (int i = 0; i < probes; ++i) {
    std::array<double, 4> x{};
    for (std::size_t k = 0; k < 4; ++k) {
      const GridAxis& a = axes_[k];
      const double t0 = sampler::mapped(a.spacing, a.lo), t1 = sampler::mapped(a.spacing, a.hi);
      x[k] = a.spacing == Spacing::explicit_values ? a.values[next_random(state) % a.values.size()]
                                                   : sampler::unmapped(a.spacing, t0 + uniform() * (t1 - t0));
    }
    probes_.push_back(x);
  }
  // The peak of each lobe over the domain (coarse grid of the four axes).
  peak_.assign(3, 1e-300);
  std::vector<std::vector<double>> coarse(4);
  for (std::size_t k = 0; k < 4; ++k) {
    GridAxis a = axes_[k];
    if (a.spacing != Spacing::explicit_values) a.count = k == 3 ? 128 : 8, a.values.clear();
    coarse[k] = a.nodes();
  }
  for (int p = 0; p < lobes_; ++p)
    for (double v : exact_grid(eta_, path_, p, coarse[0], coarse[1], coarse[2], coarse[3], rules_))
      peak_[static_cast<std::size_t>(p)] = std::max(peak_[static_cast<std::size_t>(p)], v);
}

double AxisErrorProbe::error(std::size_t k, int count) const {
  GridAxis a = axes_[k];
  if (a.spacing == Spacing::explicit_values) return 0.0;  // explicit nodes are fixed
  a.count = count;
  a.values.clear();
  const std::vector<double> nodes = a.nodes();
  std::vector<double> mids;
  for (int i = 0; i + 1 < count; ++i) mids.push_back(midpoint(a, i));
  double worst = 0.0;
  for (const auto& pr : probes_)
    for (int p = 0; p < lobes_; ++p) {
      auto along = [&](const std::vector<double>& xs) {
        std::vector<std::vector<double>> lists = {{pr[0]}, {pr[1]}, {pr[2]}, {pr[3]}};
        lists[k] = xs;
        return exact_grid(eta_, path_, p, lists[0], lists[1], lists[2], lists[3], rules_);
      };
      const auto vn = along(nodes), vm = along(mids);
      const double peak = peak_[static_cast<std::size_t>(p)];
      for (std::size_t i = 0; i < vm.size(); ++i) worst = std::max(worst, std::abs(0.5 * (vn[i] + vn[i + 1]) - vm[i]) / peak);
    }
  return worst;
}

ResolutionPlan plan_np_resolution(const std::vector<GridAxis>& axes, double eta, AbsorptionPath path, int lobes, double target,
                                  std::size_t max_entries) {
  if (!(target > 0.0 && target < 0.5)) throw_domain_error("tables.np.target_error", "must lie in (0, 0.5)", target);
  const AxisErrorProbe probe(axes, eta, path, lobes);
  auto axis_error = [&](std::size_t k, int count) { return probe.error(k, count); };
  ResolutionPlan plan;
  plan.axes = axes;
  plan.entries = 1;
  plan.predicted_error = 0.0;
  // Each axis gets an equal share of the target (second-order interpolation on every axis makes
  // the Lagrange shares equal). Its count doubles from 16 until the measured error is within the
  // share, then is interpolated in log–log between the last two counts (error ∝ n^−s locally).
  const double share = target / 4.0;
  for (std::size_t k = 0; k < 4; ++k) {
    GridAxis& a = plan.axes[k];
    if (a.spacing != Spacing::explicit_values) {
      int lo = 16;
      double e_lo = axis_error(k, lo);
      int n = lo;
      double e = e_lo;
      while (e > share && n < (1 << 14)) {
        lo = n, e_lo = e;
        n *= 2;
        e = axis_error(k, n);
      }
      int need = n;
      if (n > lo && e < share && e_lo > share && e > 0.0) {
        const double slope = std::log(e_lo / e) / std::log(static_cast<double>(n) / lo);
        plan.slope[a.name] = slope;
        need = std::min(n, static_cast<int>(std::ceil(lo * std::pow(e_lo / share, 1.0 / std::max(slope, 0.5)))));
        e = axis_error(k, need);
        if (e > share) need = n, e = axis_error(k, n);
      }
      a.count = std::max(a.count, std::max(need, 2));
      plan.axis_error[a.name] = a.count == need ? e : axis_error(k, a.count);
    } else {
      plan.axis_error[a.name] = 0.0;
    }
    plan.predicted_error += plan.axis_error[a.name];
    plan.entries *= static_cast<std::size_t>(a.count);
    if (plan.entries > max_entries)
      throw DomainError("tables.np.target_error " + std::to_string(target) + " needs more than " + std::to_string(max_entries) +
                        " entries per lobe over these ranges; raise the target or narrow the ranges");
    a.validate("tables.np.axes." + a.name);
  }
  return plan;
}

AchievedError measure_np_error(const TableSet& set, double eta, AbsorptionPath path, std::size_t samples, int threads) {
  TruthModel model;
  model.eta = eta;
  model.path = path;
  if (set.metadata.contains("lobes") && set.metadata["lobes"].is_array()) model.explicit_lobes = static_cast<int>(set.metadata["lobes"].size());
  const auto rule = std::make_shared<const GaussLegendreRule>(1024);
  AchievedError a;
  for (const Table& t : set.tables) {
    if (t.group != "np" || t.quantity != "N_p" || t.attributes.value("lobe", std::string()) == "residual") continue;
    const auto truth = table_truth(t, model, rule);
    if (!truth) continue;
    SampledErrorOptions o;
    o.points = samples;
    o.seed = 0x5eed0000ULL + static_cast<std::uint64_t>(t.attributes.value("p", 0));
    o.threads = threads;
    const SampledError r = measure_sampled_error(set, t, *truth, o);
    a.points += r.error.points;
    a.per_table[t.path()] = {r.error.worst, r.error.p99};
    if (r.error.worst > a.worst || a.worst_table.empty()) a.worst = std::max(a.worst, r.error.worst), a.worst_table = t.path();
    a.p99 = std::max(a.p99, r.error.p99);
    a.denominator = r.denominator;
  }
  return a;
}

}  // namespace hairlut
