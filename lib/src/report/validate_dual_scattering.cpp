// The validator's section for mean-energy and dual-scattering tables, and its report rendering.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "hairlut/util/angles.hpp"
#include "hairlut/physics/attenuation.hpp"
#include "hairlut/physics/dual_scattering.hpp"
#include "hairlut/bake/engine_presets.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/report/svg_plot.hpp"
#include "validate_sections.hpp"

namespace hairlut::detail {
namespace {

using json = nlohmann::ordered_json;

std::string fmt(double v, int digits = 3) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

json check(const std::string& id, const std::string& title, bool pass, double value, double threshold, const std::string& detail) {
  return {{"id", id}, {"title", title}, {"status", pass ? "pass" : "fail"}, {"value", value}, {"threshold", threshold},
          {"comparison", "<="}, {"detail", detail}};
}

json skipped(const std::string& id, const std::string& title, const std::string& why) {
  return {{"id", id}, {"title", title}, {"status", "skipped"}, {"value", nullptr}, {"threshold", nullptr}, {"comparison", ""}, {"detail", why}};
}

std::size_t position(const std::vector<GridAxis>& axes, const std::string& name) {
  for (std::size_t i = 0; i < axes.size(); ++i)
    if (axes[i].name == name) return i;
  throw DomainError("dual-scattering table metadata names an axis \"" + name + "\" that its tables do not have");
}

// Up to three indices: first, middle, last.
std::vector<std::size_t> picks(int count) {
  std::vector<std::size_t> v = {0};
  if (count > 2) v.push_back(static_cast<std::size_t>(count / 2));
  if (count > 1) v.push_back(static_cast<std::size_t>(count - 1));
  return v;
}

// Series colours: the halves, and the report's lobe colours for the lobes' energies (dashed).
constexpr const char* kForward = "#1f77b4";
constexpr const char* kBackward = "#e377c2";
std::string lobe_colour(const std::string& lobe) {
  static const std::pair<const char*, const char*> colours[] = {{"R", "#d62728"}, {"TT", "#2ca02c"}, {"TRT", "#9467bd"},
                                                                {"TRRT", "#ff7f0e"}, {"residual", "#17becf"}};
  for (const auto& [k, c] : colours)
    if (lobe == k) return c;
  return "";
}

struct Worst {
  double value = 0.0;
  std::string where;
  void update(double v, const std::string& w) {
    if (v > value || where.empty()) value = std::max(v, value), where = w;
  }
};

}  // namespace

json dual_scattering_section(const TableSet& set, const ValidationOptions& opt, std::vector<json>& checks) {
  json out = {{"groups", json::array()}};
  if (!set.metadata.contains("dual_scattering") || !set.metadata["dual_scattering"].contains("groups")) return out;
  const json& groups = set.metadata["dual_scattering"]["groups"];
  double eta = 1.55;
  AbsorptionPath path = AbsorptionPath::chord;
  try {
    eta = set.metadata.at("eta").get<double>();
    path = parse_absorption_path(set.metadata.at("absorption_path").get<std::string>(), "table metadata absorption_path");
  } catch (const nlohmann::json::exception& e) {
    throw DomainError(std::string("table metadata: malformed (") + e.what() + ")");
  }
  Worst consistency, furnace, accuracy;
  bool any_consistency = false, any_furnace = false, any_accuracy = false;
  std::vector<std::string> furnace_skips;
  for (const auto& item : groups.items()) {
    const std::string name = item.key();  // (a structured binding cannot be captured by the lambdas below under clang 14)
    const json& entry = item.value();
    if (opt.cancel && opt.cancel->load()) break;
    json g = {{"group", name}};
    std::string me_path;
    for (const auto& p : entry.value("tables", json::array())) {
      const std::string s = p.get<std::string>();
      if (s.size() >= 8 && s.compare(s.size() - 8, 8, "/E_total") == 0) me_path = s;
    }
    const Table* af = set.find(name + "/a_f");
    const Table* ab = set.find(name + "/a_b");
    const Table* et = me_path.empty() ? nullptr : set.find(me_path);
    const Table* any = af ? af : et;
    if (!any) continue;
    const RoughnessMapping rmap = RoughnessMapping::from_json(entry.at("roughness_mapping"));
    const AbsorptionMapping amap = AbsorptionMapping::from_json(entry.at("absorption_mapping"));
    const std::vector<std::string> lobes = entry.at("lobes").get<std::vector<std::string>>();
    const double d_b = entry.value("density_factor", 0.7);
    const std::vector<GridAxis>& axes = any->axes;
    const std::size_t ia = position(axes, entry.at("absorption_axis")), ir = position(axes, entry.at("roughness_axis")),
                      it = position(axes, entry.at("theta_axis"));
    const std::vector<double> xa = axes[ia].nodes(), xr = axes[ir].nodes(), xt = axes[it].nodes();
    std::vector<std::size_t> stride(3, 1);
    for (std::size_t k = 3; k-- > 1;) stride[k - 1] = stride[k] * static_cast<std::size_t>(axes[k].count);
    auto index = [&](std::size_t a, std::size_t r, std::size_t t) { return a * stride[ia] + r * stride[ir] + t * stride[it]; };
    auto where = [&](std::size_t a, std::size_t r, std::size_t t) {
      return name + " at " + axes[ia].name + " = " + fmt(xa[a]) + ", " + axes[ir].name + " = " + fmt(xr[r]) + ", " + axes[it].name + " = " +
             fmt(degrees(xt[t])) + " deg";
    };
    g["axes"] = {{"absorption", axes[ia].name}, {"roughness", axes[ir].name}, {"theta", axes[it].name}};
    g["mean_energy_group"] = me_path.empty() ? "" : me_path.substr(0, me_path.rfind('/'));

    // a_f + a_b against Σ_p E_p: two quadratures of different things that must agree.
    if (af && ab && et) {
      any_consistency = true;
      Worst w;
      for (std::size_t a = 0; a < xa.size(); ++a)
        for (std::size_t r = 0; r < xr.size(); ++r)
          for (std::size_t t = 0; t < xt.size(); ++t) {
            const std::size_t i = index(a, r, t);
            w.update(std::abs(af->get(i) + ab->get(i) - et->get(i)), where(a, r, t));
          }
      g["consistency"] = {{"max_abs", w.value}, {"where", w.where}};
      consistency.update(w.value, w.where);
    }

    // White furnace: σa = 0, the same β for every lobe, no tilt, the residual included.
    std::vector<std::size_t> zero;
    for (std::size_t a = 0; a < xa.size(); ++a)
      if (amap.sigma_a(xa[a]) == 0.0) zero.push_back(a);
    if (et && rmap.uniform() && rmap.residual && !zero.empty()) {
      any_furnace = true;
      Worst w;
      for (std::size_t a : zero)
        for (std::size_t r = 0; r < xr.size(); ++r)
          for (std::size_t t = 0; t < xt.size(); ++t) w.update(std::abs(et->get(index(a, r, t)) - 1.0), where(a, r, t));
      g["furnace"] = {{"max_abs", w.value}, {"where", w.where}};
      furnace.update(w.value, w.where);
    } else if (et) {
      furnace_skips.push_back(name + (zero.empty() ? ": no sigma_a = 0 node" : !rmap.uniform() ? ": lobes differ in roughness or are tilted" : ": no residual"));
    }

    // The tables against dual_scattering() (no θd interpolation, direct half ranges) at nodes.
    std::vector<std::array<std::size_t, 3>> nodes;
    for (std::size_t a : picks(static_cast<int>(xa.size())))
      for (std::size_t r : picks(static_cast<int>(xr.size())))
        for (std::size_t t : picks(static_cast<int>(xt.size())))
          if ((a * 7 + r * 3 + t) % 3 == 0 || (a == 0 && r == xr.size() / 2)) nodes.push_back({a, r, t});
    if (nodes.size() > 10) nodes.resize(10);
    json samples = json::array();
    if (af || et) {
      any_accuracy = true;
      std::vector<DualScatteringPoint> ref(nodes.size());
      const int threads = opt.threads > 0 ? opt.threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
      for (std::size_t n = 0; n < nodes.size(); ++n) {
        const auto [a, r, t] = nodes[n];
        const HairModel m = table_model(rmap, amap, eta, path, xr[r], xa[a]);
        DualScatteringOptions o;
        o.density_factor = d_b;
        ref[n] = dual_scattering(m, xt[t], o);
      }
      Worst w;
      for (std::size_t n = 0; n < nodes.size(); ++n) {
        const auto [a, r, t] = nodes[n];
        const std::size_t i = index(a, r, t);
        json s = {{"absorption", xa[a]}, {"roughness", xr[r]}, {"theta_i_deg", degrees(xt[t])}};
        if (af && ab) {
          s["a_f"] = {af->get(i), ref[n].a_f};
          s["a_b"] = {ab->get(i), ref[n].a_b};
          w.update(std::abs(af->get(i) - ref[n].a_f), where(a, r, t) + " (a_f)");
          w.update(std::abs(ab->get(i) - ref[n].a_b), where(a, r, t) + " (a_b)");
        }
        if (et) {
          s["E_total"] = {et->get(i), ref[n].energy_total};
          w.update(std::abs(et->get(i) - ref[n].energy_total), where(a, r, t) + " (E)");
        }
        samples.push_back(s);
      }
      g["accuracy"] = {{"max_abs", w.value}, {"where", w.where}, {"samples", samples}};
      accuracy.update(w.value, w.where);
    }

    // Curves for the plots: against roughness (first/middle/last θi, first/last absorption) and
    // against absorption (middle roughness and θi), every lobe.
    auto column = [&](const Table* tb, std::size_t a, std::size_t r, std::size_t t, int vary) {
      std::vector<double> v;
      const std::size_t n = vary == 0 ? xa.size() : xr.size();
      for (std::size_t j = 0; j < n; ++j) v.push_back(tb->get(vary == 0 ? index(j, r, t) : index(a, j, t)));
      return v;
    };
    json by_roughness = json::array();
    for (std::size_t a : {std::size_t{0}, xa.size() - 1})
      for (std::size_t t : picks(static_cast<int>(xt.size()))) {
        json c = {{"absorption", xa[a]}, {"sigma_a", amap.sigma_a(xa[a])}, {"theta_i_deg", degrees(xt[t])}};
        if (af && ab) c["a_f"] = column(af, a, 0, t, 1), c["a_b"] = column(ab, a, 0, t, 1);
        if (et) c["E_total"] = column(et, a, 0, t, 1);
        by_roughness.push_back(c);
        if (xa.size() == 1) break;
      }
    json by_absorption = json::array();
    {
      const std::size_t r = xr.size() / 2;
      for (std::size_t t : picks(static_cast<int>(xt.size()))) {
        json c = {{"roughness", xr[r]}, {"theta_i_deg", degrees(xt[t])}};
        if (af && ab) c["a_f"] = column(af, 0, r, t, 0), c["a_b"] = column(ab, 0, r, t, 0);
        if (et) {
          c["E_total"] = column(et, 0, r, t, 0);
          for (const std::string& l : lobes)
            if (const Table* e = set.find(g["mean_energy_group"].get<std::string>() + "/E_" + l)) c["E_" + l] = column(e, 0, r, t, 0);
        }
        by_absorption.push_back(c);
      }
    }
    std::vector<double> sig;
    for (double x : xa) sig.push_back(amap.sigma_a(x));
    g["plots"] = {{"roughness_nodes", xr}, {"absorption_nodes", xa}, {"sigma_a", sig}, {"roughness_label", axes[ir].name + " (" + axes[ir].units + ")"},
                  {"absorption_label", axes[ia].name + " (" + axes[ia].units + ")"}, {"by_roughness", by_roughness}, {"by_absorption", by_absorption}};
    g["roughness_mapping"] = entry.at("roughness_mapping");
    g["absorption_mapping"] = entry.at("absorption_mapping");
    out["groups"].push_back(g);
  }
  const ValidationThresholds& th = opt.thresholds;
  if (any_consistency)
    checks.push_back(check("ds_consistency", "Dual scattering against mean energy: |a_f + a_b - sum_p E_p| at every node",
                           consistency.value <= th.ds_consistency, consistency.value, th.ds_consistency, "worst: " + consistency.where));
  if (any_furnace)
    checks.push_back(check("ds_furnace", "White furnace of the mean-energy table: |sum_p E_p - 1| at sigma_a = 0 (residual included)",
                           furnace.value <= th.ds_furnace, furnace.value, th.ds_furnace, "worst: " + furnace.where));
  else if (!furnace_skips.empty()) {
    std::string why;
    for (const auto& s : furnace_skips) why += (why.empty() ? "" : "; ") + s;
    checks.push_back(skipped("ds_furnace", "White furnace of the mean-energy table", why));
  }
  if (any_accuracy)
    checks.push_back(check("ds_accuracy", "Mean-energy and dual-scattering tables against direct evaluation (no interpolation) at sampled nodes",
                           accuracy.value <= th.ds_accuracy, accuracy.value, th.ds_accuracy, "worst: " + accuracy.where));
  return out;
}

std::string render_dual_scattering_markdown(const json& r) {
  if (!r.contains("dual_scattering") || r["dual_scattering"]["groups"].empty()) return "";
  std::ostringstream o;
  o << "\n## Mean energy and dual scattering\n\n| group | a_f + a_b vs sum E_p | furnace (sigma_a = 0) | vs direct |\n|---|---|---|---|\n";
  for (const json& g : r["dual_scattering"]["groups"]) {
    auto cell = [&](const char* k) { return g.contains(k) ? fmt(g[k]["max_abs"].get<double>()) : std::string("-"); };
    o << "| " << g["group"].get<std::string>() << " | " << cell("consistency") << " | " << cell("furnace") << " | " << cell("accuracy") << " |\n";
  }
  return o.str();
}

std::string render_dual_scattering_html(const json& r) {
  if (!r.contains("dual_scattering") || r["dual_scattering"]["groups"].empty()) return "";
  using svg::escape;
  std::ostringstream o;
  o << "<h2>Mean energy and dual scattering</h2>\n<p>Zinke 2008's forward and backward average attenuations a<sub>f</sub>, a<sub>b</sub> "
       "(halves |&phi;| &gt; &pi;/2 and |&phi;| &le; &pi;/2 of the scattered energy) and the mean energy E = &Sigma;<sub>p</sub> E<sub>p</sub> "
       "(directional albedo) from the tables, against roughness and against absorption. a<sub>f</sub> + a<sub>b</sub> must equal E "
       "(two different quadratures); with &sigma;<sub>a</sub> = 0, one roughness for every lobe and no tilt, E must be 1.</p>\n";
  for (const json& g : r["dual_scattering"]["groups"]) {
    const json& p = g["plots"];
    o << "<h3>" << escape(g["group"].get<std::string>()) << "</h3>\n<p>roughness: <code>" << escape(g["roughness_mapping"].value("formula", std::string()))
      << "</code><br>absorption: <code>" << escape(g["absorption_mapping"].value("formula", std::string())) << "</code></p>\n";
    o << "<table><tr><th>check</th><th>largest deviation</th><th>where</th></tr>\n";
    for (const char* k : {"consistency", "furnace", "accuracy"})
      if (g.contains(k))
        o << "<tr><td>" << k << "</td><td>" << fmt(g[k]["max_abs"].get<double>()) << "</td><td>" << escape(g[k]["where"].get<std::string>()) << "</td></tr>\n";
    o << "</table><div class=\"plots\">\n";
    const auto xr = p["roughness_nodes"].get<std::vector<double>>();
    for (const json& c : p["by_roughness"]) {
      svg::LinePlot lp;
      lp.title = "absorption " + fmt(c["absorption"].get<double>()) + " (sigma_a " + fmt(c["sigma_a"].get<double>()) + "), theta_i " +
                 fmt(c["theta_i_deg"].get<double>()) + " deg";
      lp.xlabel = p["roughness_label"].get<std::string>();
      lp.ylabel = "energy";
      lp.min_span = 0.2;
      if (c.contains("a_f")) lp.series.push_back({"a_f", xr, c["a_f"].get<std::vector<double>>(), kForward, false});
      if (c.contains("a_b")) lp.series.push_back({"a_b", xr, c["a_b"].get<std::vector<double>>(), kBackward, false});
      if (c.contains("E_total")) lp.series.push_back({"E", xr, c["E_total"].get<std::vector<double>>(), "#000000", true});
      o << svg::line_plot(lp) << "\n";
    }
    const auto xa = p["absorption_nodes"].get<std::vector<double>>();
    for (const json& c : p["by_absorption"]) {
      svg::LinePlot lp;
      lp.title = "roughness " + fmt(c["roughness"].get<double>()) + ", theta_i " + fmt(c["theta_i_deg"].get<double>()) + " deg";
      lp.xlabel = p["absorption_label"].get<std::string>();
      lp.ylabel = "energy";
      lp.min_span = 0.2;
      for (const auto& [k, v] : c.items()) {
        if (k == "roughness" || k == "theta_i_deg") continue;
        const std::string colour = k == "a_f" ? kForward : k == "a_b" ? kBackward : k == "E_total" ? "#000000" : lobe_colour(k.substr(2));
        lp.series.push_back({k == "E_total" ? "E" : k, xa, v.get<std::vector<double>>(), colour, k.rfind("E_", 0) == 0});
      }
      o << svg::line_plot(lp) << "\n";
    }
    o << "</div>\n";
  }
  return o.str();
}

}  // namespace hairlut::detail
