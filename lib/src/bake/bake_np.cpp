// The generic N_p tables: N_p (or its shape N_p / E_p) of every explicit lobe over (β, σa, θd, φ),
// lobe energies and the residual over (σa, θd), and the grid baker every N_p table shares
// (bake_np_grid). Their layout (the axes target_error chooses, the folded lobes) is np_plan.cpp's.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>

#include "bake_internal.hpp"
#include "bake_stages.hpp"
#include "hairlut/bake/resolution.hpp"
#include "hairlut/bake/beta_bands.hpp"
#include "hairlut/physics/azimuthal_fourier.hpp"
#include "hairlut/physics/azimuthal_np.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/sampler/sampler_fiber.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

using detail::axis_named;
using detail::BakeRun;
using detail::make_table;
using detail::parallel_for;

using json = nlohmann::ordered_json;

// Lobe energies and the residual at every (σa_k, θd_t): out(k, t, energies).
template <class Out>
void bake_energies(const BakeRun& s, LobeSet lobes, const std::vector<double>& sigmas, const std::vector<double>& thetas,
                   const BakeOptions& opt, Out&& out) {
  const BakeConfig& c = *s.config;
  parallel_for(sigmas.size() * thetas.size(), opt, "energies", 1, [&](std::size_t item) {
    const std::size_t k = item / thetas.size(), t = item % thetas.size();
    out(k, t, lobe_energies(AttenuationSlice(c.eta, thetas[t], sigmas[k], c.path), lobes, s.energy_rule));
  });
}

// N_p stored as its shape N_p / E_p when `energy` holds the lobe energies at the (σa, θd) nodes
// (lobe-major), else N_p itself.
double np_shape(const std::vector<double>& energy, int p, std::size_t ns, std::size_t nt, std::size_t is, std::size_t it, double v) {
  if (energy.empty()) return v;
  const double e = energy[(static_cast<std::size_t>(p) * ns + is) * nt + it];
  return e > 1e-300 ? v / e : 0.0;  // a lobe absorbed to nothing has no shape
}

// Producer of lobe p's generic N_p rows (β indices) for slab-by-slab baking: the whole-grid
// request restricted to the rows asked for, so every entry gets the same method and rules as in
// the whole bake (bit-identical values).
std::function<void(std::size_t, std::size_t, Table&)> np_rows(NpGridRequest request, int p, std::shared_ptr<const std::vector<double>> energy,
                                                               BakeOptions opt) {
  return [request = std::move(request), p, energy = std::move(energy), opt = std::move(opt)](std::size_t row0, std::size_t rows, Table& out) mutable {
    const std::size_t ns = request.sigmas.size(), nt = request.thetas.size(), nphi = request.phis.size();
    request.only = NpGridRequest::Subset{p, row0, row0 + rows};
    bake_np_grid(request, opt, "N_p slab", [&](int, std::size_t is, std::size_t it, std::size_t ib, std::size_t ip, double v) {
      out.set((((ib - row0) * ns + is) * nt + it) * nphi + ip, np_shape(*energy, p, ns, nt, is, it, v));
    });
  };
}


}  // namespace

std::vector<GridAxis> restricted_np_axes(const BakeConfig& c, std::vector<std::string>* notes) {
  std::vector<GridAxis> axes = *c.np_axes;
  if (!c.scene || c.scene->mode != SceneConfig::Mode::restrict_generic) return axes;
  double s_lo = INFINITY, s_hi = -INFINITY, b_lo = INFINITY, b_hi = -INFINITY;
  for (const MaterialConfig& m : c.scene->materials) {
    for (double s : m.sigma_a) s_lo = std::min(s_lo, s), s_hi = std::max(s_hi, s);
    for (double b : m.beta_n) b_lo = std::min(b_lo, b), b_hi = std::max(b_hi, b);
  }
  auto restrict_axis = [&](GridAxis& a, double lo, double hi, const char* what) {
    a.values.clear();
    if (a.spacing == Spacing::explicit_values) a.spacing = Spacing::uniform;
    if (a.spacing == Spacing::log && !(lo > 0.0)) a.spacing = Spacing::sqrt;
    if (hi - lo <= 1e-12 * std::max(1.0, hi)) {
      a.count = 1;
      a.placement = Placement::edges;
      a.lo = a.hi = lo;
    } else {
      a.count = std::max(a.count, 2);
      a.lo = lo;
      a.hi = hi;
    }
    if (notes) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "scene restricts %s to [%.6g, %.6g] with %d nodes (%s spacing)", what, a.lo, a.hi,
                    a.count, std::string(to_string(a.spacing)).c_str());
      notes->push_back(buf);
    }
    a.validate("scene-restricted axis " + a.name);
  };
  for (GridAxis& a : axes) {
    if (a.name == "sigma_a") restrict_axis(a, s_lo, s_hi, "sigma_a");
    if (a.name == "beta") restrict_axis(a, b_lo, b_hi, "beta");
  }
  return axes;
}

