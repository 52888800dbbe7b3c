// The config's axes and per-lobe values (config_parse.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "config_parse.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/util/angles.hpp"

namespace hairlut::detail::config_parse {

double get_number(const nlohmann::json& j, const char* key, double fallback) {
  return j.contains(key) ? j.at(key).get<double>() : fallback;
}

// An angle or value axis of the config (schema-checked) to a GridAxis (semantics checked here).
GridAxis make_axis(const nlohmann::json& j, const std::string& path, const std::string& name, bool angle, double domain_lo,
                   double domain_hi, const std::string& units, const std::string& long_name) {
  GridAxis a;
  a.name = name;
  a.units = units;
  a.long_name = long_name;
  a.placement = parse_placement(j.value("placement", std::string("edges")), path + ".placement");
  const double scale = angle ? kPi / 180.0 : 1.0;
  if (j.contains("values") || j.contains("values_deg")) {
    const bool deg = j.contains("values_deg");
    a.spacing = Spacing::explicit_values;
    for (double v : j.at(deg ? "values_deg" : "values").get<std::vector<double>>()) a.values.push_back(deg ? v * scale : v);
    a.count = static_cast<int>(a.values.size());
    a.lo = a.values.front();
    a.hi = a.values.back();
    for (std::size_t i = 1; i < a.values.size(); ++i)
      if (!(a.values[i] > a.values[i - 1]))
        fail(path + (deg ? ".values_deg[" : ".values[") + std::to_string(i) + "]", "must be greater than the value before it");
  } else {
    const bool deg = j.contains("range_deg");
    const auto range = j.at(deg ? "range_deg" : "range").get<std::vector<double>>();
    const std::string rpath = path + (deg ? ".range_deg" : ".range");
    a.lo = range[0] * (deg ? scale : 1.0);
    a.hi = range[1] * (deg ? scale : 1.0);
    a.count = j.at("count").get<int>();
    a.spacing = parse_spacing(j.value("spacing", std::string("uniform")), path + ".spacing");
    if (!(range[0] < range[1]) && !(a.count == 1 && range[0] == range[1]))
      fail(rpath, "must be increasing, [low, high] with low < high (got [" + nlohmann::json(range[0]).dump() + ", " +
                      nlohmann::json(range[1]).dump() + "])");
    if (a.spacing == Spacing::log && !(a.lo > 0.0)) fail(rpath, "must be > 0 for log spacing (got " + nlohmann::json(range[0]).dump() + ")");
    if (a.placement == Placement::edges && a.count == 1 && a.lo != a.hi)
      fail(path + ".count", "must be >= 2 for edge-placed nodes spanning a range (got 1)");
  }
  const std::string used_key = j.contains("values_deg") ? ".values_deg"
                               : j.contains("values")   ? ".values"
                               : j.contains("range_deg") ? ".range_deg"
                                                         : ".range";
  if (a.lo < domain_lo - 1e-12 || a.hi > domain_hi + 1e-12) {
    std::ostringstream s;
    s.precision(6);
    if (angle)
      s << "must lie within [" << degrees(domain_lo) << ", " << degrees(domain_hi) << "] degrees (got [" << degrees(a.lo)
        << ", " << degrees(a.hi) << "] degrees)";
    else
      s << "must lie within [" << domain_lo << ", " << domain_hi << "] (got [" << a.lo << ", " << a.hi << "])";
    fail(path + used_key, s.str());
  }
  a.lo = std::max(a.lo, domain_lo);
  a.hi = std::min(a.hi, domain_hi);
  if (a.spacing == Spacing::explicit_values) {
    a.values.front() = std::max(a.values.front(), domain_lo);
    a.values.back() = std::min(a.values.back(), domain_hi);
  }
  if (j.contains("interpolation"))
    a.interpolation = parse_interpolation(j.at("interpolation").get<std::string>(), path + ".interpolation");
  if (j.contains("lo_end")) a.lo_end = parse_end(j.at("lo_end").get<std::string>(), path + ".lo_end");  // cubic end rule at lo
  // N_p depends on θd through cos θd only: the axis folds a signed θd to |θd| (and a cubic
  // interpolation mirrors its neighbours across θd = 0).
  if (name == "theta_d") a.wrap = Wrap::even;
  checked([&] { a.validate(path); });
  return a;
}

GridAxis make_phi_axis(const nlohmann::json& j, const std::string& path) {
  GridAxis a;
  a.name = "phi";
  a.units = "rad";
  a.long_name = "relative azimuth phi = phi_r - phi_i";
  a.count = j.at("count").get<int>();
  a.placement = parse_placement(j.value("placement", std::string("edges")), path + ".placement");
  a.spacing = Spacing::uniform;
  if (j.value("symmetry", std::string("even")) == "even") {
    a.wrap = Wrap::even;
    a.lo = 0.0;
    a.hi = kPi;
    if (a.count < 2 && a.placement == Placement::edges) fail(path + ".count", "must be >= 2 for edge-placed nodes (got 1)");
  } else {
    a.wrap = Wrap::periodic;
    a.lo = -kPi;
    a.hi = kPi;
  }
  if (j.contains("interpolation"))
    a.interpolation = parse_interpolation(j.at("interpolation").get<std::string>(), path + ".interpolation");
  checked([&] { a.validate(path); });
  return a;
}

// Lobe names → p, with the residual as -1.
int lobe_index(const std::string& name, int lobe_count, const std::string& path) {
  if (name == "residual") return -1;
  int p = -2;
  checked([&] { p = parse_lobe(name, path); });
  if (p >= lobe_count) fail(path, "lobe " + name + " is not among lobes.explicit");
  return p;
}

// Per-lobe values given for some lobes: lobes not listed take the nearest listed lower lobe's
// value (else the nearest higher); the residual takes its own or the highest lobe's.
void per_lobe_values(const nlohmann::json& j, const std::string& path, int lobe_count, double scale, std::vector<double>& out,
                     double& residual) {
  std::map<int, double> given;
  for (const auto& [key, value] : j.items()) given[lobe_index(key, lobe_count, path + "." + key)] = value.get<double>() * scale;
  out.assign(static_cast<std::size_t>(lobe_count), 0.0);
  for (int p = 0; p < lobe_count; ++p) {
    auto it = given.upper_bound(p);  // first key > p
    if (given.count(p)) out[static_cast<std::size_t>(p)] = given[p];
    else if (it != given.begin() && std::prev(it)->first >= 0) out[static_cast<std::size_t>(p)] = std::prev(it)->second;
    else {
      auto hi = given.lower_bound(0);
      if (hi == given.end()) fail(path, "must give a value for at least one explicit lobe");
      out[static_cast<std::size_t>(p)] = hi->second;
    }
  }
  residual = given.count(-1) ? given[-1] : out.back();
}

nlohmann::json axes_json(const std::vector<GridAxis>& axes) {
  nlohmann::json a = nlohmann::json::object();
  for (const GridAxis& g : axes)
    if (g.count > 0) a[g.name] = g.to_json();
  return a;
}


}  // namespace hairlut::detail::config_parse
