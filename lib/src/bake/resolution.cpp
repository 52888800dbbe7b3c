#include "hairlut/bake/resolution.hpp"

#include <algorithm>
#include <cmath>

#include "hairlut/util/angles.hpp"
#include "hairlut/bake/bake.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/bake/sampled_error.hpp"
#include "hairlut/bake/table_truth.hpp"

namespace hairlut {
namespace {

std::uint64_t next_random(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Index into exact_lists' output.
std::size_t index(int p, std::size_t k, std::size_t t, std::size_t b, std::size_t j, std::size_t ns, std::size_t nt, std::size_t nb,
                  std::size_t np) {
  return (((static_cast<std::size_t>(p) * ns + k) * nt + t) * nb + b) * np + j;
}

// A uniformly random coordinate on the axis's range (log-uniform on log axes).
double draw(const GridAxis& a, std::uint64_t& state) {
  const double u = static_cast<double>(next_random(state) >> 11) * 0x1.0p-53;
  if (a.spacing == Spacing::explicit_values) return a.values[next_random(state) % a.values.size()];
  if (a.lo == a.hi) return a.lo;
  if (a.spacing == Spacing::log) return std::exp(std::log(a.lo) + u * std::log(a.hi / a.lo));
  return a.lo + u * (a.hi - a.lo);
}

}  // namespace

AxisErrorProbe::AxisErrorProbe(std::vector<GridAxis> axes, double eta, AbsorptionPath path, int lobes, int probes, bool normalize_energy)
    : axes_(std::move(axes)), eta_(eta), path_(path), lobes_(std::min(lobes, 4)), normalize_(normalize_energy),
      rules_(std::make_shared<GaussLegendreCache>()), energy_rule_(std::make_shared<GaussLegendreRule>(128)) {
  if (axes_.size() != 4 || axes_[0].name != "beta" || axes_[1].name != "sigma_a" || axes_[2].name != "theta_d" || axes_[3].name != "phi")
    throw DomainError("the N_p resolution needs the axes beta, sigma_a, theta_d, phi");
  // Probe slabs: (σa, θd) drawn uniformly over their ranges, each with kBetas β and kPhis φ drawn
  // likewise (deterministic), the truth there and the slice peaks that scale its error.
  std::uint64_t state = 12345;
  const int dense = 721;
  for (int i = 0; i < probes; ++i) {
    Slab sl;
    sl.sigma = draw(axes_[1], state);
    sl.theta = draw(axes_[2], state);
    for (std::size_t b = 0; b < kBetas; ++b) sl.betas[b] = draw(axes_[0], state);
    for (std::size_t j = 0; j < kPhis; ++j) sl.phis[j] = draw(axes_[3], state);
    std::vector<double> phis(sl.phis.begin(), sl.phis.end());
    for (int j = 0; j < dense; ++j) phis.push_back(axes_[3].lo + (axes_[3].hi - axes_[3].lo) * j / (dense - 1));
    const std::vector<double> betas(sl.betas.begin(), sl.betas.end());
    const auto v = exact_lists(betas, {sl.sigma, 0.0}, {sl.theta}, phis);
    const std::size_t np = phis.size();
    for (int p = 0; p < lobes_; ++p)
      for (std::size_t b = 0; b < kBetas; ++b) {
        double peak = 0.0, white = 0.0;
        for (std::size_t j = kPhis; j < np; ++j) {
          peak = std::max(peak, v[index(p, 0, 0, b, j, 2, 1, kBetas, np)]);
          white = std::max(white, v[index(p, 1, 0, b, j, 2, 1, kBetas, np)]);
        }
        sl.scale[static_cast<std::size_t>(p)][b] = std::max(peak, 1e-3 * white);
        for (std::size_t j = 0; j < kPhis; ++j) sl.truth[static_cast<std::size_t>(p)][b][j] = v[index(p, 0, 0, b, j, 2, 1, kBetas, np)];
      }
    if (normalize_) sl.energy = energies(sl.sigma, sl.theta);
    slabs_.push_back(sl);
  }
}

std::vector<double> AxisErrorProbe::exact_lists(const std::vector<double>& betas, const std::vector<double>& sigmas,
                                                const std::vector<double>& thetas, const std::vector<double>& phis) const {
  NpGridRequest r;
  r.eta = eta_;
  r.path = path_;
  r.quadrature.method = NpQuadratureConfig::Method::fourier;
  r.quadrature.tolerance = 1e-12;
  r.lobes = lobes_;
  r.sigmas = sigmas;
  r.thetas = thetas;
  r.phis = phis;
  r.betas_of = [&](int) { return betas; };
  r.rules = rules_;
  std::vector<double> out(static_cast<std::size_t>(lobes_) * sigmas.size() * thetas.size() * betas.size() * phis.size());
  BakeOptions o;
  o.threads = 1;
  bake_np_grid(r, o, "", [&](int p, std::size_t k, std::size_t t, std::size_t b, std::size_t j, double v) {
    out[index(p, k, t, b, j, sigmas.size(), thetas.size(), betas.size(), phis.size())] = v;
  });
  return out;
}

std::vector<double> AxisErrorProbe::energies(double sigma, double theta) const {
  return lobe_energies(AttenuationSlice(eta_, theta, sigma, path_), LobeSet{lobes_, false}, *energy_rule_);
}

double AxisErrorProbe::error(std::size_t k, int count) const {
  GridAxis a = axes_[k];
  if (a.spacing == Spacing::explicit_values) return 0.0;  // explicit nodes are fixed
  a.count = count;
  a.values.clear();
  const sampler::PreparedAxis prepared(a.view());
  double worst = 0.0;
  for (const Slab& sl : slabs_) {
    // The nodes each probe coordinate interpolates from along axis k, and the truth there with
    // the other coordinates at the probe.
    const std::size_t nk = k == 0 ? kBetas : k == 3 ? kPhis : 1;
    std::vector<sampler::Taps> taps(nk);
    std::vector<double> nodes;
    for (std::size_t q = 0; q < nk; ++q) {
      const double x = k == 0 ? sl.betas[q] : k == 1 ? sl.sigma : k == 2 ? sl.theta : sl.phis[q];
      taps[q] = sampler::taps(prepared, x);
      for (int m = 0; m < taps[q].n; ++m) nodes.push_back(sampler::node(a.view(), taps[q].i[m]));
    }
    std::vector<double> betas(sl.betas.begin(), sl.betas.end()), sigmas = {sl.sigma}, thetas = {sl.theta}, phis(sl.phis.begin(), sl.phis.end());
    (k == 0 ? betas : k == 1 ? sigmas : k == 2 ? thetas : phis) = nodes;
    const auto v = exact_lists(betas, sigmas, thetas, phis);
    // Energies at the nodes (normalized tables interpolate N_p / E_p, then multiply by E_p here).
    std::vector<std::vector<double>> node_energy;
    if (normalize_)
      for (double x : nodes) node_energy.push_back(k == 1 ? energies(x, sl.theta) : k == 2 ? energies(sl.sigma, x) : sl.energy);
    for (int p = 0; p < lobes_; ++p)
      for (std::size_t b = 0; b < kBetas; ++b)
        for (std::size_t j = 0; j < kPhis; ++j) {
          const std::size_t q = k == 0 ? b : k == 3 ? j : 0;
          std::size_t first = 0;
          for (std::size_t r = 0; r < q; ++r) first += static_cast<std::size_t>(taps[r].n);
          double vals[4];
          for (int m = 0; m < taps[q].n; ++m) {
            const std::size_t node = first + static_cast<std::size_t>(m);
            const std::size_t bi = k == 0 ? node : b, ji = k == 3 ? node : j, si = k == 1 ? node : 0, ti = k == 2 ? node : 0;
            double val = v[index(p, si, ti, bi, ji, sigmas.size(), thetas.size(), betas.size(), phis.size())];
            if (normalize_) {
              const double e = node_energy[node][static_cast<std::size_t>(p)];
              val = e > 1e-300 ? val / e : 0.0;
            }
            vals[m] = val;
          }
          double est = 0.0;
          if (a.interpolation == Interpolation::geometric && taps[q].n == 2 && vals[0] > 0.0 && vals[1] > 0.0)
            est = std::exp(taps[q].w[0] * std::log(vals[0]) + taps[q].w[1] * std::log(vals[1]));
          else
            for (int m = 0; m < taps[q].n; ++m) est += taps[q].w[m] * vals[m];
          if (normalize_) est *= sl.energy[static_cast<std::size_t>(p)];
          est = std::max(est, 0.0);
          worst = std::max(worst, std::abs(est - sl.truth[static_cast<std::size_t>(p)][b][j]) / sl.scale[static_cast<std::size_t>(p)][b]);
        }
  }
  return worst;
}

ResolutionPlan plan_np_resolution(const std::vector<GridAxis>& axes, double eta, AbsorptionPath path, int lobes, double target,
                                  std::size_t max_entries, bool normalize_energy) {
  if (!(target > 0.0 && target < 0.5)) throw_domain_error("tables.np.target_error", "must lie in (0, 0.5)", target);
  const AxisErrorProbe probe(axes, eta, path, lobes, 24, normalize_energy);
  auto axis_error = [&](std::size_t k, int count) { return probe.error(k, count); };
  ResolutionPlan plan;
  plan.axes = axes;
  plan.entries = 1;
  plan.predicted_error = 0.0;
  // Each axis gets an equal share of the target (second-order interpolation on every axis makes
  // the Lagrange shares equal). Its count doubles from 8 until the measured error is within the
  // share, then is interpolated in log–log between the last two counts (error ∝ n^−s locally);
  // an axis within its share at 8 nodes halves its count while it stays within.
  const double share = target / 4.0;
  for (std::size_t k = 0; k < 4; ++k) {
    GridAxis& a = plan.axes[k];
    if (a.spacing != Spacing::explicit_values) {
      int lo = 8;
      double e_lo = axis_error(k, lo);
      int n = lo;
      double e = e_lo;
      while (e > share && n < (1 << 14)) {
        lo = n, e_lo = e;
        n *= 2;
        e = axis_error(k, n);
      }
      // Already within the share at 8 nodes (a narrow range, e.g. one β band): halve while it stays so.
      while (n == lo && n > 2 && e <= share) {
        const double half = axis_error(k, n / 2);
        if (half > share) break;
        n /= 2, lo = n, e = e_lo = half;
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
