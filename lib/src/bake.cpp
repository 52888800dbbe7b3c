#include "hairlut/bake.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <optional>

#include "hairlut/angles.hpp"
#include "hairlut/azimuthal_fourier.hpp"
#include "hairlut/azimuthal_np.hpp"
#include "hairlut/bake_engine.hpp"
#include "hairlut/beta_bands.hpp"
#include "hairlut/error.hpp"
#include "hairlut/hair_model.hpp"
#include "hairlut/lobe_energy.hpp"
#include "hairlut/longitudinal_mp.hpp"
#include "hairlut/material_np.hpp"
#include "hairlut/melanin.hpp"
#include "hairlut/resolution.hpp"
#include "hairlut/version.hpp"
#include "bake_internal.hpp"

namespace hairlut {
namespace {

using detail::axis_named;
using detail::make_table;
using detail::parallel_for;

using json = nlohmann::ordered_json;

// Everything the N_p bake of one (σa, θd) pair needs from the config.
struct NpSettings {
  const BakeConfig* config;
  int lobes;  // explicit lobes after folding
  GaussLegendreRule energy_rule;
};

// Lobe energies and the residual at every (σa_k, θd_t): out(k, t, energies).
template <class Out>
void bake_energies(const NpSettings& s, LobeSet lobes, const std::vector<double>& sigmas, const std::vector<double>& thetas,
                   const BakeOptions& opt, Out&& out) {
  const BakeConfig& c = *s.config;
  parallel_for(sigmas.size() * thetas.size(), opt, "energies", 1, [&](std::size_t item) {
    const std::size_t k = item / thetas.size(), t = item % thetas.size();
    out(k, t, lobe_energies(AttenuationSlice(c.eta, thetas[t], sigmas[k], c.path), lobes, s.energy_rule));
  });
}

json quadrature_json(const NpQuadratureConfig& q) {
  return {{"method", to_string(q.method)},
          {"order", q.order},
          {"variable", to_string(q.variable)},
          {"tolerance", q.tolerance},
          {"energy_order", q.energy_order},
          {"energy_method", "gauss-legendre in gamma over [0, pi/2]"}};
}

// Largest energy of each explicit lobe over the σa values and θd nodes that will be baked.
std::vector<double> max_lobe_energies(const BakeConfig& c, const std::vector<double>& sigmas, const std::vector<double>& thetas,
                                      const GaussLegendreRule& rule) {
  std::vector<double> best(static_cast<std::size_t>(c.lobe_count), 0.0);
  for (double s : sigmas)
    for (double t : thetas) {
      const auto e = lobe_energies(AttenuationSlice(c.eta, t, s, c.path), {c.lobe_count, false}, rule);
      for (std::size_t p = 0; p < e.size(); ++p) best[p] = std::max(best[p], e[p]);
    }
  return best;
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

void append_melanin_tables(const BakeConfig& c, Precision precision, TableSet& set, BakeReport& report) {
  if (!c.melanin_axes) return;
  const GridAxis channel = channel_axis({"R", "G", "B"}, "colour channel (linear sRGB primaries)");
  std::vector<GridAxis> axes = *c.melanin_axes;
  axes.push_back(channel);
  const std::vector<double> ce = axes[0].nodes(), cp = axes[1].nodes();
  SpectralMelanin::Options so;
  so.path_length = c.melanin_path_length;
  const SpectralMelanin spectral = SpectralMelanin::builtin(so);
  const SpectralMelanin::Fit fit = spectral.fit_rgb_cross_sections();
  Table deon = make_table("melanin", "sigma_a_deon", "sigma_a", "1/radius",
                          "absorption per unit radius from d'Eon 2011's RGB cross-sections", axes, precision);
  deon.attributes = {{"eumelanin_cross_section", {0.419, 0.697, 1.37}}, {"pheomelanin_cross_section", {0.187, 0.4, 1.05}},
                     {"method", "sigma_a = c_e (0.419, 0.697, 1.37) + c_p (0.187, 0.4, 1.05) (d'Eon 2011 sec. 6.1)"}};
  // The spectral model's colour leaves the sRGB gamut for dark hair (blue T_c ≤ 0), where no RGB
  // absorption reproduces it and −ln T_c has no value: the table stores the transmittance itself,
  // which stays smooth across the gamut boundary, and says how a renderer takes σa from it.
  Table spec = make_table("melanin", "transmittance_spectral", "transmittance", "1",
                          "linear sRGB transmittance over path_length radii from the Donner-Jensen 2006 spectra, CIE 1931 2 deg and D65",
                          axes, precision);
  spec.attributes = {{"path_length", c.melanin_path_length},
                     {"spectral_scale", spectral.options().spectral_scale},
                     {"fitted_eumelanin_cross_section", {fit.eumelanin.r, fit.eumelanin.g, fit.eumelanin.b}},
                     {"fitted_pheomelanin_cross_section", {fit.pheomelanin.r, fit.pheomelanin.g, fit.pheomelanin.b}},
                     {"fit_rms_relative_error", fit.rms_relative_error},
                     {"method", "T_c = linear sRGB (IEC 61966-2-1, white-balanced to D65) of D65 light through exp(-sigma_a(lambda) L), "
                                "380-780 nm in 5 nm steps"},
                     {"out_of_gamut", "T_c <= 0 where the transmitted colour lies outside the sRGB gamut (dark hair's blue); "
                                      "a renderer takes sigma_a_c = -ln(max(T_c, 1e-30)) / path_length"}};
  for (std::size_t i = 0; i < ce.size(); ++i)
    for (std::size_t j = 0; j < cp.size(); ++j) {
      const Rgb a = melanin_sigma_a_rgb(ce[i], cp[j]);
      const Rgb b = spectral.transmittance_unclamped(ce[i], cp[j], c.melanin_path_length);
      const std::size_t o = (i * cp.size() + j) * 3;
      deon.set(o, a.r), deon.set(o + 1, a.g), deon.set(o + 2, a.b);
      spec.set(o, b.r), spec.set(o + 1, b.g), spec.set(o + 2, b.b);
    }
  set.tables.push_back(std::move(deon));
  set.tables.push_back(std::move(spec));
  report.entries += 2 * ce.size() * cp.size() * 3;
}

}  // namespace detail

TableSet bake(const BakeConfig& c, const BakeOptions& opt, BakeReport* report_out, SlabbedTables* slabbed) {
  if (slabbed) {
    // Slab by slab needs every checksummed note before the first slab is written.
    if (c.marschner) throw DomainError("model marschner2003: tables larger than the memory budget cannot be baked slab by slab (raise --memory-budget)");
    if (c.np_target_error)
      throw DomainError("tables.np.target_error: the achieved error is measured on whole tables; tables larger than the memory budget "
                        "cannot use it (raise --memory-budget or give the axes' counts)");
    if (c.np_axes && c.quadrature.method == NpQuadratureConfig::Method::adaptive)
      throw DomainError("tables.np.quadrature.method adaptive: tables larger than the memory budget are baked slab by slab, which needs "
                        "the fourier or gauss-legendre method (or raise --memory-budget)");
  }
  if (c.marschner) return bake_marschner(c, opt, report_out);
  const auto t0 = std::chrono::steady_clock::now();
  BakeReport report;
  TableSet set;
  const Precision precision = c.output.hdf5_double ? Precision::float64 : Precision::float32;
  const bool per_material = c.scene && c.scene->mode == SceneConfig::Mode::per_material;
  const bool generic_np = c.np_axes && !per_material;

  NpSettings s{&c, c.lobe_count, GaussLegendreRule(c.quadrature.energy_order)};
  std::vector<GridAxis> np_axes;
  if (c.np_axes) np_axes = restricted_np_axes(c, &report.notes);
  bool normalize_energy = c.np_normalize_energy;
  std::optional<std::vector<GridAxis>> energy_axes = c.np_energy_axes;
  if (c.np_axes && c.np_target_error && !per_material) {
    // Two representations compete: the axes as configured, and the shape N_p / E_p with cubic
    // interpolation on every axis, σa uniform, and dense energy tables; the smaller table wins.
    std::optional<ResolutionPlan> configured, shape;
    std::string refused;
    try {
      configured = plan_np_resolution(np_axes, c.eta, c.path, c.lobe_count, *c.np_target_error, std::size_t{1} << 31, normalize_energy);
    } catch (const DomainError& e) {
      refused = e.what();
    }
    std::vector<GridAxis> cubic = np_axes;
    for (GridAxis& a : cubic) {
      if (a.spacing == Spacing::explicit_values) continue;
      if (a.name == "sigma_a") a.spacing = Spacing::uniform;
      a.interpolation = Interpolation::cubic;
    }
    try {
      shape = plan_np_resolution(cubic, c.eta, c.path, c.lobe_count, *c.np_target_error, std::size_t{1} << 31, true);
    } catch (const DomainError& e) {
      if (!configured) throw;
      refused = e.what();
    }
    const bool use_shape = shape && (!configured || shape->entries < configured->entries);
    const ResolutionPlan& plan = use_shape ? *shape : *configured;
    if (use_shape && !normalize_energy) {
      normalize_energy = true;
      if (!energy_axes) {
        GridAxis es = axis_named(np_axes, "sigma_a"), et = axis_named(np_axes, "theta_d");
        es.spacing = Spacing::uniform, es.count = std::max(es.count, 128), es.interpolation = Interpolation::geometric;
        et.count = std::max(et.count, 512), et.interpolation = Interpolation::cubic;
        if (es.lo == es.hi) es.count = 1, es.interpolation = Interpolation::linear;
        energy_axes = std::vector<GridAxis>{es, et};
      }
    }
    np_axes = plan.axes;
    report.resolution = {{"target_error", *c.np_target_error}, {"predicted_error", plan.predicted_error}, {"entries_per_lobe", plan.entries},
                         {"representation", use_shape ? "shape N_p / E_p, cubic" : "as configured"}};
    if (configured) report.resolution["entries_as_configured"] = configured->entries;
    if (shape) report.resolution["entries_shape_cubic"] = shape->entries;
    for (const GridAxis& a : np_axes) {
      report.resolution["counts"][a.name] = a.count;
      report.resolution["predicted_axis_error"][a.name] = plan.axis_error.at(a.name);
    }
    report.notes.push_back("target_error " + std::to_string(*c.np_target_error) + ": counts beta " + std::to_string(np_axes[0].count) +
                           ", sigma_a " + std::to_string(np_axes[1].count) + ", theta_d " + std::to_string(np_axes[2].count) + ", phi " +
                           std::to_string(np_axes[3].count) + " (" + std::to_string(plan.entries) + " entries per lobe)");
  }

  // Fold explicit lobes whose largest energy over everything baked stays below the threshold.
  if (c.np_axes && c.fold_below > 0.0) {
    std::vector<double> sigmas;
    if (generic_np) sigmas = axis_named(np_axes, "sigma_a").nodes();
    else
      for (const MaterialConfig& m : c.scene->materials) sigmas.insert(sigmas.end(), m.sigma_a.begin(), m.sigma_a.end());
    const auto best = max_lobe_energies(c, sigmas, axis_named(np_axes, "theta_d").nodes(), s.energy_rule);
    while (s.lobes > 1 && best[static_cast<std::size_t>(s.lobes - 1)] < c.fold_below) {
      report.folded.push_back({lobe_name(s.lobes - 1), best[static_cast<std::size_t>(s.lobes - 1)]});
      --s.lobes;
    }
    std::reverse(report.folded.begin(), report.folded.end());
  }
  report.explicit_lobes = s.lobes;
  const LobeSet lobe_set{s.lobes, c.residual};

  set.metadata["hairlut_version"] = kVersion;
  set.metadata["model"] = c.model;
  set.metadata["name"] = c.name;
  set.metadata["description"] = c.description;
  set.metadata["conventions"] =
      "hairlut conventions (docs/conventions.md): angles in radians; S = sum_p M_p N_p; int M cos(theta_r) dtheta_r = 1; "
      "N_p(phi) = 1/2 int A(p,h) D_beta(phi - Phi(p,h)) dh; sigma_a per unit fiber radius; tilt shifts theta_r";
  set.metadata["eta"] = c.eta;
  set.metadata["absorption_path"] = to_string(c.path);
  set.metadata["lobes"] = json::array();
  for (int p = 0; p < s.lobes; ++p) set.metadata["lobes"].push_back(lobe_name(p));
  set.metadata["residual"] = c.residual;
  set.metadata["residual_from_p"] = s.lobes;
  set.metadata["folded_lobes"] = json::array();
  for (const auto& f : report.folded) set.metadata["folded_lobes"].push_back({{"lobe", f.lobe}, {"max_energy", f.max_energy}});
  set.metadata["quadrature"] = quadrature_json(c.quadrature);
  set.metadata["config_hash"] = c.hash;
  set.metadata["config"] = c.normalized.dump();
  set.metadata["precision"] = precision == Precision::float32 ? "float32" : "float64";

  std::size_t unconverged = 0;
  const auto rules = std::make_shared<GaussLegendreCache>();  // Gauss–Legendre rules shared by the whole bake
  auto residual_name = [&] { return "residual"; };

  // ---- Generic N_p over (β, σa, θd, φ), lobe energies and the residual over (σa, θd).
  if (generic_np) {
    const std::vector<double> betas = axis_named(np_axes, "beta").nodes(), sigmas = axis_named(np_axes, "sigma_a").nodes(),
                              thetas = axis_named(np_axes, "theta_d").nodes(), phis = axis_named(np_axes, "phi").nodes();
    // The energy and residual tables live on their own (σa, θd) axes when the config gives them
    // (they are small, so they may be denser than N_p's).
    std::vector<GridAxis> st_axes = {axis_named(np_axes, "sigma_a"), axis_named(np_axes, "theta_d")};
    if (energy_axes) st_axes = *energy_axes;
    const std::vector<double> energy_sigmas = st_axes[0].nodes(), energy_thetas = st_axes[1].nodes();
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
    const std::size_t energy_first = set.tables.size();
    for (int p = 0; p < lobe_set.size(); ++p) {
      const bool res = p == s.lobes;
      const std::string lobe = res ? residual_name() : lobe_name(p);
      Table t = make_table("np", "energy_" + lobe, "energy", "1",
                           "energy 1/2 int A dh = int N_p dphi of lobe " + lobe + (res ? " (all p >= " + std::to_string(p) + ")" : ""),
                           st_axes, precision);
      t.attributes = {{"lobe", lobe}, {"p", p}};
      set.tables.push_back(std::move(t));
    }
    std::size_t residual_index = 0;
    if (c.residual) {
      Table t = make_table("np", "residual", "N_p", "1/rad",
                           "residual lobes p >= " + std::to_string(s.lobes) + " spread uniformly in phi: energy/(2 pi)",
                           st_axes, precision);
      t.attributes = {{"lobe", "residual"}, {"p_from", s.lobes}, {"uniform_in", json::array({"phi", "beta"})}};
      residual_index = set.tables.size();
      set.tables.push_back(std::move(t));
    }
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
    const std::size_t ent = energy_thetas.size();
    bake_energies(s, lobe_set, energy_sigmas, energy_thetas, opt, [&](std::size_t is, std::size_t it, const std::vector<double>& e) {
      for (std::size_t p = 0; p < e.size(); ++p) set.tables[energy_first + p].set(is * ent + it, e[p]);
      if (c.residual) set.tables[residual_index].set(is * ent + it, e.back() / kTwoPi);
    });
    report.entries += nb * nphi * static_cast<std::size_t>(s.lobes) * ns * nt + static_cast<std::size_t>(lobe_set.size()) * energy_sigmas.size() * ent;
    // β bands 1 … n − 1 (beta_bands.cpp); the tables above are band 0.
    if (!c.np_beta_bands.empty()) append_beta_band_tables(c, s.lobes, normalize_energy, precision, opt, set, report);
  }

  // ---- Per-material RGB tables over (channel, θd, φ).
  if (per_material) {
    const GridAxis theta_axis = axis_named(np_axes, "theta_d"), phi_axis = axis_named(np_axes, "phi");
    const std::vector<double> thetas = theta_axis.nodes(), phis = phi_axis.nodes();
    const GridAxis channel = channel_axis({"R", "G", "B"}, "colour channel (linear sRGB primaries)");
    const std::size_t nt = thetas.size(), nphi = phis.size();
    // Each material's tables and planned N_p, filled by one parallel loop below.
    struct Pending {
      std::size_t first, energy_first, residual_index;
      std::vector<double> sigmas;
      std::unique_ptr<MaterialNp> np;  // null: N_p already baked by bake_np_grid (per-entry methods)
    };
    std::vector<Pending> pending;
    pending.reserve(c.scene->materials.size());
    for (const MaterialConfig& m : c.scene->materials) {
      const std::string group = "materials/" + m.name;
      const std::size_t first = set.tables.size();
      for (int p = 0; p < s.lobes; ++p) {
        Table t = make_table(group, "np_" + lobe_name(p), "N_p", "1/rad",
                             "N_p of lobe " + lobe_name(p) + " for material " + m.name + " (RGB sigma_a)",
                             {channel, theta_axis, phi_axis}, precision);
        t.attributes = {{"lobe", lobe_name(p)}, {"p", p}, {"material", m.name}, {"beta", m.beta_n[static_cast<std::size_t>(p)]},
                        {"sigma_a", m.sigma_a}};
        set.tables.push_back(std::move(t));
      }
      const std::size_t energy_first = set.tables.size();
      for (int p = 0; p < lobe_set.size(); ++p) {
        const std::string lobe = p == s.lobes ? residual_name() : lobe_name(p);
        Table t = make_table(group, "energy_" + lobe, "energy", "1", "energy of lobe " + lobe + " for material " + m.name,
                             {channel, theta_axis}, precision);
        t.attributes = {{"lobe", lobe}, {"p", p}, {"material", m.name}};
        set.tables.push_back(std::move(t));
      }
      std::size_t residual_index = 0;
      if (c.residual) {
        Table t = make_table(group, "np_residual", "N_p", "1/rad",
                             "residual lobes p >= " + std::to_string(s.lobes) + " for material " + m.name + ", uniform in phi",
                             {channel, theta_axis}, precision);
        t.attributes = {{"lobe", "residual"}, {"p_from", s.lobes}, {"material", m.name}};
        residual_index = set.tables.size();
        set.tables.push_back(std::move(t));
      }
      const std::vector<double> channel_sigmas(m.sigma_a.begin(), m.sigma_a.end());
      Pending& item = pending.emplace_back(Pending{first, energy_first, residual_index, channel_sigmas, nullptr});
      if (c.quadrature.method == NpQuadratureConfig::Method::fourier) {
        // The material's own path: every lobe and channel of a θd from one node set.
        MaterialNpRequest mr{c.eta, c.path, {}, channel_sigmas, thetas, phis, c.quadrature.tolerance};
        for (int p = 0; p < s.lobes; ++p) mr.betas.push_back(m.beta_n[static_cast<std::size_t>(p)]);
        item.np = std::make_unique<MaterialNp>(std::move(mr));
        if (!item.np->note().empty() && &m == &c.scene->materials.front()) report.notes.push_back("per-material N_p: " + item.np->note());
      } else {
        unconverged += bake_np_grid(
            {c.eta, c.path, c.quadrature, s.lobes, channel_sigmas, thetas, phis,
             [&](int p) { return std::vector<double>{m.beta_n[static_cast<std::size_t>(p)]}; }, rules, {}},
            opt, "N_p " + m.name, [&](int p, std::size_t ic, std::size_t it, std::size_t, std::size_t ip, double v) {
              set.tables[first + static_cast<std::size_t>(p)].set((ic * nt + it) * nphi + ip, v);
            });
      }
      report.entries += 3 * nt * (nphi * static_cast<std::size_t>(s.lobes) + static_cast<std::size_t>(lobe_set.size()));
    }
    // One parallel loop over every (material, θd): N_p of every lobe and channel, and the lobe
    // energies of every channel at once (material_energies: lobe_energies' rule and integrand).
    // Few large loops rather than two per material: less time in OpenMP's start and spin-waiting.
    parallel_for(pending.size() * nt, opt, "N_p and energies (per material)", 3 * nphi * static_cast<std::size_t>(s.lobes), [&](std::size_t item) {
      const Pending& w = pending[item / nt];
      const std::size_t it = item % nt, K = w.sigmas.size();
      if (w.np) {
        std::vector<double> v;
        w.np->evaluate(it, v);
        for (int p = 0; p < s.lobes; ++p)
          for (std::size_t ic = 0; ic < K; ++ic)
            for (std::size_t ip = 0; ip < nphi; ++ip)
              set.tables[w.first + static_cast<std::size_t>(p)].set((ic * nt + it) * nphi + ip, v[(static_cast<std::size_t>(p) * K + ic) * nphi + ip]);
      }
      std::vector<double> e;
      material_energies(c.eta, thetas[it], c.path, w.sigmas, lobe_set, s.energy_rule, e);
      const auto E = static_cast<std::size_t>(lobe_set.size());
      for (std::size_t ic = 0; ic < K; ++ic) {
        for (std::size_t p = 0; p < E; ++p) set.tables[w.energy_first + p].set(ic * nt + it, e[ic * E + p]);
        if (c.residual) set.tables[w.residual_index].set(ic * nt + it, e[ic * E + E - 1] / kTwoPi);
      }
    });
  }

  // ---- M_p: generic over (β, θi, θr) per lobe; per material over (θi, θr).
  if (c.mp_axes) {
    const GridAxis ti_axis = axis_named(*c.mp_axes, "theta_i"), tr_axis = axis_named(*c.mp_axes, "theta_r");
    const std::vector<double> tis = ti_axis.nodes(), trs = tr_axis.nodes();
    const int n_mp = s.lobes + (c.residual ? 1 : 0);
    auto tilt_of = [&](int p) { return p == s.lobes ? c.residual_tilt : c.tilt[static_cast<std::size_t>(p)]; };
    auto lobe_of = [&](int p) { return p == s.lobes ? std::string(residual_name()) : lobe_name(p); };
    const std::size_t ni = tis.size(), nr = trs.size();
    if (!per_material) {
      const std::vector<double> betas = axis_named(*c.mp_axes, "beta").nodes();
      const std::size_t first = set.tables.size();
      for (int p = 0; p < n_mp; ++p) {
        Table t = make_table("mp", lobe_of(p), "M_p", "1/rad",
                             "d'Eon longitudinal function M(beta^2, theta_i, theta_r - alpha) of lobe " + lobe_of(p), *c.mp_axes,
                             precision, !slabbed);
        t.attributes = {{"lobe", lobe_of(p)}, {"p", p}, {"alpha", tilt_of(p)}};
        set.tables.push_back(std::move(t));
      }
      const std::size_t nb = betas.size();
      if (slabbed) {
        for (int p = 0; p < n_mp; ++p)
          slabbed->tables.push_back({first + static_cast<std::size_t>(p), [betas, tis, trs, opt, alpha = tilt_of(p)](std::size_t row0, std::size_t rows, Table& out) {
                                       const std::size_t n_i = tis.size(), n_r = trs.size();
                                       parallel_for(rows * n_i, opt, "M_p slab", n_r, [&](std::size_t k) {
                                         const std::size_t ib = row0 + k / n_i, ii = k % n_i;
                                         for (std::size_t ir = 0; ir < n_r; ++ir)
                                           out.set(k * n_r + ir, longitudinal_deon_tilted(betas[ib] * betas[ib], alpha, tis[ii], trs[ir]));
                                       });
                                     }});
      } else {
        parallel_for(nb * ni, opt, "M_p", nr * static_cast<std::size_t>(n_mp), [&](std::size_t k) {
          const std::size_t ib = k / ni, ii = k % ni;
          const double v = betas[ib] * betas[ib];
          for (int p = 0; p < n_mp; ++p) {
            Table& t = set.tables[first + static_cast<std::size_t>(p)];
            for (std::size_t ir = 0; ir < nr; ++ir)
              t.set((ib * ni + ii) * nr + ir, longitudinal_deon_tilted(v, tilt_of(p), tis[ii], trs[ir]));
          }
        });
      }
      report.entries += nb * ni * nr * static_cast<std::size_t>(n_mp);
    } else {
      for (const MaterialConfig& m : c.scene->materials) {
        const std::string group = "materials/" + m.name;
        const std::size_t first = set.tables.size();
        for (int p = 0; p < n_mp; ++p) {
          const double beta = p == s.lobes ? m.residual_beta_m : m.beta_m[static_cast<std::size_t>(p)];
          Table t = make_table(group, "mp_" + lobe_of(p), "M_p", "1/rad",
                               "M_p of lobe " + lobe_of(p) + " for material " + m.name, {ti_axis, tr_axis}, precision);
          t.attributes = {{"lobe", lobe_of(p)}, {"p", p}, {"material", m.name}, {"beta", beta}, {"alpha", tilt_of(p)}};
          set.tables.push_back(std::move(t));
        }
        std::vector<double> betas;
        for (int p = 0; p < n_mp; ++p) betas.push_back(p == s.lobes ? m.residual_beta_m : m.beta_m[static_cast<std::size_t>(p)]);
        parallel_for(ni, opt, "M_p " + m.name, nr * static_cast<std::size_t>(n_mp), [&](std::size_t ii) {
          for (int p = 0; p < n_mp; ++p) {
            Table& t = set.tables[first + static_cast<std::size_t>(p)];
            const double beta = betas[static_cast<std::size_t>(p)];
            for (std::size_t ir = 0; ir < nr; ++ir)
              t.set(ii * nr + ir, longitudinal_deon_tilted(beta * beta, tilt_of(p), tis[ii], trs[ir]));
          }
        });
        report.entries += ni * nr * static_cast<std::size_t>(n_mp);
      }
    }
  }

  detail::append_melanin_tables(c, precision, set, report);

  // ---- Mean energy and dual scattering (tables.dual_scattering), engine presets (tables.engine).
  bake_dual_scattering_tables(c, opt, set, report);

  if (unconverged) report.notes.push_back(std::to_string(unconverged) + " adaptive N_p entries did not reach the tolerance");
  if (!report.resolution.is_null() && generic_np) {
    const AchievedError achieved = measure_np_error(set, c.eta, c.path, 4096, opt.threads);
    report.resolution["achieved_error"] = achieved.worst;
    report.resolution["achieved_p99"] = achieved.p99;
    report.notes.push_back("target_error: achieved sampled error " + std::to_string(achieved.worst) + " (worst, " + achieved.worst_table + "), p99 " +
                           std::to_string(achieved.p99) + " at random points, relative to " + achieved.denominator);
    set.metadata["resolution"] = report.resolution;
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  set.metadata["notes"] = report.notes;
  if (report_out) *report_out = report;
  return set;
}

}  // namespace hairlut
