// The validator's accuracy section: every table's sampled error at random points over its declared
// domain against direct evaluation (sampled_error.hpp), per kind of table, with heat maps of where
// the error sits.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "hairlut/bake/sampled_error.hpp"
#include "hairlut/bake/table_truth.hpp"
#include "hairlut/report/table_kind_report.hpp"
#include "hairlut/tables/fourier_tables.hpp"
#include "hairlut/util/error.hpp"
#include "validate_sections.hpp"

namespace hairlut::detail::validation {
namespace {
// ---------------------------------------------------------------------------------------------
// Accuracy where a renderer samples: random points over every table's declared domain against
// direct evaluation, relative to the local denominator of each kind (sampled_error.hpp).

// The kind of a table for the per-kind checks: "np" (the N_p tables of the lobes, also per
// material), "energy" (energies, and the residual's N_p: its energy / 2π, uniform in φ and β),
// "mp", the name of a kind of lib/kinds/ that owns it, or "" (no check).
std::string accuracy_kind(const Table& t) {
  if (t.quantity == "N_p" || is_fourier_table(t)) return t.attributes.value("lobe", std::string()) == "residual" ? "energy" : "np";
  if (t.quantity == "energy") return "energy";
  if (t.quantity == "M_p") return "mp";
  for (const TableKindReport* k : table_kind_reports())
    if (k->owns(t)) return std::string(k->name());
  return "";
}

json error_stats(const SampledErrorStats& s) {
  return {{"points", s.points}, {"max_rel", s.worst}, {"p99_rel", s.p99}, {"mean_rel", s.mean}, {"max_abs", s.worst_abs}};
}

std::string point_text(const Table& t, const std::vector<double>& x) {
  std::string s;
  for (std::size_t k = 0; k < t.axes.size() && k < x.size(); ++k) {
    const GridAxis& a = t.axes[k];
    const bool angle = a.units == "rad";
    s += (s.empty() ? "" : ", ") + a.name + " = " + fmt(angle ? degrees(x[k]) : x[k], 4) + (angle ? " deg" : "");
    if (a.count > 1 && a.name != "channel") s += " (cell " + std::to_string(cell_of(a, x[k])) + ")";
  }
  return s;
}

// Midpoint of cell i in the axis's mapped coordinate (heat-map labels).
double cell_centre(const GridAxis& a, int i) {
  if (a.spacing == Spacing::explicit_values) return 0.5 * (a.values[static_cast<std::size_t>(i)] + a.values[static_cast<std::size_t>(i) + 1]);
  const double t0 = sampler::mapped(a.spacing, sampler::node(a.view(), i));
  const double t1 = sampler::mapped(a.spacing, sampler::node(a.view(), i + 1));
  return sampler::unmapped(a.spacing, 0.5 * (t0 + t1));
}

constexpr std::size_t kDualScatteringPoints = 256;

// The description of table t (no values) with its leading axis narrowed to the part's range: the
// domain its points are drawn over. The range's ends are nodes of t's (narrowed) axis.
Table part_domain(const Table& t, const ValidationPart& part) {
  Table d;
  d.group = t.group, d.name = t.name, d.quantity = t.quantity, d.units = t.units, d.long_name = t.long_name;
  d.attributes = t.attributes, d.precision = t.precision, d.axes = t.axes;
  const auto nodes = t.axes[0].nodes();
  auto nearest = [&](double x) {
    return static_cast<int>(std::min_element(nodes.begin(), nodes.end(), [&](double a, double b) { return std::abs(a - x) < std::abs(b - x); }) -
                            nodes.begin());
  };
  const int i0 = nearest(part.lo), i1 = nearest(part.hi);
  d.axes[0] = narrowed_axis(t.axes[0], i0, i1 - i0 + 1, t.path() + "." + part.axis);
  return d;
}

}  // namespace

json accuracy_section(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt, std::vector<json>& checks) {
  json out = json::array();
  struct Worst {
    double value = -1.0;
    std::string where;
    bool any = false;
    void update(double v, const std::string& w) {
      any = true;
      if (v > value) value = v, where = w;
    }
  };
  std::map<std::string, Worst> worst_max, worst_p99;
  std::map<std::string, std::string> denominators;
  const auto rule = std::make_shared<const GaussLegendreRule>(1024);
  const TruthModel model{info.eta, info.path, info.explicit_lobes, info.kind, info.settings};
  const auto ds_memo = make_dual_scattering_memo();
  std::size_t done = 0;
  for (const Table& t : set.tables) {
    if (opt.progress) opt.progress("accuracy", done, set.tables.size());
    ++done;
    check_cancel(opt);
    std::string kind = accuracy_kind(t);
    // A Fourier table is judged as N_p over the (β, σa, θd, φ) it defines, read through its evaluator.
    const bool fourier = is_fourier_table(t);
    // A set validated in parts: its tables over the part's axis are measured over the part's cells
    // alone (their rows reach one node beyond, for the taps); the others in part 0.
    const ValidationPart* part = opt.part ? &*opt.part : nullptr;
    const bool in_part = part && !fourier && !t.axes.empty() && t.group == part->group && t.axes[0].name == part->axis;
    if (part && part->index > 0 && !in_part) continue;
    const Table domain = fourier ? fourier_domain_table(t) : in_part ? part_domain(t, *part) : Table();
    const Table& d = fourier || in_part ? domain : t;
    auto truth = kind.empty() ? std::nullopt : table_truth(d, model, rule);
    if (!truth && (truth = dual_scattering_truth(set, t, ds_memo))) kind = "ds";
    if (!truth) continue;
    SampledErrorOptions so;
    // Dual-scattering references are slow (adaptive θr integrals of half-range energies): at most
    // kDualScatteringPoints points, the same for every table of the groups (one evaluation each).
    so.points = std::max<std::size_t>(kind == "ds" ? std::min(opt.max_points, kDualScatteringPoints) : opt.max_points, 1);
    if (in_part) so.points = std::max<std::size_t>(static_cast<std::size_t>(std::ceil(static_cast<double>(so.points) * part->share)), 1);
    // The run's seed mixed with the table's path (the dual-scattering tables share their points, one
    // reference evaluation each, so they share a seed).
    so.seed = sampled_error_seed(kind == "ds" ? "dual_scattering" : t.path()) ^ (opt.seed.value_or(0) * 0x9e3779b97f4a7c15ULL);
    if (in_part) so.seed ^= static_cast<std::uint64_t>(part->index + 1) * 0xbf58476d1ce4e5b9ULL;  // each part its own points
    // The dual-scattering references are too slow for the search (adaptive integrals per point).
    so.search = opt.search && kind != "ds";
    so.threads = opt.threads;
    so.half_float = !fourier && !in_part;  // a Fourier table is HDF5 only (float32 or float64); a part is measured through a function
    so.keep_points = true;
    so.cancel = opt.cancel;
    const SampledError r = fourier   ? measure_sampled_error(d, fourier_point_function(t), *truth, so)
                           : in_part ? measure_sampled_error(d, [&](const std::vector<double>& x) { return set.sample_value(t, x); }, *truth, so)
                                     : measure_sampled_error(set, t, *truth, so);
    check_cancel(opt);
    json tj = {{"path", t.path()}, {"quantity", t.quantity}, {"kind", kind}, {"denominator", r.denominator}, {"dims", json::array()}};
    for (const GridAxis& a : d.axes) tj["dims"].push_back(a.name);
    if (fourier) tj["representation"] = "fourier: N_p over (" + std::string(kind == "np" ? "beta, sigma_a, theta_d, phi" : "sigma_a, theta_d") + ") from the coefficients";
    if (t.attributes.contains("beta_band")) tj["beta_band"] = t.attributes["beta_band"];  // N_p in β bands (beta_bands.hpp)
    if (in_part) tj["part"] = {{"index", part->index}, {"axis", part->axis}, {"range", {part->lo, part->hi}}};
    tj["off_node"] = error_stats(r.error);
    tj["off_node_half"] = error_stats(r.half);
    auto at_of = [&](const std::vector<double>& x) {
      json at = json::object();
      for (std::size_t k = 0; k < d.axes.size() && k < x.size(); ++k) at[d.axes[k].name] = x[k];
      return at;
    };
    // The worst point found (random points and every stage of the search): what the checks judge.
    tj["worst"] = {{"max_rel", r.found}, {"at", at_of(r.worst_at)}, {"where", point_text(d, r.worst_at)}, {"sampled", r.worst_sampled},
                   {"exact", r.worst_exact}, {"denominator", r.worst_denominator}};
    json stages = json::array();
    std::size_t evaluated = 0;
    for (const SearchStage& st : r.stages) {
      stages.push_back({{"stage", st.name}, {"points", st.points}, {"max_rel", st.worst}, {"at", at_of(st.at)}, {"where", st.at.empty() ? std::string() : point_text(d, st.at)}});
      evaluated += st.points;
    }
    tj["search"] = {{"seed", so.seed}, {"points", evaluated}, {"stages", stages}};
    // Per axis: the worst error among the points in each cell of the axis.
    json per_axis = json::array();
    for (std::size_t k = 0; k < d.axes.size(); ++k) {
      if (d.axes[k].count < 2 || d.axes[k].name == "channel") continue;
      const auto& cells = r.per_axis_cells[k];
      const auto mx = std::max_element(cells.begin(), cells.end());
      per_axis.push_back({{"axis", d.axes[k].name}, {"count", d.axes[k].count}, {"max_rel", *mx},
                          {"worst_cell", static_cast<int>(mx - cells.begin())}, {"cells_max_rel", cells}});
    }
    tj["per_axis"] = per_axis;
    // Heat maps of the largest relative error per pair of axes (cells of the table).
    json heat = json::array();
    for (std::size_t i = 0; i < d.axes.size(); ++i)
      for (std::size_t j = i + 1; j < d.axes.size(); ++j) {
        const GridAxis &ai = d.axes[i], &aj = d.axes[j];
        if (ai.count < 2 || aj.count < 2 || ai.name == "channel" || aj.name == "channel") continue;
        const auto ni = static_cast<std::size_t>(ai.count - 1), nj = static_cast<std::size_t>(aj.count - 1);
        std::vector<std::vector<double>> grid(ni, std::vector<double>(nj, NAN));  // NaN: no point in this cell
        for (std::size_t q = 0; q < r.x.size(); ++q) {
          double& g = grid[static_cast<std::size_t>(cell_of(ai, r.x[q][i]))][static_cast<std::size_t>(cell_of(aj, r.x[q][j]))];
          g = std::isnan(g) ? r.rel[q] : std::max(g, r.rel[q]);
        }
        std::vector<double> ci, cj;
        for (int c = 0; c + 1 < ai.count; ++c) ci.push_back(cell_centre(ai, c));
        for (int c = 0; c + 1 < aj.count; ++c) cj.push_back(cell_centre(aj, c));
        heat.push_back({{"x", aj.name}, {"y", ai.name}, {"x_units", aj.units}, {"y_units", ai.units}, {"x_centres", cj}, {"y_centres", ci},
                        {"max_rel", grid}});
      }
    tj["heatmaps"] = heat;
    out.push_back(tj);
    worst_max[kind].update(r.found, t.path() + " at " + point_text(d, r.worst_at) + ": sampled " + fmt(r.worst_sampled, 4) + ", exact " +
                                              fmt(r.worst_exact, 4) + ", denominator " + fmt(r.worst_denominator, 4));
    worst_p99[kind].update(r.error.p99, t.path());
    denominators[kind] = r.denominator;
  }
  if (opt.progress) opt.progress("accuracy", set.tables.size(), set.tables.size());
  const ValidationThresholds& th = opt.thresholds;
  auto words = [&](const std::string& kind) { return "; denominator: " + denominators[kind]; };
  if (!worst_max["np"].any) {
    checks.push_back(skipped("accuracy_max_rel", "N_p tables where a renderer samples", "no N_p table of a known kind"));
  } else {
    checks.push_back(check("accuracy_max_rel", "N_p tables: worst error found (random points over the domain, then the worst-point search), relative to the slice's peak over phi",
                           worst_max["np"].value <= th.accuracy_max_rel, worst_max["np"].value, th.accuracy_max_rel, "<=",
                           worst_max["np"].where + words("np")));
    checks.push_back(check("accuracy_p99_rel", "N_p tables: 99th percentile of the error at the random points", worst_p99["np"].value <= th.accuracy_p99_rel,
                           worst_p99["np"].value, th.accuracy_p99_rel, "<=", worst_p99["np"].where));
  }
  std::vector<std::tuple<std::string, std::string, std::string, double>> kinds = {
      {"energy", "accuracy_energy_max_rel", "Energy tables and the residual's N_p: worst relative error found (random points, then the search)",
       th.accuracy_energy_max_rel},
      {"mp", "accuracy_mp_max_rel", "M_p tables: worst error found (random points, then the search), relative to the peak over theta_r", th.accuracy_mp_max_rel}};
  for (const TableKindReport* k : table_kind_reports())
    kinds.emplace_back(k->name(), k->accuracy_check(), k->accuracy_title(), th.get(std::string(k->accuracy_check())));
  kinds.emplace_back("ds", "accuracy_ds_max_rel", "Dual-scattering and mean-energy tables: worst relative error at random points", th.accuracy_ds_max_rel);
  for (const auto& [kind, id, title, threshold] : kinds)
    if (worst_max[kind].any)
      checks.push_back(check(id, title, worst_max[kind].value <= threshold, worst_max[kind].value, threshold, "<=", worst_max[kind].where + words(kind)));
  return out;
}

}  // namespace hairlut::detail::validation

