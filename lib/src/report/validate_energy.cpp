// The validator's energy sections every model shares: the M_p tables' normalisation, and absorption
// (∫ N_table dφ against the energy tables, energies against σa and θd); and the integrals over φ
// the models' own sections (lib/models/<model>/<model>_report.cpp) use.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "hairlut/bake/sampled_error.hpp"
#include "hairlut/physics/directional_albedo.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "hairlut/physics/marschner.hpp"
#include "hairlut/tables/fourier_tables.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"
#include "validate_sections.hpp"

namespace hairlut::detail::validation {

namespace {

// ∫_{−π}^{π} N(φ) dφ of a table sampled along its φ axis, exactly for the sampler: between the φ
// nodes it is linear in φ (uniform spacing) and constant beyond the outermost nodes, so the
// trapezoid rule over the nodes and the ends of the interval is exact; a cubic (Catmull–Rom) φ
// axis over the whole circle (even or periodic, whose end neighbours are mirrored or wrapped)
// integrates to the same trapezoid sum, since its corrections to each cell cancel in the sum.
template <class Sample>
double phi_integral(const GridAxis& a, Sample&& sample) {
  std::vector<double> phis = a.nodes();
  const bool even = a.wrap == Wrap::even;
  phis.push_back(even ? 0.0 : -kPi);
  phis.push_back(kPi);
  std::sort(phis.begin(), phis.end());
  phis.erase(std::unique(phis.begin(), phis.end()), phis.end());
  double sum = 0.0, prev_phi = phis.front(), prev = sample(prev_phi);
  for (std::size_t i = 1; i < phis.size(); ++i) {
    const double v = sample(phis[i]);
    sum += 0.5 * (v + prev) * (phis[i] - prev_phi);
    prev = v, prev_phi = phis[i];
  }
  return even ? 2.0 * sum : sum;
}

}  // namespace

double table_energy(const TableSet& set, const Table& t, double beta, double sigma, double theta_d) {
  return phi_integral(t.axes[3], [&](double phi) { return set.sample_value(t, {beta, sigma, theta_d, phi}); });
}

double marschner_table_energy(const Table& t, double sigma, double theta_d, double phi_h) {
  return phi_integral(t.axes.back(), [&](double phi) {
    return t.axes.size() == 4 ? t.sample({sigma, theta_d, phi_h, phi}) : t.sample({sigma, theta_d, phi});
  });
}


json longitudinal_section(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt, std::vector<json>& checks) {
  json out;
  const auto thetas = theta_grid_deg();
  out["theta_i_deg"] = thetas;
  json curves = json::array();
  double worst_deon = 0.0;
  double low_theta_h = 0.0, grazing_gain = 0.0, high_loss = 2.0;
  for (double bd : {2.0, 5.0, 10.0, 20.0, 30.0, 45.0}) {
    const double beta = radians(bd);
    std::vector<double> deon, g1, g2;
    for (double td : thetas) {
      const double ti = radians(td);
      deon.push_back(longitudinal_energy_deon(beta * beta, 0.0, ti).value[0]);
      g1.push_back(longitudinal_energy_gaussian(beta, 0.0, ti, GaussianArgument::theta_h).value[0]);
      g2.push_back(longitudinal_energy_gaussian(beta, 0.0, ti, GaussianArgument::two_theta_h).value[0]);
      worst_deon = std::max(worst_deon, std::abs(deon.back() - 1.0));
      if (bd == 2.0 && std::abs(td) <= 60) low_theta_h = std::max(low_theta_h, std::abs(g1.back() - 2.0));
      if (bd == 10.0 && td == 89) grazing_gain = g2.back();
      if (bd == 30.0 && std::abs(td) <= 45) high_loss = std::min(high_loss, 1.0 - g2.back());
    }
    curves.push_back({{"beta_deg", bd}, {"deon", deon}, {"gaussian_theta_h", g1}, {"gaussian_2theta_h", g2}});
  }
  out["curves"] = curves;
  const double t = opt.thresholds.longitudinal_deon;
  checks.push_back(check("longitudinal_deon", "d'Eon's M_p is normalized: |int M cos(theta_r) dtheta_r - 1|", worst_deon <= t, worst_deon, t, "<=",
                         "beta 2-45 deg, theta_i -89..89 deg"));
  const bool fig3 = low_theta_h < 0.05 && grazing_gain > 1.05 && high_loss > 0.05;
  checks.push_back(check("paper_gaussian", "d'Eon 2011 Fig. 3: Gaussian M_p energy ~2 (theta_h), gain at grazing, loss at high roughness", fig3,
                         grazing_gain, 1.05, ">",
                         "theta_h at beta 2 deg within " + fmt(low_theta_h) + " of 2; 2theta_h at 89 deg, beta 10 deg: " + fmt(grazing_gain) +
                             "; 2theta_h at beta 30 deg loses at least " + fmt(high_loss)));
  // The M_p tables against the exact (tilted) energy.
  json tables = json::array();
  double worst_table = 0.0;
  std::string worst_where;
  const ModelKindReport* model = nullptr;
  for (const ModelKindReport* m : model_kind_reports())
    if (m->name() == info.model) model = m;
  for (const Table& tb : set.tables) {
    if (!model || tb.quantity != "M_p" || tb.axes.size() != 3 || tb.axes[0].name != "beta") continue;
    // The model says what the table's energy is and with which measure (d'Eon's tilted M: cos θr;
    // Marschner's Gaussian: cos²θr).
    // θi over the table's own range (a model may keep it off the poles: Kajiya–Kay's).
    std::vector<double> table_thetas;
    for (double td : thetas)
      if (radians(td) >= tb.axes[1].lo - 1e-12 && radians(td) <= tb.axes[1].hi + 1e-12) table_thetas.push_back(td);
    json tj = {{"path", tb.path()}, {"alpha", model->mp_energy(tb, tb.axes[0].nodes().front(), 0.0).shift}, {"theta_i_deg", table_thetas},
               {"curves", json::array()}};
    for (double beta : representative(tb.axes[0])) {
      std::vector<double> sampled, exact;
      for (double td : table_thetas) {
        const double ti = radians(td);
        const ModelKindReport::MpEnergy e = model->mp_energy(tb, beta, ti);
        AdaptiveOptions ao;
        ao.rel_tol = 1e-7;
        ao.max_intervals = 400;
        std::vector<double> bp = {-kHalfPi, kHalfPi};
        if (std::abs(e.peak) < kHalfPi) bp.insert(bp.begin() + 1, e.peak);
        const AdaptiveResult r = integrate_adaptive(
            [&](double tr, std::span<double> o) {
              o[0] = tb.sample({beta, ti, tr}) * std::cos(tr);
              for (int k = 1; k < e.cos_power; ++k) o[0] *= std::cos(tr);
            },
            1, bp, ao);
        sampled.push_back(r.value[0]);
        exact.push_back(e.exact);
        if (std::abs(sampled.back() - exact.back()) > worst_table)
          worst_table = std::abs(sampled.back() - exact.back()), worst_where = tb.path() + " at theta_i = " + fmt(td) + " deg, beta = " + fmt(degrees(beta)) + " deg";
      }
      tj["curves"].push_back({{"beta_deg", degrees(beta)}, {"table", sampled}, {"exact", exact}});
    }
    tables.push_back(tj);
  }
  out["tables"] = tables;
  if (!tables.empty()) {
    const double tt = opt.thresholds.mp_table_energy;
    checks.push_back(check("mp_table_energy", "M_p tables: |int M_table - int M| over theta_r with the model's measure (with the lobe's tilt)",
                           worst_table <= tt, worst_table, tt, "<=", "worst: " + worst_where));
  }
  return out;
}

// ∫ N_table dφ against the energy table, and energies against σa and θd.
json absorption_section(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt, std::vector<json>& checks) {
  json out;
  json energies = json::array();
  double worst = 0.0;
  std::string where;
  for (const std::string& l : info.lobes) {
    const Table* e = set.find("np/energy_" + l);
    const Table* n = set.find("np/" + l);
    if (!e || e->axes.size() != 2) continue;
    const auto sig = e->axes[0].nodes(), th = e->axes[1].nodes();
    std::vector<std::vector<double>> grid(sig.size(), std::vector<double>(th.size()));
    double emax = 0.0;
    for (std::size_t i = 0; i < sig.size(); ++i)
      for (std::size_t j = 0; j < th.size(); ++j) {
        grid[i][j] = e->get(i * th.size() + j) * e->grazing_factor()(sig[i], th[j]);  // a table reaching 90° stores E / g
        emax = std::max(emax, grid[i][j]);
      }
    energies.push_back({{"lobe", l}, {"sigma_a", sig}, {"theta_d", th}, {"energy", grid}});
    if (n && n->axes.size() == 3 && n->axes[2].name == "phi" && n->group == "np") {  // Marschner (σa, θd, φ)
      for (std::size_t i = 0; i < sig.size(); i += std::max<std::size_t>(1, sig.size() / 4))
        for (std::size_t j = 0; j < th.size(); j += std::max<std::size_t>(1, th.size() / 6)) {
          const double d = std::abs(marschner_table_energy(*n, sig[i], th[j], 0.0) - grid[i][j]) / std::max(emax, 1e-12);
          if (d > worst) worst = d, where = "np/" + l + " at sigma_a = " + fmt(sig[i]) + ", theta_d = " + fmt(degrees(th[j])) + " deg";
        }
    }
    if (n && n->axes.size() == 4 && n->axes[0].name == "beta") {
      for (double beta : representative(n->axes[0]))
        for (std::size_t i = 0; i < sig.size(); i += std::max<std::size_t>(1, sig.size() / 4))
          for (std::size_t j = 0; j < th.size(); j += std::max<std::size_t>(1, th.size() / 6)) {
            const double d = std::abs(table_energy(set, *n, beta, sig[i], th[j]) - grid[i][j]) / std::max(emax, 1e-12);
            if (d > worst) worst = d, where = "np/" + l + " at beta = " + fmt(degrees(beta)) + " deg, sigma_a = " + fmt(sig[i]) + ", theta_d = " + fmt(degrees(th[j])) + " deg";
          }
    }
  }
  out["energies"] = energies;
  if (!energies.empty())
    checks.push_back(check("energy_consistency", "int N_table dphi against the lobe energy tables (relative to the largest energy)",
                           worst <= opt.thresholds.energy_consistency, worst, opt.thresholds.energy_consistency, "<=", where.empty() ? "-" : where));
  return out;
}

}  // namespace hairlut::detail::validation

