#include "hairlut/validate.hpp"

#include <Imath/half.h>

#include <omp.h>

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <memory>
#include <optional>
#include <set>

#include "hairlut/angles.hpp"
#include "hairlut/azimuthal_np.hpp"
#include "hairlut/bake.hpp"
#include "hairlut/compare.hpp"
#include "hairlut/config.hpp"
#include "hairlut/directional_albedo.hpp"
#include "hairlut/error.hpp"
#include "hairlut/hair_model.hpp"
#include "hairlut/hash.hpp"
#include "hairlut/lobe_energy.hpp"
#include "hairlut/longitudinal_mp.hpp"
#include "hairlut/marschner.hpp"
#include "hairlut/melanin.hpp"
#include "hairlut/sampled_error.hpp"
#include "hairlut/table_truth.hpp"
#include "validate_sections.hpp"

namespace hairlut {

const std::map<std::string, double ValidationThresholds::*>& ValidationThresholds::fields() {
  static const std::map<std::string, double ValidationThresholds::*> f = {
      {"furnace_direct", &ValidationThresholds::furnace_direct},
      {"furnace_table", &ValidationThresholds::furnace_table},
      {"longitudinal_deon", &ValidationThresholds::longitudinal_deon},
      {"mp_table_energy", &ValidationThresholds::mp_table_energy},
      {"accuracy_max_rel", &ValidationThresholds::accuracy_max_rel},
      {"accuracy_p99_rel", &ValidationThresholds::accuracy_p99_rel},
      {"accuracy_energy_max_rel", &ValidationThresholds::accuracy_energy_max_rel},
      {"accuracy_mp_max_rel", &ValidationThresholds::accuracy_mp_max_rel},
      {"accuracy_melanin_max_rel", &ValidationThresholds::accuracy_melanin_max_rel},
      {"accuracy_ds_max_rel", &ValidationThresholds::accuracy_ds_max_rel},
      {"energy_consistency", &ValidationThresholds::energy_consistency},
      {"ds_furnace", &ValidationThresholds::ds_furnace},
      {"ds_consistency", &ValidationThresholds::ds_consistency},
      {"ds_accuracy", &ValidationThresholds::ds_accuracy}};
  return f;
}

void ValidationThresholds::set(const std::string& name, double value) {
  const auto it = fields().find(name);
  if (it == fields().end()) {
    std::string known;
    for (const auto& [k, v] : fields()) known += (known.empty() ? "" : ", ") + k;
    throw DomainError("threshold " + name + " is unknown (known: " + known + ")");
  }
  require_positive("threshold " + name, value);
  this->*(it->second) = value;
}

nlohmann::ordered_json ValidationThresholds::to_json() const {
  nlohmann::ordered_json j;
  for (const auto& [k, v] : fields()) j[k] = this->*v;
  return j;
}

namespace {

using json = nlohmann::ordered_json;

// ---------------------------------------------------------------------------------------------
// The model the tables were baked with, from their metadata.
struct ModelInfo {
  std::string model = "deon2011";
  double eta = 1.55;
  AbsorptionPath path = AbsorptionPath::chord;
  std::vector<std::string> lobes;
  int explicit_lobes = 0;
  bool residual = false;
  int energy_order = 128;
  std::optional<MarschnerConfig> marschner;  ///< model "marschner2003"
};

ModelInfo model_from(const TableSet& set) {
  const json& m = set.metadata;
  auto need = [&](const char* key) -> const json& {
    if (!m.contains(key)) throw DomainError("table metadata: missing \"" + std::string(key) + "\" (not a hairlut table set?)");
    return m.at(key);
  };
  ModelInfo info;
  try {
    info.eta = need("eta").get<double>();
    info.path = parse_absorption_path(need("absorption_path").get<std::string>(), "table metadata absorption_path");
    info.lobes = need("lobes").get<std::vector<std::string>>();
    info.residual = need("residual").get<bool>();
    info.explicit_lobes = static_cast<int>(info.lobes.size());
    if (m.contains("quadrature")) info.energy_order = m.at("quadrature").value("energy_order", 128);
    info.model = m.value("model", std::string("deon2011"));
  } catch (const nlohmann::json::exception& e) {
    throw DomainError(std::string("table metadata: malformed (") + e.what() + ")");
  }
  require_greater("table metadata eta", info.eta, 1.0, "must be > 1");
  if (info.model == "marschner2003") {
    if (!m.contains("marschner")) throw DomainError("table metadata: model marschner2003 without its \"marschner\" settings");
    info.marschner = marschner_from_json(m.at("marschner"), info.eta, info.path);
  } else if (info.model != "deon2011") {
    throw DomainError("table metadata: unknown model \"" + info.model + "\"");
  }
  if (info.lobes.empty()) throw DomainError("table metadata: lobes is empty");
  for (std::size_t p = 0; p < info.lobes.size(); ++p)
    if (parse_lobe(info.lobes[p], "table metadata lobes") != static_cast<int>(p))
      throw DomainError("table metadata: lobes must be R, TT, TRT, ... in order");
  return info;
}

// ---------------------------------------------------------------------------------------------
// Checks and small statistics.

json check(const std::string& id, const std::string& title, bool pass, double value, double threshold, const std::string& comparison,
           const std::string& detail) {
  return {{"id", id}, {"title", title}, {"status", pass ? "pass" : "fail"}, {"value", value}, {"threshold", threshold},
          {"comparison", comparison}, {"detail", detail}};
}

json skipped(const std::string& id, const std::string& title, const std::string& why) {
  return {{"id", id}, {"title", title}, {"status", "skipped"}, {"value", nullptr}, {"threshold", nullptr}, {"comparison", ""}, {"detail", why}};
}

std::string fmt(double v, int digits = 3) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

void check_cancel(const ValidationOptions& opt) {
  if (opt.cancel && opt.cancel->load()) throw BakeCancelled();
}

std::vector<double> theta_grid_deg() {
  std::vector<double> t;
  for (int d = -89; d <= 89; d += (std::abs(d) >= 75 ? 2 : 5)) t.push_back(d);
  if (t.back() != 89) t.push_back(89);
  return t;
}

// Up to three representative nodes of an axis (first, middle, last).
std::vector<double> representative(const GridAxis& a) {
  const auto n = a.nodes();
  std::vector<double> r = {n.front()};
  if (n.size() > 2) r.push_back(n[n.size() / 2]);
  if (n.size() > 1) r.push_back(n.back());
  return r;
}

// ---------------------------------------------------------------------------------------------
// Sanity: values and metadata.

json sanity_section(const TableSet& set, const ModelInfo& info, std::vector<json>& checks) {
  json out;
  long long nan = 0, inf = 0, neg = 0;
  json per_table = json::array();
  for (const Table& t : set.tables) {
    long long tn = 0, ti = 0, tneg = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double v = t.get(i);
      if (std::isnan(v)) ++tn;
      else if (std::isinf(v)) ++ti;
      else if (v < 0.0 && t.quantity != "shift" && t.quantity != "transmittance") ++tneg;  // shifts are signed; spectral transmittance is negative out of gamut
    }
    nan += tn, inf += ti, neg += tneg;
    per_table.push_back({{"path", t.path()}, {"values", t.size()}, {"nan", tn}, {"inf", ti}, {"negative", tneg}});
  }
  out["tables"] = per_table;
  checks.push_back(check("sanity_values", "No NaN, Inf or negative value in any table", nan + inf + neg == 0,
                         static_cast<double>(nan + inf + neg), 0, "==",
                         std::to_string(nan) + " NaN, " + std::to_string(inf) + " Inf, " + std::to_string(neg) + " negative in " +
                             std::to_string(set.tables.size()) + " tables"));
  // Lobes the metadata lists must have their tables.
  std::vector<std::string> missing;
  const bool has_np = std::any_of(set.tables.begin(), set.tables.end(), [](const Table& t) { return t.group == "np"; });
  const bool has_mp = std::any_of(set.tables.begin(), set.tables.end(), [](const Table& t) { return t.group == "mp"; });
  std::set<std::string> materials;
  for (const Table& t : set.tables)
    if (t.group.rfind("materials/", 0) == 0) materials.insert(t.group);
  std::vector<std::string> lobes = info.lobes;
  if (info.residual) lobes.push_back("residual");
  for (const std::string& l : lobes) {
    if (has_np) {
      if (l != "residual" && !set.find("np/" + l)) missing.push_back("np/" + l);
      if (!set.find("np/energy_" + l)) missing.push_back("np/energy_" + l);
      if (l == "residual" && !set.find("np/residual")) missing.push_back("np/residual");
    }
    if (has_mp && !set.find("mp/" + l)) missing.push_back("mp/" + l);
    for (const std::string& g : materials)
      if (!set.find(g + "/np_" + l)) missing.push_back(g + "/np_" + l);
  }
  std::string list;
  for (const auto& m : missing) list += (list.empty() ? "" : ", ") + m;
  checks.push_back(check("sanity_lobes", "Every lobe the metadata lists has its tables", missing.empty(), static_cast<double>(missing.size()), 0,
                         "==", missing.empty() ? "lobes " + std::to_string(lobes.size()) + ", all present" : "missing: " + list));
  out["missing_tables"] = missing;
  // Metadata consistency: the config hash, axis units, the residual against its energy.
  std::vector<std::string> problems;
  const json& m = set.metadata;
  if (m.contains("config") && m.contains("config_hash") && m.contains("hairlut_version")) {
    const std::string expect = fnv1a64_hex(m["config"].get<std::string>() + "\nhairlut " + m["hairlut_version"].get<std::string>());
    if (expect != m["config_hash"].get<std::string>()) problems.push_back("config_hash does not match the recorded config");
  } else {
    problems.push_back("metadata lacks config, config_hash or hairlut_version");
  }
  static const std::map<std::string, std::string> units = {{"theta_d", "rad"}, {"phi", "rad"},     {"beta", "rad"},
                                                           {"theta_i", "rad"}, {"theta_r", "rad"}, {"sigma_a", "1/radius"},
                                                           {"phi_h", "rad"}};
  for (const Table& t : set.tables) {
    for (const GridAxis& a : t.axes) {
      const auto u = units.find(a.name);
      if (u != units.end() && u->second != a.units) problems.push_back(t.path() + ": axis " + a.name + " in " + a.units);
    }
  }
  const Table* r = set.find("np/residual");
  const Table* e = set.find("np/energy_residual");
  if (r && e && r->size() == e->size()) {
    // Each stored value carries the rounding of its file format (half in a half EXR, float32, or
    // float64): allow that unit roundoff u on both sides, |2 pi r - e| <= u (2 pi |r| + |e|), on
    // top of 1e-6. The format is the coarsest one that holds every value of both tables exactly.
    auto holds = [&](auto round) {
      for (const Table* t : {r, e})
        for (std::size_t i = 0; i < t->size(); ++i)
          if (round(t->get(i)) != t->get(i)) return false;
      return true;
    };
    const double u = holds([](double v) { return static_cast<double>(static_cast<float>(half(static_cast<float>(v)))); }) ? std::ldexp(1.0, -11)
                     : holds([](double v) { return static_cast<double>(static_cast<float>(v)); })                          ? std::ldexp(1.0, -24)
                                                                                                                        : std::ldexp(1.0, -53);
    double worst = 0.0, worst_excess = 0.0;
    for (std::size_t i = 0; i < r->size(); ++i) {
      const double diff = std::abs(r->get(i) * kTwoPi - e->get(i));
      worst = std::max(worst, diff);
      worst_excess = std::max(worst_excess, diff - u * (kTwoPi * std::abs(r->get(i)) + std::abs(e->get(i))));
    }
    if (worst_excess > 1e-6)
      problems.push_back("np/residual is not np/energy_residual / 2 pi (off by " + fmt(worst) + ", beyond the storage rounding)");
  }
  std::string plist;
  for (const auto& p : problems) plist += (plist.empty() ? "" : "; ") + p;
  checks.push_back(check("sanity_metadata", "Metadata consistent with the data (config hash, axis units, residual)", problems.empty(),
                         static_cast<double>(problems.size()), 0, "==", problems.empty() ? "consistent" : plist));
  out["metadata_problems"] = problems;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Energy: white furnace (direct and from the tables) and truncation.

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

// ∫ N_table(β, σa, θd, φ) dφ of a d'Eon table (read as a renderer reads it: with its factor).
double table_energy(const TableSet& set, const Table& t, double beta, double sigma, double theta_d) {
  return phi_integral(t.axes[3], [&](double phi) { return set.sample_value(t, {beta, sigma, theta_d, phi}); });
}

// ∫ N_table dφ of a Marschner table (σa, θd, [φh,] φ) at φh (ignored without that axis).
double marschner_table_energy(const Table& t, double sigma, double theta_d, double phi_h) {
  return phi_integral(t.axes.back(), [&](double phi) {
    return t.axes.size() == 4 ? t.sample({sigma, theta_d, phi_h, phi}) : t.sample({sigma, theta_d, phi});
  });
}

// e_p,table(θd) on a fine θd grid, for interpolation inside the θr integral.
struct EnergyCurve {
  std::vector<double> values;  // at θd = k (π/2)/n, k = 0 … n
  double at(double theta_d) const {
    const double n = static_cast<double>(values.size() - 1);
    const double s = std::clamp(theta_d / kHalfPi * n, 0.0, n);
    const auto k = std::min(static_cast<std::size_t>(s), values.size() - 2);
    const double w = s - static_cast<double>(k);
    return (1.0 - w) * values[k] + w * values[k + 1];
  }
};

json furnace_section(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt, std::vector<json>& checks) {
  json out;
  const auto thetas = theta_grid_deg();
  out["theta_i_deg"] = thetas;
  std::vector<double> betas;
  const Table* first = set.find("np/" + info.lobes[0]);
  if (first && first->axes.size() == 4) betas = representative(first->axes[0]);
  else betas = {radians(2.0), radians(10.0), radians(30.0)};
  double worst_direct = 0.0, worst_direct_theta = 0.0, worst_direct_beta = 0.0;
  double worst_table = 0.0, worst_table_theta = 0.0, worst_table_beta = 0.0;
  bool have_table = first && first->axes.size() == 4 && first->group == "np";
  double table_sigma = 0.0;
  if (have_table) table_sigma = first->axes[1].nodes().front();
  out["table_sigma_a"] = table_sigma;
  json curves = json::array();
  for (double beta : betas) {
    check_cancel(opt);
    const HairModel model = HairModel::uniform(info.eta, 0.0, beta, info.explicit_lobes, true);
    HairModel at_sigma = HairModel::uniform(info.eta, table_sigma, beta, info.explicit_lobes, info.residual);
    at_sigma.path = info.path;
    json c = {{"beta", beta}, {"beta_deg", degrees(beta)}};
    std::vector<double> total, table_total;
    std::vector<std::vector<double>> per_lobe(static_cast<std::size_t>(info.explicit_lobes + 1));
    std::vector<std::vector<double>> table_lobes(static_cast<std::size_t>(info.explicit_lobes + (info.residual ? 1 : 0)));
    for (double td : thetas) {
      const AlbedoResult r = directional_albedo(model, radians(td), 1e-10, std::max(info.energy_order, 128));
      total.push_back(r.total);
      for (std::size_t p = 0; p < r.per_lobe.size(); ++p) per_lobe[p].push_back(r.per_lobe[p]);
      if (std::abs(r.total - 1.0) > worst_direct) worst_direct = std::abs(r.total - 1.0), worst_direct_theta = td, worst_direct_beta = beta;
    }
    c["direct"] = {{"total", total}};
    for (std::size_t p = 0; p < per_lobe.size(); ++p)
      c["direct"][p < info.lobes.size() ? info.lobes[p] : std::string("residual")] = per_lobe[p];
    if (have_table) {
      // E_table(θi) = Σ_p ∫ M(β², θi, θr) e_p,table(θd) cos θr dθr with e_p from the N_p tables.
      std::vector<const Table*> tables;
      for (const auto& l : info.lobes) tables.push_back(set.find("np/" + l));
      const Table* res = info.residual ? set.find("np/residual") : nullptr;
      const std::size_t m = tables.size() + (res ? 1 : 0);
      std::vector<double> direct_at_sigma;
      std::vector<EnergyCurve> curves_e(m);
      for (std::size_t p = 0; p < m; ++p) {
        curves_e[p].values.resize(2001);
        for (std::size_t k = 0; k <= 2000; ++k) {
          const double thd = kHalfPi * static_cast<double>(k) / 2000.0;
          curves_e[p].values[k] = p < tables.size() ? (tables[p] ? table_energy(set, *tables[p], beta, table_sigma, thd) : 0.0)
                                                    : kTwoPi * res->sample({table_sigma, thd});
        }
      }
      for (double td : thetas) {
        const double ti = radians(td);
        std::vector<double> bp = {-kHalfPi, kHalfPi};
        if (std::abs(ti) < kHalfPi) bp.insert(bp.begin() + 1, -ti);
        AdaptiveOptions ao;
        ao.rel_tol = 1e-7;
        ao.max_intervals = 400;
        const AdaptiveResult r = integrate_adaptive(
            [&](double tr, std::span<double> outv) {
              const double M = longitudinal_deon(beta * beta, ti, tr) * std::cos(tr);
              const double thd = std::abs(0.5 * (tr - ti));
              for (std::size_t p = 0; p < m; ++p) outv[p] = M * curves_e[p].at(thd);
            },
            m, bp, ao);
        double tot = 0.0;
        for (std::size_t p = 0; p < m; ++p) {
          table_lobes[p].push_back(r.value[p]);
          tot += r.value[p];
        }
        table_total.push_back(tot);
        const double ref = directional_albedo(at_sigma, ti, 1e-10).total;
        direct_at_sigma.push_back(ref);
        if (std::abs(tot - ref) > worst_table) worst_table = std::abs(tot - ref), worst_table_theta = td, worst_table_beta = beta;
      }
      c["table"] = {{"total", table_total}, {"direct_at_table_sigma_a", direct_at_sigma}};
      for (std::size_t p = 0; p < table_lobes.size(); ++p)
        c["table"][p < info.lobes.size() ? info.lobes[p] : std::string("residual")] = table_lobes[p];
    }
    curves.push_back(c);
  }
  out["curves"] = curves;
  const double t = opt.thresholds.furnace_direct;
  checks.push_back(check("furnace_direct", "White furnace of the model: |E(theta_i) - 1| with sigma_a = 0, all lobes, no tilt",
                         worst_direct <= t, worst_direct, t, "<=",
                         "worst at theta_i = " + fmt(worst_direct_theta) + " deg, beta = " + fmt(degrees(worst_direct_beta)) + " deg"));
  if (have_table) {
    const double tt = opt.thresholds.furnace_table;
    checks.push_back(check("furnace_table",
                           std::string("Energy from the N_p tables (sampled) against direct evaluation, sigma_a = ") + fmt(table_sigma) +
                               (table_sigma == 0.0 && info.residual ? " (white furnace)" : ""),
                           worst_table <= tt, worst_table, tt, "<=",
                           "worst at theta_i = " + fmt(worst_table_theta) + " deg, beta = " + fmt(degrees(worst_table_beta)) + " deg"));
  } else {
    checks.push_back(skipped("furnace_table", "Energy from the N_p tables", "no generic np tables in this set"));
  }
  out["worst_direct"] = {{"deviation", worst_direct}, {"theta_i_deg", worst_direct_theta}, {"beta_deg", degrees(worst_direct_beta)}};
  out["worst_table"] = {{"deviation", worst_table}, {"theta_i_deg", worst_table_theta}, {"beta_deg", degrees(worst_table_beta)}};
  return out;
}

json truncation_section(const ModelInfo& info, std::vector<json>& checks) {
  json out;
  const auto thetas = theta_grid_deg();
  const double beta = radians(5.0);
  std::vector<double> three, four, full;
  double worst = 0.0, worst_theta = 0.0;
  for (double td : thetas) {
    const double ti = radians(td);
    three.push_back(directional_albedo(HairModel::uniform(info.eta, 0.0, beta, 3, false), ti).total);
    four.push_back(directional_albedo(HairModel::uniform(info.eta, 0.0, beta, 4, false), ti).total);
    full.push_back(directional_albedo(HairModel::uniform(info.eta, 0.0, beta, 3, true), ti).total);
    if (1.0 - three.back() > worst) worst = 1.0 - three.back(), worst_theta = td;
  }
  out = {{"theta_i_deg", thetas}, {"beta_deg", 5.0}, {"eta", info.eta}, {"R+TT+TRT", three}, {"R+TT+TRT+TRRT", four}, {"R+TT+TRT+residual", full},
         {"largest_loss", worst}, {"largest_loss_theta_i_deg", worst_theta}};
  if (std::abs(info.eta - 1.55) < 0.05) {
    const bool pass = worst > 0.12 && worst < 0.16;
    checks.push_back(check("paper_truncation", "d'Eon 2011 Fig. 5: R + TT + TRT lose close to 15% at grazing (white fiber)", pass, worst, 0.15,
                           "~", "largest loss at theta_i = " + fmt(worst_theta) + " deg; TRRT recovers " +
                                    fmt(four[std::find(thetas.begin(), thetas.end(), worst_theta) - thetas.begin()] -
                                        three[std::find(thetas.begin(), thetas.end(), worst_theta) - thetas.begin()]) +
                                    ", the residual the rest"));
  }
  return out;
}

// Marschner 2003 is not energy conserving: its E(θi) (per lobe, direct) is shown, and the same
// from the tables (the sampled N_p integrated over φ, the sampled M_p over θr) is checked against it.
json marschner_energy_section(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt, std::vector<json>& checks) {
  const MarschnerConfig& m = *info.marschner;
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
    check_cancel(opt);
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

json longitudinal_section(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt, std::vector<json>& checks) {
  (void)info;
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
  for (const Table& tb : set.tables) {
    if (tb.quantity != "M_p" || tb.axes.size() != 3 || tb.axes[0].name != "beta") continue;
    // d'Eon's tilted M (measure cos θr, tilt α of θr) or Marschner's Gaussian (measure cos²θr,
    // shift α of θh, width beta_ratio·β).
    const bool gaussian = tb.attributes.value("function", std::string()) == "gaussian";
    const double alpha = gaussian ? tb.attributes.value("alpha_theta_h", 0.0) : tb.attributes.value("alpha", 0.0);
    const double ratio = tb.attributes.value("beta_ratio", 1.0);
    const GaussianArgument argument =
        tb.attributes.value("argument", std::string("theta-h")) == "2theta-h" ? GaussianArgument::two_theta_h : GaussianArgument::theta_h;
    json tj = {{"path", tb.path()}, {"alpha", alpha}, {"curves", json::array()}};
    for (double beta : representative(tb.axes[0])) {
      std::vector<double> sampled, exact;
      for (double td : thetas) {
        const double ti = radians(td);
        AdaptiveOptions ao;
        ao.rel_tol = 1e-7;
        ao.max_intervals = 400;
        std::vector<double> bp = {-kHalfPi, kHalfPi};
        const double centre = gaussian ? 2.0 * alpha - ti : fold_inclination(-ti + alpha);
        if (std::abs(centre) < kHalfPi) bp.insert(bp.begin() + 1, centre);
        const AdaptiveResult r = integrate_adaptive(
            [&](double tr, std::span<double> o) { o[0] = tb.sample({beta, ti, tr}) * std::cos(tr) * (gaussian ? std::cos(tr) : 1.0); }, 1, bp, ao);
        sampled.push_back(r.value[0]);
        exact.push_back(gaussian ? longitudinal_energy_gaussian(ratio * beta, alpha, ti, argument).value[0]
                                 : longitudinal_energy_deon(beta * beta, alpha, ti).value[0]);
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

// ---------------------------------------------------------------------------------------------
// Accuracy where a renderer samples: random points over every table's declared domain against
// direct evaluation, relative to the local denominator of each kind (sampled_error.hpp).

// The kind of a table for the per-kind checks: "np" (the N_p tables of the lobes, also per
// material), "energy" (energies, and the residual's N_p: its energy / 2π, uniform in φ and β),
// "mp", "melanin", or "" (no check).
std::string accuracy_kind(const Table& t) {
  if (t.quantity == "N_p") return t.attributes.value("lobe", std::string()) == "residual" ? "energy" : "np";
  if (t.quantity == "energy") return "energy";
  if (t.quantity == "M_p") return "mp";
  if (t.quantity == "sigma_a" || t.quantity == "transmittance") return "melanin";
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

std::uint64_t seed_of(const std::string& path) {  // FNV-1a: the same points for a table in every run
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : path) h = (h ^ c) * 1099511628211ULL;
  return h;
}

constexpr std::size_t kDualScatteringPoints = 256;

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
  const TruthModel model{info.eta, info.path, info.explicit_lobes, info.marschner};
  const auto ds_memo = make_dual_scattering_memo();
  std::size_t done = 0;
  for (const Table& t : set.tables) {
    if (opt.progress) opt.progress("accuracy", done, set.tables.size());
    ++done;
    check_cancel(opt);
    std::string kind = accuracy_kind(t);
    auto truth = kind.empty() ? std::nullopt : table_truth(t, model, rule);
    if (!truth && (truth = dual_scattering_truth(set, t, ds_memo))) kind = "ds";
    if (!truth) continue;
    SampledErrorOptions so;
    // Dual-scattering references are slow (adaptive θr integrals of half-range energies): at most
    // kDualScatteringPoints points, the same for every table of the groups (one evaluation each).
    so.points = std::max<std::size_t>(kind == "ds" ? std::min(opt.max_points, kDualScatteringPoints) : opt.max_points, 1);
    so.seed = kind == "ds" ? seed_of("dual_scattering") : seed_of(t.path());
    so.threads = opt.threads;
    so.half_float = true;
    so.keep_points = true;
    so.cancel = opt.cancel;
    const SampledError r = measure_sampled_error(set, t, *truth, so);
    check_cancel(opt);
    json tj = {{"path", t.path()}, {"quantity", t.quantity}, {"kind", kind}, {"denominator", r.denominator}, {"dims", json::array()}};
    for (const GridAxis& a : t.axes) tj["dims"].push_back(a.name);
    if (t.attributes.contains("beta_band")) tj["beta_band"] = t.attributes["beta_band"];  // N_p in β bands (beta_bands.hpp)
    tj["off_node"] = error_stats(r.error);
    tj["off_node_half"] = error_stats(r.half);
    json at = json::object();
    for (std::size_t k = 0; k < t.axes.size(); ++k) at[t.axes[k].name] = r.worst_at[k];
    tj["worst"] = {{"at", at}, {"where", point_text(t, r.worst_at)}, {"sampled", r.worst_sampled}, {"exact", r.worst_exact},
                   {"denominator", r.worst_denominator}};
    // Per axis: the worst error among the points in each cell of the axis.
    json per_axis = json::array();
    for (std::size_t k = 0; k < t.axes.size(); ++k) {
      if (t.axes[k].count < 2 || t.axes[k].name == "channel") continue;
      const auto& cells = r.per_axis_cells[k];
      const auto mx = std::max_element(cells.begin(), cells.end());
      per_axis.push_back({{"axis", t.axes[k].name}, {"count", t.axes[k].count}, {"max_rel", *mx},
                          {"worst_cell", static_cast<int>(mx - cells.begin())}, {"cells_max_rel", cells}});
    }
    tj["per_axis"] = per_axis;
    // Heat maps of the largest relative error per pair of axes (cells of the table).
    json heat = json::array();
    for (std::size_t i = 0; i < t.axes.size(); ++i)
      for (std::size_t j = i + 1; j < t.axes.size(); ++j) {
        const GridAxis &ai = t.axes[i], &aj = t.axes[j];
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
        heat.push_back({{"x", aj.name}, {"y", ai.name}, {"x_centres", cj}, {"y_centres", ci}, {"max_rel", grid}});
      }
    tj["heatmaps"] = heat;
    out.push_back(tj);
    worst_max[kind].update(r.error.worst, t.path() + " at " + point_text(t, r.worst_at) + ": sampled " + fmt(r.worst_sampled, 4) + ", exact " +
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
    checks.push_back(check("accuracy_max_rel", "N_p tables: worst error at random points over the domain, relative to the slice's peak over phi",
                           worst_max["np"].value <= th.accuracy_max_rel, worst_max["np"].value, th.accuracy_max_rel, "<=",
                           worst_max["np"].where + words("np")));
    checks.push_back(check("accuracy_p99_rel", "N_p tables: 99th percentile of the same", worst_p99["np"].value <= th.accuracy_p99_rel,
                           worst_p99["np"].value, th.accuracy_p99_rel, "<=", worst_p99["np"].where));
  }
  const std::tuple<const char*, const char*, const char*, double> kinds[] = {
      {"energy", "accuracy_energy_max_rel", "Energy tables and the residual's N_p: worst relative error at random points over the domain",
       th.accuracy_energy_max_rel},
      {"mp", "accuracy_mp_max_rel", "M_p tables: worst error at random points, relative to the peak over theta_r", th.accuracy_mp_max_rel},
      {"melanin", "accuracy_melanin_max_rel", "Melanin tables (sigma_a, spectral transmittance): worst relative error at random points", th.accuracy_melanin_max_rel},
      {"ds", "accuracy_ds_max_rel", "Dual-scattering and mean-energy tables: worst relative error at random points", th.accuracy_ds_max_rel}};
  for (const auto& [kind, id, title, threshold] : kinds)
    if (worst_max[kind].any)
      checks.push_back(check(id, title, worst_max[kind].value <= threshold, worst_max[kind].value, threshold, "<=", worst_max[kind].where + words(kind)));
  return out;
}
// ∫ N_table dφ against the energy table, and energies against σa and θd, melanin swatches.
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
        grid[i][j] = e->get(i * th.size() + j);
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
  // Melanin swatches: the colour of light through one fiber diameter, exp(−2 σa), per concentration.
  json swatches = json::array();
  for (const char* name : {"melanin/sigma_a_deon", "melanin/transmittance_spectral"}) {
    const Table* m = set.find(name);
    if (!m || m->axes.size() != 3) continue;
    const auto ce = m->axes[0].nodes(), cp = m->axes[1].nodes();
    // The colour through one diameter: exp(−2 σa), or the tabulated transmittance over its path
    // (2 radii by default), clamped to [0, 1] out of gamut.
    const bool transmittance = m->quantity == "transmittance";
    auto colour = [&](std::size_t o) { return transmittance ? std::clamp(m->get(o), 0.0, 1.0) : std::exp(-2.0 * m->get(o)); };
    json rows = json::array();
    for (std::size_t i = 0; i < ce.size(); ++i)
      for (std::size_t j = 0; j < cp.size(); ++j) {
        const std::size_t o = (i * cp.size() + j) * 3;
        rows.push_back({{"eumelanin", ce[i]}, {"pheomelanin", cp[j]}, {"rgb", {colour(o), colour(o + 1), colour(o + 2)}}});
      }
    swatches.push_back({{"table", name}, {"swatches", rows}, {"attributes", m->attributes}});
  }
  out["melanin"] = swatches;
  return out;
}

// The model comparison for the fiber of a Marschner table set: its η, path and settings, the
// σa node nearest 0.5 (a light brown) and the middle β_R of its M_p tables.
json compare_for(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt) {
  CompareSettings s;
  s.eta = info.eta;
  s.path = info.path;
  s.marschner = *info.marschner;
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

}  // namespace

nlohmann::ordered_json validate_tables(const TableSet& set, const std::string& source, const ValidationOptions& opt) {
  if (set.tables.empty()) throw DomainError(source + ": contains no tables");
  const ModelInfo info = model_from(set);
  std::vector<json> checks;
  json report;
  report["source"] = source;
  report["validator"] = "validate-hair-luts";
  report["table_metadata"] = set.metadata;
  report["thresholds"] = opt.thresholds.to_json();
  if (opt.progress) opt.progress("sanity", 0, 6);
  report["sanity"] = sanity_section(set, info, checks);
  if (info.marschner) {
    if (opt.progress) opt.progress("energy", 1, 6);
    report["marschner_energy"] = marschner_energy_section(set, info, opt, checks);
    if (opt.progress) opt.progress("compare", 2, 6);
    report["compare"] = compare_for(set, info, opt);
  } else {
    if (opt.progress) opt.progress("white furnace", 1, 6);
    report["furnace"] = furnace_section(set, info, opt, checks);
    if (opt.progress) opt.progress("truncation", 2, 6);
    report["truncation"] = truncation_section(info, checks);
  }
  check_cancel(opt);
  if (opt.progress) opt.progress("longitudinal", 3, 6);
  report["longitudinal"] = longitudinal_section(set, info, opt, checks);
  report["accuracy"] = accuracy_section(set, info, opt, checks);
  report["absorption"] = absorption_section(set, info, opt, checks);
  report["dual_scattering"] = detail::dual_scattering_section(set, opt, checks);
  int passed = 0, failed = 0, skipped_n = 0;
  for (const json& c : checks) {
    const std::string s = c["status"].get<std::string>();
    (s == "pass" ? passed : s == "fail" ? failed : skipped_n)++;
  }
  report["summary"] = {{"status", failed == 0 ? "pass" : "fail"}, {"passed", passed}, {"failed", failed}, {"skipped", skipped_n}};
  report["checks"] = checks;
  return report;
}

}  // namespace hairlut