// N_p of lobes p = 0 … lobes − 1 at every (σa_k, θd_t) pair for the lobe's β list and all φ,
// written through out(p, k, t, b, j, value). The Fourier method works per (θd, p) for all σa at
// once; the per-entry methods per (σa, θd). Either way each work item writes its own entries.
std::size_t bake_np_grid(const NpGridRequest& r, const BakeOptions& opt, const std::string& stage, const NpGridOutput& out) {
  const NpQuadratureConfig& q = r.quadrature;
  const auto& sigmas = r.sigmas;
  const auto& thetas = r.thetas;
  const auto& phis = r.phis;
  const auto& betas_of = r.betas_of;
  std::size_t unconverged = 0;
  const std::size_t ns = sigmas.size(), nt = thetas.size(), nphi = phis.size();
  std::mutex mutex;
  // Entries this call evaluates (all of them unless r.only restricts to one lobe's β range).
  auto wanted_lobe = [&](int p) { return !r.only || r.only->p == p; };
  auto wanted = [&](int p, std::size_t b) { return !r.only || (r.only->p == p && b >= r.only->b0 && b < r.only->b1); };
  if (q.method == NpQuadratureConfig::Method::fourier) {
    // Per (θd, lobe): the β list splits into the narrowest detectors, evaluated by spreading
    // Gaussians onto the periodic φ grid, and the rest, evaluated from Fourier coefficients,
    // where the split point minimizes the estimated work. Both are the same quadrature and meet
    // the tolerance; choices and rules are fixed before the parallel loop (deterministic).
    const PeriodicGrid grid = PeriodicGrid::of(phis);
    const std::size_t L = static_cast<std::size_t>(r.lobes);
    struct Plan {
      std::vector<std::size_t> spread, fourier;  // β indices
      int terms = 0;
    };
    std::vector<Plan> plans(nt * L);
    std::vector<int> spread_m(nt, 0), fourier_m(nt, 0);
    int max_terms = 0;
    for (std::size_t t = 0; t < nt; ++t) {
      const FiberGeometry g = FiberGeometry::make(r.eta, thetas[t]);
      for (int p = 0; p < r.lobes; ++p) {
        const auto betas = betas_of(p);
        std::vector<std::size_t> order(betas.size());
        for (std::size_t b = 0; b < order.size(); ++b) order[b] = b;
        std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return betas[x] < betas[y]; });
        std::size_t best_split = 0;
        double best_cost = INFINITY;
        for (std::size_t split = 0; split <= order.size(); ++split) {
          double cost = 0.0;
          for (std::size_t i = 0; i < split; ++i)
            cost += spread_cost(betas[order[i]], spread_nodes(betas[order[i]], p, g, q.tolerance), ns, grid, q.tolerance);
          if (split < order.size()) {
            const int N = fourier_terms(betas[order[split]], q.tolerance);
            cost += fourier_cost(N, fourier_nodes(N, p, g, q.tolerance), ns, order.size() - split, nphi);
          }
          if (cost < best_cost) best_cost = cost, best_split = split;
        }
        Plan& plan = plans[t * L + static_cast<std::size_t>(p)];
        plan.spread.assign(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(best_split));
        plan.fourier.assign(order.begin() + static_cast<std::ptrdiff_t>(best_split), order.end());
        for (std::size_t b : plan.spread) spread_m[t] = std::max(spread_m[t], spread_nodes(betas[b], p, g, q.tolerance));
        if (!plan.fourier.empty()) {
          plan.terms = fourier_terms(betas[plan.fourier.front()], q.tolerance);
          fourier_m[t] = std::max(fourier_m[t], fourier_nodes(plan.terms, p, g, q.tolerance));
          max_terms = std::max(max_terms, plan.terms);
        }
      }
    }
    const auto cache = r.rules ? r.rules : std::make_shared<GaussLegendreCache>();
    std::map<int, const GaussLegendreRule*> rules;
    for (std::size_t t = 0; t < nt; ++t)
      for (int m : {spread_m[t], fourier_m[t]})
        if (m > 0 && !rules.count(m)) rules[m] = &cache->get(m);
    const CosineSeries series(phis, max_terms);
    parallel_for(nt, opt, stage, ns * nphi * L, [&](std::size_t t) {
      const FiberGeometry g = FiberGeometry::make(r.eta, thetas[t]);
      std::optional<FiberNodes> spread_nodes_t, fourier_nodes_t;
      if (spread_m[t] > 0) spread_nodes_t = FiberNodes::make(g, r.path, *rules.at(spread_m[t]));
      if (fourier_m[t] > 0) fourier_nodes_t = FiberNodes::make(g, r.path, *rules.at(fourier_m[t]));
      std::vector<double> C, v, row(nphi);
      // Every spread (lobe, β) of this θd in one pass over the nodes.
      std::vector<SpreadLobe> spread_lobes;
      std::vector<std::pair<int, std::size_t>> spread_index;
      for (int p = 0; p < r.lobes; ++p) {
        const auto betas = betas_of(p);
        for (std::size_t b : plans[t * L + static_cast<std::size_t>(p)].spread) {
          if (!wanted(p, b)) continue;
          spread_lobes.push_back({p, betas[b]});
          spread_index.emplace_back(p, b);
        }
      }
      if (!spread_lobes.empty()) {
        std::vector<std::vector<double>> spread;
        spread_np(*spread_nodes_t, g, spread_lobes, sigmas, grid, q.tolerance, spread);
        for (std::size_t l = 0; l < spread.size(); ++l)
          for (std::size_t k = 0; k < ns; ++k)
            for (std::size_t j = 0; j < nphi; ++j) out(spread_index[l].first, k, t, spread_index[l].second, j, spread[l][k * nphi + j]);
      }
      for (int p = 0; p < r.lobes; ++p) {
        const Plan& plan = plans[t * L + static_cast<std::size_t>(p)];
        const auto betas = betas_of(p);
        if (plan.fourier.empty() || !wanted_lobe(p) ||
            std::none_of(plan.fourier.begin(), plan.fourier.end(), [&](std::size_t b) { return wanted(p, b); }))
          continue;
        const int N = plan.terms;
        fourier_coefficients(*fourier_nodes_t, g, p, sigmas, N, C);
        for (std::size_t b : plan.fourier) {
          if (!wanted(p, b)) continue;
          const int Nb = std::min(N, fourier_terms(betas[b], q.tolerance));
          // Weights (2 − δ_n0) e^{−n²β²/2} / 2π of the detector's Fourier series.
          std::vector<double> weight(static_cast<std::size_t>(Nb) + 1);
          for (int n = 0; n <= Nb; ++n)
            weight[static_cast<std::size_t>(n)] = (n ? 2.0 : 1.0) * std::exp(-0.5 * static_cast<double>(n) * n * betas[b] * betas[b]) / kTwoPi;
          v.resize(weight.size());
          for (std::size_t k = 0; k < ns; ++k) {
            for (std::size_t n = 0; n < weight.size(); ++n) v[n] = weight[n] * C[n * ns + k];
            series.evaluate(v, row);
            for (std::size_t j = 0; j < nphi; ++j) out(p, k, t, b, j, std::max(0.0, row[j]));  // roundoff below 0 clamped
          }
        }
      }
    });
    return 0;
  }
  const GaussLegendreRule rule(q.method == NpQuadratureConfig::Method::gauss_legendre ? q.order : 1);
  parallel_for(ns * nt, opt, stage, nphi * static_cast<std::size_t>(r.lobes), [&](std::size_t item) {
    const std::size_t k = item / nt, t = item % nt;
    const AttenuationSlice slice(r.eta, thetas[t], sigmas[k], r.path);
    std::size_t local_unconverged = 0;
    for (int p = 0; p < r.lobes; ++p) {
      if (!wanted_lobe(p)) continue;
      const auto betas = betas_of(p);
      if (q.method == NpQuadratureConfig::Method::gauss_legendre) {
        const NpQuadratureSlab slab(slice, p, rule, q.variable);
        for (std::size_t b = 0; b < betas.size(); ++b)
          if (wanted(p, b))
            for (std::size_t j = 0; j < nphi; ++j) out(p, k, t, b, j, slab(betas[b], phis[j]));
      } else {
        for (std::size_t b = 0; b < betas.size(); ++b)
          for (std::size_t j = 0; j < nphi && wanted(p, b); ++j) {
            const AdaptiveResult ar = azimuthal_np_reference(slice, p, betas[b], phis[j], q.tolerance);
            if (!ar.converged) ++local_unconverged;
            out(p, k, t, b, j, ar.value[0]);
          }
      }
    }
    if (local_unconverged) {
      std::lock_guard<std::mutex> lock(mutex);
      unconverged += local_unconverged;
    }
  });
  return unconverged;
}

