#include "hairlut/bake/resolution.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include "hairlut/util/angles.hpp"
#include "hairlut/physics/azimuthal_fourier.hpp"
#include "hairlut/bake/bake.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/bake/sampled_error.hpp"
#include "hairlut/bake/table_truth.hpp"
#include "hairlut/tables/fourier_tables.hpp"

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
    : AxisErrorProbe(std::move(axes), eta, path, lobes, probes, normalize_energy ? Nodes::shape : Nodes::n_p) {}

AxisErrorProbe::AxisErrorProbe(std::vector<GridAxis> axes, double eta, AbsorptionPath path, int lobes, int probes, Nodes nodes)
    : axes_(std::move(axes)), eta_(eta), path_(path), lobes_(std::min(lobes, 4)), nodes_(nodes),
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
    if (nodes_ != Nodes::n_p) sl.energy = divisors(sl.sigma, sl.theta);
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

std::vector<double> AxisErrorProbe::divisors(double sigma, double theta) const {
  const AttenuationSlice slice(eta_, theta, sigma, path_);
  if (nodes_ == Nodes::shape) return lobe_energies(slice, LobeSet{lobes_, false}, *energy_rule_);
  std::vector<double> f;
  for (int p = 0; p < lobes_; ++p) f.push_back(least_absorption(slice, p));
  return f;
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
    // Divisors at the nodes (a shape table interpolates N_p / E_p, the Fourier coefficients N_p / F;
    // then multiplied by E_p or F at the point here).
    const bool normalize = nodes_ != Nodes::n_p;
    std::vector<std::vector<double>> node_energy;
    if (normalize)
      for (double x : nodes) node_energy.push_back(k == 1 ? divisors(x, sl.theta) : k == 2 ? divisors(sl.sigma, x) : sl.energy);
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
            if (normalize) {
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
          if (normalize) est *= sl.energy[static_cast<std::size_t>(p)];
          est = std::max(est, 0.0);
          worst = std::max(worst, std::abs(est - sl.truth[static_cast<std::size_t>(p)][b][j]) / sl.scale[static_cast<std::size_t>(p)][b]);
        }
  }
  return worst;
}

namespace {

// The count of axis `a` for an error share: doubled from 8 until the measured error is within the
// share, then interpolated in log–log between the last two counts (error ∝ n^−s locally); an axis
// within its share at 8 nodes halves its count while it stays within. The axis's own count is a
// lower bound. Returns the error at the chosen count; records the local slope.
double choose_count(GridAxis& a, const std::function<double(int)>& axis_error, double share, std::map<std::string, double>& slopes) {
  int lo = 8;
  double e_lo = axis_error(lo);
  int n = lo;
  double e = e_lo;
  while (e > share && n < (1 << 14)) {
    lo = n, e_lo = e;
    n *= 2;
    e = axis_error(n);
  }
  // Already within the share at 8 nodes (a narrow range, e.g. one β band): halve while it stays so.
  while (n == lo && n > 2 && e <= share) {
    const double half = axis_error(n / 2);
    if (half > share) break;
    n /= 2, lo = n, e = e_lo = half;
  }
  int need = n;
  if (n > lo && e < share && e_lo > share && e > 0.0) {
    const double slope = std::log(e_lo / e) / std::log(static_cast<double>(n) / lo);
    slopes[a.name] = slope;
    need = std::min(n, static_cast<int>(std::ceil(lo * std::pow(e_lo / share, 1.0 / std::max(slope, 0.5)))));
    e = axis_error(need);
    if (e > share) need = n, e = axis_error(n);
  }
  a.count = std::max(a.count, std::max(need, 2));
  return a.count == need ? e : axis_error(a.count);
}

}  // namespace

ResolutionPlan plan_np_resolution(const std::vector<GridAxis>& axes, double eta, AbsorptionPath path, int lobes, double target,
                                  std::size_t max_entries, bool normalize_energy) {
  if (!(target > 0.0 && target < 0.5)) throw_domain_error("tables.np.target_error", "must lie in (0, 0.5)", target);
  const AxisErrorProbe probe(axes, eta, path, lobes, 24, normalize_energy);
  ResolutionPlan plan;
  plan.axes = axes;
  plan.entries = 1;
  plan.predicted_error = 0.0;
  // Each axis gets an equal share of the target (second-order interpolation on every axis makes
  // the Lagrange shares equal).
  const double share = target / 4.0;
  for (std::size_t k = 0; k < 4; ++k) {
    GridAxis& a = plan.axes[k];
    if (a.spacing != Spacing::explicit_values)
      plan.axis_error[a.name] = choose_count(a, [&](int count) { return probe.error(k, count); }, share, plan.slope);
    else
      plan.axis_error[a.name] = 0.0;
    plan.predicted_error += plan.axis_error[a.name];
    plan.entries *= static_cast<std::size_t>(a.count);
    if (plan.entries > max_entries)
      throw DomainError("tables.np.target_error " + std::to_string(target) + " needs more than " + std::to_string(max_entries) +
                        " entries per lobe over these ranges; raise the target or narrow the ranges");
    a.validate("tables.np.axes." + a.name);
  }
  return plan;
}

