// Model "marschner2003" in the validator: Marschner 2003 does not conserve energy, so its sections
// are its E(θi) (per lobe, direct) with the same through the tables checked against it, and the
// comparison with d'Eon 2011's model for the tables' fiber (report/compare.hpp).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "hairlut/physics/directional_albedo.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "hairlut/physics/marschner.hpp"
#include "hairlut/report/compare.hpp"
#include "hairlut/report/model_kind_report.hpp"
#include "hairlut/report/svg_plot.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/util/quadrature.hpp"
#include "report/report_html.hpp"
#include "report/validate_sections.hpp"

namespace hairlut::models::marschner2003 {
namespace {

using namespace detail::validation;
using detail::html::lobe_colour;
using detail::html::vec;
using svg::escape;

// Marschner 2003 is not energy conserving: its E(θi) (per lobe, direct) is shown, and the same
// from the tables (the sampled N_p integrated over φ, the sampled M_p over θr) is checked against it.
json marschner_energy_section(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt, std::vector<json>& checks) {
  const MarschnerConfig m = marschner_from_json(info.settings->json(), info.eta, info.path);
  json out;
  std::vector<double> thetas;
  for (int d = -85; d <= 85; d += 5) thetas.push_back(d);
  out["theta_i_deg"] = thetas;
  const Table* mp_first = set.find("mp/" + info.lobes[0]);
  const Table* np_first = set.find("np/" + info.lobes[0]);
  std::vector<double> betas = {radians(2.0), radians(5.0), radians(10.0)};
  if (mp_first && mp_first->axes.size() == 3) betas = representative(mp_first->axes[0]);
  const bool have_tables = mp_first && mp_first->axes.size() == 3 && np_first && np_first->axes.size() >= 3 && np_first->group == "np";
  const double sigma = np_first && np_first->group == "np" ? np_first->axes[0].nodes().front() : 0.0;
  out["sigma_a"] = sigma;
  out["measure"] = "E(theta_i) = sum_p int M_p e_p(theta_d) cos^2(theta_r) dtheta_r (d'Eon 2011 eq. 5), e_p = int N_p dphi, phi_h = 0";
  double worst = 0.0;
  std::string where = "-";
  json curves = json::array();
  const int lobes = static_cast<int>(info.lobes.size());
  for (double beta : betas) {
    detail::validation::check_cancel(opt);
    const MarschnerLobes l = m.lobes(beta);
    json c = {{"beta_R_deg", degrees(beta)}};
    std::vector<double> total;
    std::vector<std::vector<double>> per(static_cast<std::size_t>(lobes));
    for (double td : thetas) {
      const MarschnerAlbedo a = marschner_directional_albedo(m.params, l, m.argument, sigma, radians(td));
      double t = 0.0;
      for (int p = 0; p < lobes; ++p) per[static_cast<std::size_t>(p)].push_back(a.per_lobe[static_cast<std::size_t>(p)]), t += a.per_lobe[static_cast<std::size_t>(p)];
      total.push_back(t);
    }
    c["direct"] = {{"total", total}};
    for (int p = 0; p < lobes; ++p) c["direct"][info.lobes[static_cast<std::size_t>(p)]] = per[static_cast<std::size_t>(p)];
    if (have_tables) {
      std::vector<const Table*> np, mp;
      for (const auto& name : info.lobes) np.push_back(set.find("np/" + name)), mp.push_back(set.find("mp/" + name));
      std::vector<EnergyCurve> e(static_cast<std::size_t>(lobes));
      for (int p = 0; p < lobes; ++p) {
        e[static_cast<std::size_t>(p)].values.resize(1001);
        for (std::size_t k = 0; k <= 1000; ++k)
          e[static_cast<std::size_t>(p)].values[k] = np[static_cast<std::size_t>(p)]
                                                         ? marschner_table_energy(*np[static_cast<std::size_t>(p)], sigma, kHalfPi * static_cast<double>(k) / 1000.0, 0.0)
                                                         : 0.0;
      }
      std::vector<double> table_total;
      for (std::size_t i = 0; i < thetas.size(); ++i) {
        const double ti = radians(thetas[i]);
        std::vector<double> bp = {-kHalfPi, kHalfPi};
        for (int p = 0; p < lobes; ++p)
          if (std::abs(2.0 * l.alpha[p] - ti) < kHalfPi) bp.push_back(2.0 * l.alpha[p] - ti);
        std::sort(bp.begin(), bp.end());
        AdaptiveOptions ao;
        ao.rel_tol = 1e-7;
        ao.max_intervals = 400;
        const AdaptiveResult r = integrate_adaptive(
            [&](double tr, std::span<double> o) {
              const double c2 = std::cos(tr) * std::cos(tr), thd = std::abs(0.5 * (tr - ti));
              o[0] = 0.0;
              for (int p = 0; p < lobes; ++p)
                if (mp[static_cast<std::size_t>(p)]) o[0] += mp[static_cast<std::size_t>(p)]->sample({beta, ti, tr}) * e[static_cast<std::size_t>(p)].at(thd) * c2;
            },
            1, bp, ao);
        table_total.push_back(r.value[0]);
        const double d = std::abs(r.value[0] - total[i]) / std::max(1.0, total[i]);
        if (d > worst) worst = d, where = "theta_i = " + fmt(thetas[i]) + " deg, beta_R = " + fmt(degrees(beta)) + " deg";
      }
      c["table"] = {{"total", table_total}};
    }
    curves.push_back(c);
  }
  out["curves"] = curves;
  checks.push_back(skipped("furnace_direct", "White furnace of the model", "model marschner2003 does not conserve energy (see its energy section)"));
  if (have_tables) {
    const double t = opt.thresholds.furnace_table;
    checks.push_back(check("energy_table", "Energy E(theta_i) from the sampled N_p and M_p tables against direct evaluation (relative, sigma_a = " + fmt(sigma) + ")",
                           worst <= t, worst, t, "<=", "worst at " + where));
  } else {
    checks.push_back(skipped("energy_table", "Energy from the tables", "needs generic np and mp tables"));
  }
  return out;
}

// The model comparison for the fiber of a Marschner table set: its η, path and settings, the
// σa node nearest 0.5 (a light brown) and the middle β_R of its M_p tables.
json compare_for(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt) {
  CompareSettings s;
  s.eta = info.eta;
  s.path = info.path;
  s.marschner = marschner_from_json(info.settings->json(), info.eta, info.path);
  s.cancel = opt.cancel;
  if (const Table* n = set.find("np/R"); n && n->axes[0].name == "sigma_a") {
    double best = INFINITY;
    for (double v : n->axes[0].nodes())
      if (std::abs(v - 0.5) < std::abs(best - 0.5)) best = v;
    s.sigma_a = best;
  }
  if (const Table* mt = set.find("mp/R"); mt && mt->axes.size() == 3) {
    const auto b = mt->axes[0].nodes();
    s.beta_r = b[b.size() / 2];
  }
  s.fiber = "from the tables' metadata";
  return compare_models(s);
}

class Report final : public ModelKindReport {
 public:
  std::string_view name() const override { return "marschner2003"; }
  void energy_sections(const TableSet& set, const TableSetModel& info, const ValidationOptions& opt, std::vector<json>& checks,
                       json& report) const override {
    if (!info.settings) throw DomainError("table metadata: model marschner2003 without its settings");
    if (opt.progress) opt.progress("energy", 1, 6);
    report["marschner_energy"] = marschner_energy_section(set, info, opt, checks);
    if (opt.progress) opt.progress("compare", 2, 6);
    report["compare"] = compare_for(set, info, opt);
  }
  // Marschner's Gaussian: measure cos²θr, shift α of θh, width beta_ratio·β.
  MpEnergy mp_energy(const Table& t, double beta, double theta_i) const override {
    const double alpha = t.attributes.value("alpha_theta_h", 0.0);
    const double ratio = t.attributes.value("beta_ratio", 1.0);
    const GaussianArgument argument =
        t.attributes.value("argument", std::string("theta-h")) == "2theta-h" ? GaussianArgument::two_theta_h : GaussianArgument::theta_h;
    return {longitudinal_energy_gaussian(ratio * beta, alpha, theta_i, argument).value[0], 2, 2.0 * alpha - theta_i, alpha};
  }
  std::string html(const json& r) const override {
    if (!r.contains("marschner_energy")) return {};
    std::ostringstream o;
    const json& me = r["marschner_energy"];
    o << "<h2>Energy of Marschner's model: E(&theta;<sub>i</sub>) per lobe</h2>\n<p>Marschner 2003 does not conserve energy: "
      << escape(me["measure"].get<std::string>()) << ", &sigma;<sub>a</sub> = " << detail::html::fmt(me["sigma_a"])
      << ". Solid: direct evaluation; dashed: from the sampled tables (N<sub>p</sub> integrated over &phi;, M<sub>p</sub> over &theta;<sub>r</sub>).</p>"
         "<div class=\"plots\">\n";
    const auto th = vec(me["theta_i_deg"]);
    for (const json& c : me["curves"]) {
      svg::LinePlot p = detail::html::energy_plot("E(theta_i), beta_R = " + detail::html::fmt(c["beta_R_deg"]) + " deg");
      for (const auto& [k, v] : c["direct"].items()) p.series.push_back({k, th, vec(v), lobe_colour(k), false});
      if (c.contains("table")) p.series.push_back({"total (tables)", th, vec(c["table"]["total"]), lobe_colour("total"), true});
      o << svg::line_plot(p) << "\n";
    }
    o << "</div>\n";
    if (r.contains("compare")) o << render_compare_html_sections(r["compare"]);
    return o.str();
  }
};

}  // namespace

const ModelKindReport& report() {
  static const Report r;
  return r;
}

}  // namespace hairlut::models::marschner2003
