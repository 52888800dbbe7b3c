#include "hairlut/report/validate.hpp"

// half's conversions inline (bit shifts, the same values as libImath's table): this layer links no
// OpenEXR or Imath library.
#define IMATH_HALF_NO_LOOKUP_TABLE
#include <Imath/half.h>

#include <omp.h>

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <set>

#include "hairlut/util/angles.hpp"
#include "hairlut/physics/azimuthal_np.hpp"
#include "hairlut/bake/bake.hpp"
#include "hairlut/report/compare.hpp"
#include "hairlut/bake/config.hpp"
#include "hairlut/physics/directional_albedo.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/util/hash.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "hairlut/physics/marschner.hpp"
#include "hairlut/bake/sampled_error.hpp"
#include "hairlut/bake/table_truth.hpp"
#include "hairlut/tables/fourier_tables.hpp"
#include "hairlut/bake/table_kind.hpp"
#include "hairlut/report/model_kind_report.hpp"
#include "hairlut/report/table_kind_report.hpp"
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
      {"accuracy_ds_max_rel", &ValidationThresholds::accuracy_ds_max_rel},
      {"energy_consistency", &ValidationThresholds::energy_consistency},
      {"ds_furnace", &ValidationThresholds::ds_furnace},
      {"ds_consistency", &ValidationThresholds::ds_consistency},
      {"ds_accuracy", &ValidationThresholds::ds_accuracy}};
  return f;
}

ValidationThresholds::ValidationThresholds() {
  for (const TableKind* k : table_kinds()) kinds[std::string(k->threshold().name)] = k->threshold().value;
}

void ValidationThresholds::set(const std::string& name, double value) {
  const auto it = fields().find(name);
  const auto kind = kinds.find(name);
  if (it == fields().end() && kind == kinds.end()) {
    std::map<std::string, double> all = kinds;
    for (const auto& [k, v] : fields()) all[k] = 0.0;
    std::string known;
    for (const auto& [k, v] : all) known += (known.empty() ? "" : ", ") + k;
    throw DomainError("threshold " + name + " is unknown (known: " + known + ")");
  }
  require_positive("threshold " + name, value);
  if (it != fields().end()) this->*(it->second) = value;
  else kind->second = value;
}

double ValidationThresholds::get(const std::string& name) const {
  if (const auto it = fields().find(name); it != fields().end()) return this->*(it->second);
  if (const auto kind = kinds.find(name); kind != kinds.end()) return kind->second;
  throw DomainError("threshold " + name + " is unknown");
}

nlohmann::ordered_json ValidationThresholds::to_json() const {
  std::map<std::string, double> all = kinds;  // every threshold by name, in name order
  for (const auto& [k, v] : fields()) all[k] = this->*v;
  nlohmann::ordered_json j;
  for (const auto& [k, v] : all) j[k] = v;
  return j;
}

namespace detail::validation {

bool may_be_negative(const Table& t) {
  // Shifts are signed; spectral transmittance is negative out of gamut; a sampling prefix
  // integrates an unclamped interpolant; cosine-series coefficients are signed.
  return t.quantity == "shift" || t.quantity == "transmittance" || t.quantity == "sampling_cdf" || is_fourier_table(t);
}

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
  info.kind = find_model_kind(info.model);
  if (!info.kind) throw DomainError("table metadata: unknown model \"" + info.model + "\"");
  info.settings = info.kind->from_metadata(m, info.eta, info.path);
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

std::string fmt(double v, int digits) {
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

}  // namespace detail::validation

namespace {

using namespace detail::validation;

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
      else if (v < 0.0 && !may_be_negative(t)) ++tneg;
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
      // N_p of a lobe: its tensor table, or its Fourier table (the representation the set records).
      const bool fourier = set.metadata.value("np_representation", std::string()) == "fourier";
      const std::string n_p = (fourier ? std::string(kFourierGroup) + "/" : std::string("np/")) + l;
      if ((l != "residual" || fourier) && !set.find(n_p)) missing.push_back(n_p);
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

}  // namespace

nlohmann::ordered_json validate_tables(const TableSet& set, const std::string& source, const ValidationOptions& given) {
  if (set.tables.empty()) throw DomainError(source + ": contains no tables");
  ValidationOptions opt = given;
  if (!opt.seed) {
    std::random_device device;
    opt.seed = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  }
  const ModelInfo info = model_from(set);
  std::vector<json> checks;
  json report;
  report["source"] = source;
  report["validator"] = "validate-hair-luts";
  report["table_metadata"] = set.metadata;
  report["thresholds"] = opt.thresholds.to_json();
  if (opt.progress) opt.progress("sanity", 0, 6);
  report["sanity"] = sanity_section(set, info, checks);
  for (const ModelKindReport* m : model_kind_reports())  // lib/models/
    if (m->name() == info.model) m->energy_sections(set, info, opt, checks, report);
  check_cancel(opt);
  // In a part after the first, only what reads the tables in parts is checked again.
  const bool rest = !opt.part || opt.part->index == 0;
  if (opt.progress) opt.progress("longitudinal", 3, 6);
  if (rest) report["longitudinal"] = longitudinal_section(set, info, opt, checks);
  report["accuracy_search"] = {{"seed", *opt.seed},
                               {"search", opt.search},
                               {"random_points", opt.max_points},
                               {"stages", opt.search ? json::array({"random", "edges", "corners", "features", "grazing", "climb"}) : json::array({"random"})},
                               {"note", "each table's points come from this seed mixed with the table's path; --seed repeats the run"}};
  report["accuracy"] = accuracy_section(set, info, opt, checks);
  report["absorption"] = absorption_section(set, info, opt, checks);
  if (rest) {
    for (const TableKindReport* k : table_kind_reports())  // lib/kinds/
      if (json s = k->section(set); !s.is_null()) report[std::string(k->name())] = std::move(s);
    report["sampling_data"] = sampling_data_section(set, checks);
    report["dual_scattering"] = detail::dual_scattering_section(set, opt, checks);
  }
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

