// Model "kajiya1989" in the validator: Kajiya–Kay does not conserve energy, so its section is its
// E(θi) = 2π ∫ M_KK cos²θr dθr (N_KK = 1), direct and through the M table, checked against each other.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "hairlut/physics/kajiya_kay.hpp"
#include "hairlut/report/model_kind_report.hpp"
#include "hairlut/report/svg_plot.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/util/quadrature.hpp"
#include "report/report_html.hpp"
#include "report/validate_sections.hpp"

namespace hairlut::models::kajiya1989 {
namespace {

using namespace detail::validation;
using detail::html::lobe_colour;
using detail::html::vec;
using svg::escape;

KajiyaKayParams params_of(const Table& t, double beta) {
  KajiyaKayParams p;
  p.kd = t.attributes.value("kd", 0.0);
  p.ks = t.attributes.value("ks", 1.0);
  p.exponent = KajiyaKayParams::exponent_for_width(beta);
  return p;
}

// 2π ∫ M_table cos²θr dθr at (β, θi), with the mirror cone as a breakpoint.
double table_energy_kk(const Table& t, double beta, double theta_i) {
  std::vector<double> bp = {-kHalfPi, -theta_i, kHalfPi};
  AdaptiveOptions ao;
  ao.rel_tol = 1e-7;
  ao.max_intervals = 400;
  const AdaptiveResult r = integrate_adaptive(
      [&](double tr, std::span<double> o) { o[0] = t.sample({beta, theta_i, tr}) * std::cos(tr) * std::cos(tr); }, 1, bp, ao);
  return kTwoPi * r.value[0];
}

json energy_section(const TableSet& set, const ValidationOptions& opt, std::vector<json>& checks) {
  json out;
  std::vector<double> thetas;
  for (int d = -85; d <= 85; d += 5) thetas.push_back(d);
  out["theta_i_deg"] = thetas;
  out["measure"] = "E(theta_i) = 2 pi int M_KK cos^2(theta_r) dtheta_r (N_KK = 1)";
  const Table* mp = set.find("mp/R");
  const bool have_table = mp && mp->axes.size() == 3 && mp->attributes.value("function", std::string()) == "kajiya_kay";
  json curves = json::array();
  double worst = 0.0;
  std::string where = "-";
  if (have_table) {
    for (double beta : representative(mp->axes[0])) {
      detail::validation::check_cancel(opt);
      std::vector<double> direct, table;
      for (double td : thetas) {
        const double ti = radians(td);
        direct.push_back(kajiya_kay_energy(params_of(*mp, beta), ti));
        table.push_back(table_energy_kk(*mp, beta, ti));
        const double d = std::abs(table.back() - direct.back()) / std::max(1.0, direct.back());
        if (d > worst) worst = d, where = "theta_i = " + fmt(td) + " deg, beta = " + fmt(degrees(beta)) + " deg";
      }
      curves.push_back({{"beta_deg", degrees(beta)}, {"direct", {{"total", direct}}}, {"table", {{"total", table}}}});
    }
  }
  out["curves"] = curves;
  checks.push_back(skipped("furnace_direct", "White furnace of the model", "model kajiya1989 does not conserve energy (see its energy section)"));
  if (have_table) {
    const double t = opt.thresholds.furnace_table;
    checks.push_back(check("energy_table", "Energy E(theta_i) from the sampled M table against direct evaluation (relative, floored at 1)", worst <= t,
                           worst, t, "<=", "worst at " + where));
  } else {
    checks.push_back(skipped("energy_table", "Energy from the tables", "needs the M table mp/R over (beta, theta_i, theta_r)"));
  }
  return out;
}

class Report final : public ModelKindReport {
 public:
  std::string_view name() const override { return "kajiya1989"; }
  void energy_sections(const TableSet& set, const TableSetModel&, const ValidationOptions& opt, std::vector<json>& checks,
                       json& report) const override {
    if (opt.progress) opt.progress("energy", 1, 6);
    report["kajiya_kay_energy"] = energy_section(set, opt, checks);
  }
  // Kajiya–Kay's measure is the curve scattering functions' cos²θr; its lobe peaks on the mirror cone.
  MpEnergy mp_energy(const Table& t, double beta, double theta_i) const override {
    return {kajiya_kay_energy(params_of(t, beta), theta_i) / kTwoPi, 2, -theta_i, 0.0};
  }
  std::string html(const json& r) const override {
    if (!r.contains("kajiya_kay_energy")) return {};
    const json& e = r["kajiya_kay_energy"];
    std::ostringstream o;
    o << "<h2>Energy of the Kajiya&ndash;Kay model: E(&theta;<sub>i</sub>)</h2>\n<p>Kajiya&ndash;Kay does not conserve energy: "
      << escape(e["measure"].get<std::string>())
      << ". Solid: direct evaluation; dashed: from the sampled M table.</p><div class=\"plots\">\n";
    const auto th = vec(e["theta_i_deg"]);
    for (const json& c : e["curves"]) {
      svg::LinePlot p = detail::html::energy_plot("E(theta_i), beta = " + detail::html::fmt(c["beta_deg"]) + " deg");
      p.series.push_back({"total", th, vec(c["direct"]["total"]), lobe_colour("total"), false});
      p.series.push_back({"total (tables)", th, vec(c["table"]["total"]), lobe_colour("total"), true});
      o << svg::line_plot(p) << "\n";
    }
    o << "</div>\n";
    return o.str();
  }
};

}  // namespace

const ModelKindReport& report() {
  static const Report r;
  return r;
}

}  // namespace hairlut::models::kajiya1989