namespace detail {

// Whether a θd axis's range ends at 90°, where the energies of the lobes p ≥ 1 and of the residual
// vanish (Fresnel transmission 1 − F ~ cos θd at grazing): its last node there, or, texel-centred,
// half a cell short of it, beyond which a lookup holds the last stored value and the factor
// multiplied back still gives the limit.
bool reaches_grazing(const GridAxis& theta_d) {
  return theta_d.count > 0 && theta_d.spacing != Spacing::explicit_values && std::abs(theta_d.hi - 0.5 * kPi) <= 1e-12;
}

// The factor g(σa, θd) by which an energy table reaching 90° divides its values, so that what it
// stores has a finite, non-zero limit there (docs/table-format.md, "Energies at grazing"). At
// grazing 1 − F ≈ k u cos γi with u = cos θd, k = 2 (1 + η²) / √(η² − 1), and each internal segment
// transmits T∞ = exp(−τ σa), τ = 2 / cos θt∞ (chord; 4 / cos θt∞ for the papers' path),
// cos θt∞ = √(1 − 1/η²). So E_R → 1 (none); E_p ≈ (2/3) k² T∞^p u² for p ≥ 1 (n = 2); the
// residual (1 − f)² f^{P−1} T^P / (1 − f T) ≈ k u T∞^{P−1} J(a), a = x / u, x = expm1(τ σa) / k,
// J(a) = ∫ cos³γ / (a + cos γ) dγ over [0, π/2], which goes from π/4 (σa = 0: E ~ u) to 2/(3a)
// (σa > 0: E ~ u²) over σa of the order of u. J(a) ≈ (π/4)(1 + b a + e a²) / (1 + c a + d a² + f a³)
// with c = b + 4/π (J's slope −1 at 0) and f = 3πe/8 (its 2/(3a) tail), b, e and d fitted for the
// least largest relative error over a ∈ [0, ∞) (Gauss–Legendre J on 4000 points of a / (1 + a)):
// within 2.25e-5 for every a ≥ 0 (the three-constant form (1 + b a) / (1 + c a + d a²) reaches only
// 4.5e-4, which set the residual tables' error near the corner). So g = u (1 + b a + e a²) /
// (1 + c a + d a² + f a³) leaves the residual a stored value within 2.25e-5 of (π/4) k T∞^{P−1}
// near the corner (σa, θd) → (0, 90°), where E / u alone is a step in σa / u.
sampler::GrazingFactor grazing_factor_of(const BakeConfig& c, const GridAxis& theta_d, int p, bool residual) {
  sampler::GrazingFactor g;
  if (!reaches_grazing(theta_d) || !(c.eta > 1.0) || p == 0) return g;
  g.cos_power = residual ? 1 : 2;
  if (residual) {
    const double k = 2.0 * (1.0 + c.eta * c.eta) / std::sqrt(c.eta * c.eta - 1.0), cos_t = std::sqrt(1.0 - 1.0 / (c.eta * c.eta));
    g.x_scale = 1.0 / k;
    g.tau = (c.path == AbsorptionPath::chord ? 2.0 : 4.0) / cos_t;
    g.b = 7.18516478, g.e = 8.79721254, g.d = 17.6233951;
    g.c = g.b + 4.0 / kPi;
    g.f = 3.0 * kPi * g.e / 8.0;
  }
  return g;
}

namespace {

// A value over g at a node: θd = 90° is evaluated as the double nearest π/2 (below it), where cos θd = 6.1e-17
// and the physics gives the limit ratio to rounding.
// (g underflows only where the energy has: such a node stores 0.)
double divided_by_factor(const Table& t, double value, double sigma_a, double theta_d) {
  const double g = t.grazing_factor()(sigma_a, std::min(theta_d, 0.5 * kPi));
  return g > 0.0 ? value / g : 0.0;
}

// The energy and residual tables over `axes` (σa, θd), without values.
void append_energy_tables(const BakeRun& s, const std::vector<GridAxis>& axes, TableSet& set) {
  const BakeConfig& c = *s.config;
  const LobeSet lobe_set{s.lobes, c.residual};
  for (int p = 0; p < lobe_set.size(); ++p) {
    const bool res = p == s.lobes;
    const std::string lobe = res ? "residual" : lobe_name(p);
    const sampler::GrazingFactor g = grazing_factor_of(c, axes[1], p, res);
    Table t = make_table("np", "energy_" + lobe, "energy", "1",
                         "energy 1/2 int A dh = int N_p dphi of lobe " + lobe + (res ? " (all p >= " + std::to_string(p) + ")" : "") +
                             (g.none() ? "" : " divided by its grazing factor"),
                         axes, s.precision);
    t.attributes = {{"lobe", lobe}, {"p", p}};
    t.set_grazing_factor(g);
    set.tables.push_back(std::move(t));
  }
  if (c.residual) {
    const sampler::GrazingFactor g = grazing_factor_of(c, axes[1], s.lobes, true);
    Table t = make_table("np", "residual", "N_p", "1/rad",
                         "residual lobes p >= " + std::to_string(s.lobes) + " spread uniformly in phi: energy/(2 pi)" +
                             (g.none() ? "" : ", divided by its grazing factor"),
                         axes, s.precision);
    t.attributes = {{"lobe", "residual"}, {"p_from", s.lobes}, {"uniform_in", json::array({"phi", "beta"})}};
    t.set_grazing_factor(g);
    set.tables.push_back(std::move(t));
  }
}

// The values of the energy and residual tables that start at set.tables[first].
void bake_energy_values(const BakeRun& s, std::size_t first, TableSet& set, BakeReport& report) {
  const BakeConfig& c = *s.config;
  const LobeSet lobe_set{s.lobes, c.residual};
  const std::vector<GridAxis>& axes = set.tables[first].axes;
  const std::vector<double> sigmas = axes[0].nodes(), thetas = axes[1].nodes();
  const std::size_t nt = thetas.size(), residual_index = first + static_cast<std::size_t>(lobe_set.size());
  bake_energies(s, lobe_set, sigmas, thetas, s.options, [&](std::size_t is, std::size_t it, const std::vector<double>& e) {
    for (std::size_t p = 0; p < e.size(); ++p) {
      Table& t = set.tables[first + p];
      t.set(is * nt + it, divided_by_factor(t, e[p], sigmas[is], thetas[it]));
    }
    if (c.residual) {
      Table& t = set.tables[residual_index];
      t.set(is * nt + it, divided_by_factor(t, e.back() / kTwoPi, sigmas[is], thetas[it]));
    }
  });
  report.entries += static_cast<std::size_t>(lobe_set.size()) * sigmas.size() * nt;
}

}  // namespace

void bake_energy_tables(const BakeRun& run, const std::vector<GridAxis>& axes, TableSet& set, BakeReport& report) {
  const std::size_t first = set.tables.size();
  append_energy_tables(run, axes, set);
  bake_energy_values(run, first, set, report);
}

void bake_generic_np(BakeRun& run, const NpPlan& plan, TableSet& set, BakeReport& report) {
  const BakeConfig& c = *run.config;
  const BakeOptions& opt = run.options;
  const Precision precision = run.precision;
  SlabbedTables* const slabbed = run.slabbed;
  const BakeRun& s = run;
  const std::vector<GridAxis>& np_axes = plan.axes;
  const bool normalize_energy = plan.normalize_energy;
  const std::optional<std::vector<GridAxis>>& energy_axes = plan.energy_axes;
  const std::shared_ptr<GaussLegendreCache>& rules = run.rules;
  std::size_t& unconverged = run.unconverged;
  const std::vector<double> betas = axis_named(np_axes, "beta").nodes(), sigmas = axis_named(np_axes, "sigma_a").nodes(),
                            thetas = axis_named(np_axes, "theta_d").nodes(), phis = axis_named(np_axes, "phi").nodes();
  // The energy and residual tables live on their own (σa, θd) axes when the config gives them
  // (they are small, so they may be denser than N_p's).
  std::vector<GridAxis> st_axes = {axis_named(np_axes, "sigma_a"), axis_named(np_axes, "theta_d")};
  if (energy_axes) st_axes = *energy_axes;
  const std::size_t first = set.tables.size();
  for (int p = 0; p < s.lobes; ++p) {
    const std::string lobe = lobe_name(p);
    Table t = make_table("np", lobe, "N_p", "1/rad",
                         normalize_energy ? "shape N_p / E_p of lobe " + lobe + " (N_p = this x np/energy_" + lobe + ")"
                                               : "azimuthal scattering function N_p of lobe " + lobe,
                         np_axes, precision, !slabbed);
    t.attributes = {{"lobe", lobe}, {"p", p}};
    if (normalize_energy) t.attributes["factor"] = "np/energy_" + lobe;
    set.tables.push_back(std::move(t));
  }
  // normalize "energy": every N_p value is divided by its lobe's energy at the same (σa, θd)
  // node (the shape integrates to 1 over φ and changes slowly where the energy falls fast).
  const std::size_t ns = sigmas.size(), nt = thetas.size();
  std::vector<double> node_energy;
  if (normalize_energy) {
    node_energy.assign(static_cast<std::size_t>(s.lobes) * ns * nt, 0.0);
    bake_energies(s, LobeSet{s.lobes, false}, sigmas, thetas, opt, [&](std::size_t is, std::size_t it, const std::vector<double>& e) {
      for (int p = 0; p < s.lobes; ++p) node_energy[(static_cast<std::size_t>(p) * ns + is) * nt + it] = e[static_cast<std::size_t>(p)];
    });
  }
  // The energy and residual tables follow the N_p tables in the set (their values are baked below).
  const std::size_t energy_first = set.tables.size();
  append_energy_tables(run, st_axes, set);
  const std::size_t nb = betas.size(), nphi = phis.size();
  if (c.quadrature.method == NpQuadratureConfig::Method::fourier && !PeriodicGrid::why_not(phis).empty())
    report.notes.push_back("N_p: " + PeriodicGrid::why_not(phis));
  if (slabbed) {
    const auto energy = std::make_shared<const std::vector<double>>(std::move(node_energy));
    for (int p = 0; p < s.lobes; ++p)
      slabbed->tables.push_back({first + static_cast<std::size_t>(p),
                                 np_rows({c.eta, c.path, c.quadrature, s.lobes, sigmas, thetas, phis, [betas](int) { return betas; }, rules, {}},
                                         p, energy, opt)});
  } else {
    unconverged += bake_np_grid({c.eta, c.path, c.quadrature, s.lobes, sigmas, thetas, phis, [&](int) { return betas; }, rules, {}}, opt, "N_p",
                                [&](int p, std::size_t is, std::size_t it, std::size_t ib, std::size_t ip, double v) {
                                  set.tables[first + static_cast<std::size_t>(p)].set(((ib * ns + is) * nt + it) * nphi + ip,
                                                                                      np_shape(node_energy, p, ns, nt, is, it, v));
                                });
  }
  report.entries += nb * nphi * static_cast<std::size_t>(s.lobes) * ns * nt;
  bake_energy_values(run, energy_first, set, report);
  // β bands 1 … n − 1 (beta_bands.cpp); the tables above are band 0.
  if (!plan.bands.empty()) append_beta_band_tables(c, plan.bands, s.lobes, normalize_energy, precision, opt, set, report);
}

}  // namespace detail
}  // namespace hairlut