// Probe slabs of the Fourier plan: its axis errors are those of the narrowest detectors on the
// caustics, which few random slabs miss (and a Fourier table is cheap to probe: two axes).
constexpr int kFourierProbes = 96;

FourierResolutionPlan plan_fourier_resolution(const FourierNpConfig& bounds, double eta, AbsorptionPath path, int lobes, double target,
                                              std::size_t max_entries) {
  if (!(target > 0.0 && target < 0.5)) throw_domain_error("tables.np.target_error", "must lie in (0, 0.5)", target);
  FourierResolutionPlan plan;
  plan.config = bounds;
  FourierNpConfig& f = plan.config;
  // The truncation takes a tenth of the target (its bound, relative to the lobe's mean height);
  // θd and σa share the rest (β and φ are exact).
  f.tolerance = std::min(0.1, 0.1 * target);
  const double share = 0.45 * target;
  GridAxis beta, phi;
  beta.name = "beta", beta.units = "rad", beta.spacing = f.beta_hi > f.beta_lo ? Spacing::log : Spacing::uniform;
  beta.lo = f.beta_lo, beta.hi = f.beta_hi, beta.count = f.beta_hi > f.beta_lo ? 2 : 1;
  phi.name = "phi", phi.units = "rad", phi.wrap = Wrap::even, phi.lo = 0.0, phi.hi = kPi, phi.count = 2;
  GridAxis& theta = f.axes[0];
  GridAxis& sigma = f.axes[1];
  const AxisErrorProbe probe({beta, sigma, theta, phi}, eta, path, lobes, kFourierProbes, AxisErrorProbe::Nodes::over_least_absorption);
  std::map<std::string, double> slopes;
  plan.axis_error["theta_d"] = choose_count(theta, [&](int count) { return probe.error(2, count); }, share, slopes);
  plan.axis_error["sigma_a"] = sigma.count > 1 || sigma.lo < sigma.hi ? choose_count(sigma, [&](int count) { return probe.error(1, count); }, share, slopes)
                                                                      : 0.0;
  plan.terms = (fourier_terms(f.beta_lo, f.tolerance) + 4) / 4 * 4;
  plan.entries = static_cast<std::size_t>(plan.terms) * static_cast<std::size_t>(theta.count) * static_cast<std::size_t>(sigma.count);
  plan.predicted_error = plan.axis_error["theta_d"] + plan.axis_error["sigma_a"] + f.tolerance;
  if (plan.entries > max_entries)
    throw DomainError("tables.np.target_error " + std::to_string(target) + " needs more than " + std::to_string(max_entries) +
                      " Fourier coefficients per lobe over these ranges; raise the target or narrow the ranges");
  theta.validate("tables.np.axes.theta_d");
  sigma.validate("tables.np.axes.sigma_a");
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
    const bool fourier = is_fourier_table(t);
    if ((t.group != "np" || t.quantity != "N_p") && !fourier) continue;
    if (t.attributes.value("lobe", std::string()) == "residual") continue;
    // A Fourier table is measured over the (β, σa, θd, φ) it defines, read through its evaluator.
    const Table domain = fourier ? fourier_domain_table(t) : Table();
    const auto truth = table_truth(fourier ? domain : t, model, rule);
    if (!truth) continue;
    SampledErrorOptions o;
    o.points = samples;
    // Points the plan never saw: the planner probes its own fixed slabs (AxisErrorProbe); these
    // come from another seed, then the worst-point search (edges, corners, caustics, grazing θd,
    // local maximisation). Fixed per table so that a config bakes the same bytes every time.
    o.seed = sampled_error_seed("target_error acceptance: " + t.path());
    o.search = true;
    o.threads = threads;
    const SampledError r = fourier ? measure_sampled_error(domain, fourier_point_function(t), *truth, o) : measure_sampled_error(set, t, *truth, o);
    for (const SearchStage& st : r.stages) a.points += st.points;
    a.per_table[t.path()] = {r.found, r.error.p99};
    if (r.found > a.worst || a.worst_table.empty()) a.worst = std::max(a.worst, r.found), a.worst_table = t.path();
    a.p99 = std::max(a.p99, r.error.p99);
    a.denominator = r.denominator;
  }
  return a;
}

}  // namespace hairlut
