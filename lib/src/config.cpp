#include "hairlut/config.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "hairlut/angles.hpp"
#include "hairlut/error.hpp"
#include "hairlut/hair_model.hpp"
#include "hairlut/json_schema.hpp"
#include "hairlut/melanin.hpp"
#include "hairlut/version.hpp"

namespace hairlut {
namespace detail {
extern const char* const config_schema_json;  // generated from schemas/hairlut-config.schema.json
}

const char* config_schema_text() { return detail::config_schema_json; }

std::string_view to_string(NpQuadratureConfig::Method method) {
  switch (method) {
    case NpQuadratureConfig::Method::adaptive: return "adaptive";
    case NpQuadratureConfig::Method::gauss_legendre: return "gauss-legendre";
    default: return "fourier";
  }
}

namespace {

using nlohmann::json;

// Thrown inside the parser with a key path; turned into "<source>: <path>: <reason>".
struct KeyError {
  std::string path, reason;
};

[[noreturn]] void fail(const std::string& path, const std::string& reason) { throw KeyError{path, reason}; }

// Runs a library validation that throws DomainError whose message starts with the key path.
template <class F>
void checked(F&& f) {
  try {
    f();
  } catch (const DomainError& e) {
    const std::string m = e.what();
    const auto space = m.find(' ');
    fail(m.substr(0, space), space == std::string::npos ? m : m.substr(space + 1));
  }
}

double get_number(const json& j, const char* key, double fallback) {
  return j.contains(key) ? j.at(key).get<double>() : fallback;
}

// An angle or value axis of the config (schema-checked) to a GridAxis (semantics checked here).
GridAxis make_axis(const json& j, const std::string& path, const std::string& name, bool angle, double domain_lo,
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
      fail(rpath, "must be increasing, [low, high] with low < high (got [" + json(range[0]).dump() + ", " +
                      json(range[1]).dump() + "])");
    if (a.spacing == Spacing::log && !(a.lo > 0.0)) fail(rpath, "must be > 0 for log spacing (got " + json(range[0]).dump() + ")");
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

GridAxis make_phi_axis(const json& j, const std::string& path) {
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
void per_lobe_values(const json& j, const std::string& path, int lobe_count, double scale, std::vector<double>& out,
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

json axes_json(const std::vector<GridAxis>& axes) {
  json a = json::object();
  for (const GridAxis& g : axes)
    if (g.count > 0) a[g.name] = g.to_json();
  return a;
}

// The settings of model marschner2003, and the keys of the d'Eon model it has no use for.
MarschnerConfig parse_marschner(const json& doc, const json& lobes, const BakeConfig& c) {
  if (c.lobe_count > 3)
    fail("lobes.explicit", "model marschner2003 has the lobes R, TT and TRT only (got " + std::to_string(c.lobe_count) + " lobes)");
  if (lobes.contains("residual") && lobes.at("residual").get<bool>())
    fail("lobes.residual", "model marschner2003 has no residual lobe: set it to false or leave it out");
  if (lobes.contains("tilt_deg"))
    fail("lobes.tilt_deg", "does not apply to model marschner2003: its lobes are shifted by marschner.longitudinal.alpha_R_deg with Table 1's relations");
  if (lobes.contains("fold_below")) fail("lobes.fold_below", "applies to model deon2011 only");
  if (doc.contains("quadrature")) fail("quadrature", "applies to model deon2011 only (marschner2003 solves for the smooth fiber's paths)");
  const json mj = doc.value("marschner", json::object());
  MarschnerConfig m;
  m.params.eta = c.eta;
  m.params.path = c.path;
  m.params.roots = parse_marschner_roots(mj.value("roots", std::string("exact")), "marschner.roots");
  const json k = mj.value("caustic", json::object());
  m.params.caustic.k_G = get_number(k, "k_G", 0.5);
  m.params.caustic.w_c = radians(get_number(k, "w_c_deg", 15.0));
  m.params.caustic.delta_eta_prime = get_number(k, "delta_eta_prime", 0.3);
  m.params.caustic.delta_h_max = get_number(k, "delta_h_max", 0.5);
  m.params.eccentricity = get_number(mj, "eccentricity", 1.0);
  m.params.eccentric_fresnel = parse_eccentric_fresnel(mj.value("eccentric_fresnel", std::string("eta")), "marschner.eccentric_fresnel");
  const json l = mj.value("longitudinal", json::object());
  m.alpha_r = radians(get_number(l, "alpha_R_deg", -5.0));
  m.argument = l.value("argument", std::string("theta-h")) == "2theta-h" ? GaussianArgument::two_theta_h : GaussianArgument::theta_h;
  checked([&] {
    try {
      m.params.validate();
    } catch (const DomainError& e) {
      throw DomainError("marschner." + std::string(e.what()));
    }
  });
  return m;
}

// ---- tables.dual_scattering and tables.engine -------------------------------------------------

// tables.dual_scattering: axes theta_i, beta, sigma_a; lobe_scale per lobe (lobes not listed: 1).
DualScatteringTablesConfig parse_dual_scattering(const json& j, int lobe_count, bool residual) {
  DualScatteringTablesConfig d;
  const json& ax = j.at("axes");
  const std::string p = "tables.dual_scattering.axes.";
  d.axes = {make_axis(ax.at("sigma_a"), p + "sigma_a", "sigma_a", false, 0.0, 1e5, "1/radius", "absorption coefficient per unit fiber radius"),
            make_axis(ax.at("beta"), p + "beta", "beta", true, 1e-6, kPi, "rad",
                      "roughness beta: beta_m,p = beta_n,p = lobe_scale_p * beta"),
            make_axis(ax.at("theta_i"), p + "theta_i", "theta_i", true, -kHalfPi, kHalfPi, "rad", "incident inclination theta_i")};
  d.lobe_scale.assign(static_cast<std::size_t>(lobe_count) + (residual ? 1 : 0), 1.0);
  if (j.contains("lobe_scale"))
    for (const auto& [key, value] : j.at("lobe_scale").items()) {
      const int lobe = lobe_index(key, lobe_count, "tables.dual_scattering.lobe_scale." + key);
      if (lobe < 0 && !residual) fail("tables.dual_scattering.lobe_scale.residual", "is given but lobes.residual is false");
      d.lobe_scale[lobe < 0 ? d.lobe_scale.size() - 1 : static_cast<std::size_t>(lobe)] = value.get<double>();
    }
  d.density_factor = get_number(j, "density_factor", 0.7);
  return d;
}

// tables.engine: a preset of engine textures; the presets bake R, TT, TRT (and the residual).
EngineConfig parse_engine(const json& j, const std::vector<std::string>& lobe_names) {
  EngineConfig e;
  e.preset = j.at("preset").get<std::string>();
  if (j.contains("textures")) e.textures = j.at("textures").get<std::vector<std::string>>();
  e.density_factor = get_number(j, "density_factor", 0.7);
  if (j.contains("unity")) {
    if (e.preset != "unity-hdrp-hair") fail("tables.engine.unity", "applies to the unity-hdrp-hair preset only (preset is " + e.preset + ")");
    const json& u = j.at("unity");
    e.radial_smoothness = get_number(u, "radial_smoothness", e.radial_smoothness);
    e.cuticle_angle_deg = get_number(u, "cuticle_angle_deg", e.cuticle_angle_deg);
    e.attenuation_scale = get_number(u, "attenuation_scale", e.attenuation_scale);
  }
  if (lobe_names != std::vector<std::string>{"R", "TT", "TRT"}) {
    std::string got;
    for (const auto& n : lobe_names) got += (got.empty() ? "" : ", ") + n;
    fail("lobes.explicit", "must be [\"R\", \"TT\", \"TRT\"] for tables.engine (engines shade these three lobes; got [" + got + "])");
  }
  checked([&] {
    try {
      engine_preset_textures(e);
    } catch (const DomainError& err) {
      // "tables.engine.textures ..." names its key; the unknown-preset message names tables.engine.preset.
      const std::string m = err.what();
      throw DomainError(m.rfind("tables.engine", 0) == 0 ? m : "tables.engine.preset " + m);
    }
  });
  return e;
}

json dual_scattering_json(const DualScatteringTablesConfig& d) {
  return {{"axes", axes_json(d.axes)}, {"lobe_scale", d.lobe_scale}, {"density_factor", d.density_factor}};
}

json engine_json(const EngineConfig& e) {
  json j = {{"preset", e.preset}, {"textures", e.textures}, {"density_factor", e.density_factor}};
  if (e.preset == "unity-hdrp-hair")
    j["unity"] = {{"radial_smoothness", e.radial_smoothness}, {"cuticle_angle_deg", e.cuticle_angle_deg}, {"attenuation_scale", e.attenuation_scale}};
  return j;
}

BakeConfig parse_checked(const json& doc, const std::filesystem::path& base_dir) {
  BakeConfig c;
  c.name = doc.at("name").get<std::string>();
  c.description = doc.value("description", std::string());
  c.model = doc.value("model", std::string("deon2011"));
  if (c.model == "deon") c.model = "deon2011";  // short names (schema enum) → the recorded ones
  if (c.model == "marschner") c.model = "marschner2003";

  const json fiber = doc.value("fiber", json::object());
  c.eta = get_number(fiber, "eta", 1.55);
  c.path = parse_absorption_path(fiber.value("absorption_path", std::string("chord")), "fiber.absorption_path");

  const json lobes = doc.value("lobes", json::object());
  const auto names = lobes.value("explicit", c.model == "marschner2003" ? std::vector<std::string>{"R", "TT", "TRT"}
                                                                       : std::vector<std::string>{"R", "TT", "TRT", "TRRT"});
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string path = "lobes.explicit[" + std::to_string(i) + "]";
    int p = -1;
    checked([&] { p = parse_lobe(names[i], path); });
    if (p != static_cast<int>(i))
      fail(path, "must be \"" + lobe_name(static_cast<int>(i)) + "\": list the lobes R, TT, TRT, ... in order without gaps (got \"" +
                     names[i] + "\")");
  }
  c.lobe_count = static_cast<int>(names.size());
  if (doc.contains("marschner") && c.model != "marschner2003")
    fail("marschner", "applies to model \"marschner2003\" only (model is \"" + c.model + "\")");
  if (c.model == "marschner2003") c.marschner = parse_marschner(doc, lobes, c);
  c.residual = c.marschner ? false : lobes.value("residual", true);
  c.fold_below = get_number(lobes, "fold_below", 0.0);
  c.tilt.assign(static_cast<std::size_t>(c.lobe_count), 0.0);
  if (lobes.contains("tilt_deg")) {
    for (const auto& [key, value] : lobes.at("tilt_deg").items()) {
      const int p = lobe_index(key, c.lobe_count, "lobes.tilt_deg." + key);
      if (p < 0) c.residual_tilt = radians(value.get<double>());
      else c.tilt[static_cast<std::size_t>(p)] = radians(value.get<double>());
    }
  }

  const json q = doc.value("quadrature", json::object());
  const std::string method = q.value("method", std::string("fourier"));
  c.quadrature.method = method == "adaptive"         ? NpQuadratureConfig::Method::adaptive
                        : method == "gauss-legendre" ? NpQuadratureConfig::Method::gauss_legendre
                                                     : NpQuadratureConfig::Method::fourier;
  c.quadrature.order = q.value("order", 256);
  c.quadrature.variable = parse_integration_variable(q.value("variable", std::string("gamma")), "quadrature.variable");
  c.quadrature.tolerance = get_number(q, "tolerance", 1e-12);
  c.quadrature.energy_order = q.value("energy_order", 128);

  const json tables = doc.value("tables", json::object());
  if (tables.contains("np")) {
    const json& ax = tables.at("np").at("axes");
    const std::string p = "tables.np.axes.";
    // Per-material scenes take sigma_a and beta from their materials; generic tables need them.
    const bool per_material = doc.contains("scene") && doc.at("scene").value("mode", std::string("per-material")) == "per-material";
    if (c.marschner && ax.contains("beta"))
      fail(p + "beta", "model marschner2003 has no azimuthal roughness (its N_p is the smooth fiber's): remove this axis");
    if (!c.marschner && ax.contains("phi_h")) fail(p + "phi_h", "applies to model marschner2003 with an eccentric fiber only");
    for (const char* key : {"sigma_a", "beta"})
      if (!ax.contains(key) && !per_material && !(c.marschner && key == std::string("beta")))
        fail("tables.np.axes", std::string("missing required key \"") + key + "\" (needed unless scene.mode is per-material)");
    GridAxis beta_axis, sigma_axis;
    beta_axis.name = "beta", sigma_axis.name = "sigma_a";
    beta_axis.count = sigma_axis.count = 0;  // unused (per-material scene) unless given
    if (ax.contains("beta"))
      beta_axis = make_axis(ax.at("beta"), p + "beta", "beta", true, 1e-6, kPi, "rad", "azimuthal roughness beta (detector width)");
    if (ax.contains("sigma_a"))
      sigma_axis = make_axis(ax.at("sigma_a"), p + "sigma_a", "sigma_a", false, 0.0, 1e5, "1/radius",
                             "absorption coefficient per unit fiber radius");
    if (tables.at("np").contains("target_error")) {
      if (c.marschner) fail("tables.np.target_error", "applies to model deon2011 only");
      c.np_target_error = tables.at("np").at("target_error").get<double>();
    }
    const GridAxis theta_axis = make_axis(ax.at("theta_d"), p + "theta_d", "theta_d", true, 0.0, kHalfPi, "rad",
                                          "longitudinal difference angle theta_d = (theta_r - theta_i)/2");
    if (c.marschner) {
      // N_R, N_TT over (sigma_a, theta_d, phi); an eccentric TRT also over phi_h (before phi).
      c.np_axes = std::vector<GridAxis>{sigma_axis, theta_axis, make_phi_axis(ax.at("phi"), p + "phi")};
      const bool eccentric = c.marschner->params.eccentricity != 1.0;
      if (ax.contains("phi_h") && !eccentric)
        fail(p + "phi_h", "applies to an eccentric fiber only (marschner.eccentricity is 1)");
      if (eccentric) {
        const json def = {{"count", 9}, {"range_deg", {0, 90}}};
        GridAxis ph = make_axis(ax.contains("phi_h") ? ax.at("phi_h") : def, p + "phi_h", "phi_h", true, 0.0, kHalfPi, "rad",
                                "azimuthal half angle phi_h = (phi_i + phi_r)/2 from the axis where eta* = eta1* (period pi, even)");
        ph.wrap = Wrap::reflect;
        if (ph.lo != 0.0 || std::abs(ph.hi - kHalfPi) > 1e-12)
          fail(p + "phi_h", "must cover [0, 90] degrees (eta* is even in phi_h with period 180 degrees; the sampler folds phi_h into it)");
        ph.hi = kHalfPi;
        c.np_axes->insert(c.np_axes->begin() + 2, ph);
      }
    } else {
      c.np_axes = std::vector<GridAxis>{beta_axis, sigma_axis, theta_axis, make_phi_axis(ax.at("phi"), p + "phi")};
    }
    checked([&] { validate_interpolation(*c.np_axes, "tables.np"); });
    const json& np = tables.at("np");
    if (np.value("normalize", std::string("none")) == "energy") {
      if (c.marschner) fail("tables.np.normalize", "applies to model deon2011 only");
      if (per_material) fail("tables.np.normalize", "applies to generic N_p tables (not to a per-material scene)");
      c.np_normalize_energy = true;
    }
    if (np.contains("energy_axes")) {
      if (c.marschner || per_material) fail("tables.np.energy_axes", "applies to generic deon2011 N_p tables only");
      const json& ea = np.at("energy_axes");
      const std::string eq = "tables.np.energy_axes.";
      GridAxis es = sigma_axis, et = theta_axis;
      if (ea.contains("sigma_a"))
        es = make_axis(ea.at("sigma_a"), eq + "sigma_a", "sigma_a", false, 0.0, 1e5, "1/radius", "absorption coefficient per unit fiber radius");
      if (ea.contains("theta_d"))
        et = make_axis(ea.at("theta_d"), eq + "theta_d", "theta_d", true, 0.0, kHalfPi, "rad",
                       "longitudinal difference angle theta_d = (theta_r - theta_i)/2");
      if (es.lo > sigma_axis.lo || es.hi < sigma_axis.hi)
        fail(eq + "sigma_a", "must cover the N_p axis's range (the energies multiply every N_p value)");
      if (et.lo > theta_axis.lo || et.hi < theta_axis.hi)
        fail(eq + "theta_d", "must cover the N_p axis's range (the energies multiply every N_p value)");
      c.np_energy_axes = std::vector<GridAxis>{es, et};
      checked([&] { validate_interpolation(*c.np_energy_axes, "tables.np.energy_axes"); });
    }
    if (np.contains("beta_bands")) {  // β bands (beta_bands.cpp): band 0 becomes the N_p axes
      if (c.marschner || doc.contains("scene") || c.np_target_error)
        fail("tables.np.beta_bands", "applies to generic deon2011 N_p tables without a scene or target_error");
      checked([&] {
        c.np_beta_bands = parse_beta_bands(np.at("beta_bands"), ax, [&](const json& bx, const std::string& bp) {
          std::vector<GridAxis> b{make_axis(bx.at("beta"), bp + "beta", "beta", true, 1e-6, kPi, "rad", "azimuthal roughness beta (detector width)"),
                                  make_axis(bx.at("sigma_a"), bp + "sigma_a", "sigma_a", false, 0.0, 1e5, "1/radius", "absorption coefficient per unit fiber radius"),
                                  make_axis(bx.at("theta_d"), bp + "theta_d", "theta_d", true, 0.0, kHalfPi, "rad", "longitudinal difference angle theta_d = (theta_r - theta_i)/2"),
                                  make_phi_axis(bx.at("phi"), bp + "phi")};
          validate_interpolation(b, bp.substr(0, bp.size() - 1));
          return b;
        });
      });
      if (std::abs(c.np_beta_bands.front().lo() - beta_axis.lo) > 1e-12 || std::abs(c.np_beta_bands.back().hi() - beta_axis.hi) > 1e-12)
        fail("tables.np.beta_bands", "must cover tables.np.axes.beta's range from its first band's lo to its last band's hi");
      c.np_axes = c.np_beta_bands.front().axes;
    }
  }
  if (tables.contains("mp")) {
    const json& ax = tables.at("mp").at("axes");
    const std::string p = "tables.mp.axes.";
    const bool per_material = doc.contains("scene") && doc.at("scene").value("mode", std::string("per-material")) == "per-material";
    if (!ax.contains("beta") && !per_material)
      fail("tables.mp.axes", "missing required key \"beta\" (needed unless scene.mode is per-material)");
    GridAxis beta_axis;
    beta_axis.name = "beta";
    beta_axis.count = 0;  // unused (per-material scene) unless given
    if (ax.contains("beta"))
      beta_axis = make_axis(ax.at("beta"), p + "beta", "beta", true, 1e-6, kPi, "rad",
                            c.marschner ? "width beta_R of the R lobe's Gaussian (lobe p uses Table 1's beta_p = ratio_p beta_R)"
                                        : "longitudinal roughness beta, v = beta^2");
    c.mp_axes = std::vector<GridAxis>{
        beta_axis,
        make_axis(ax.at("theta_i"), p + "theta_i", "theta_i", true, -kHalfPi, kHalfPi, "rad", "incident inclination theta_i"),
        make_axis(ax.at("theta_r"), p + "theta_r", "theta_r", true, -kHalfPi, kHalfPi, "rad", "exit inclination theta_r")};
    checked([&] { validate_interpolation(*c.mp_axes, "tables.mp"); });
  }
  if (tables.contains("melanin")) {
    const json& m = tables.at("melanin");
    const std::string p = "tables.melanin.axes.";
    c.melanin_axes = std::vector<GridAxis>{
        make_axis(m.at("axes").at("eumelanin"), p + "eumelanin", "eumelanin", false, 0.0, 100.0, "1",
                  "eumelanin concentration (d'Eon 2011 / pbrt units)"),
        make_axis(m.at("axes").at("pheomelanin"), p + "pheomelanin", "pheomelanin", false, 0.0, 100.0, "1",
                  "pheomelanin concentration (d'Eon 2011 / pbrt units)")};
    c.melanin_path_length = get_number(m, "path_length", 2.0);
  }

  if (c.marschner)
    for (const char* key : {"dual_scattering", "engine"})
      if (tables.contains(key))
        fail(std::string("tables.") + key, "applies to model deon2011 only (computed from d'Eon's energy-conserving M_p and N_p)");
  if (tables.contains("dual_scattering")) c.dual_scattering = parse_dual_scattering(tables.at("dual_scattering"), c.lobe_count, c.residual);
  if (tables.contains("engine")) c.engine = parse_engine(tables.at("engine"), names);

  if (doc.contains("scene")) {
    const json& s = doc.at("scene");
    SceneConfig scene;
    scene.mode = s.value("mode", std::string("per-material")) == "restrict-generic" ? SceneConfig::Mode::restrict_generic
                                                                                 : SceneConfig::Mode::per_material;
    if (!c.np_axes) fail("scene", "needs tables.np: its theta_d and phi axes (and, for restrict-generic, sigma_a and beta counts)");
    std::set<std::string> seen;
    std::optional<SpectralMelanin> spectral;
    for (std::size_t i = 0; i < s.at("materials").size(); ++i) {
      const json& mj = s.at("materials")[i];
      const std::string path = "scene.materials[" + std::to_string(i) + "]";
      MaterialConfig m;
      m.name = mj.at("name").get<std::string>();
      if (!seen.insert(m.name).second) fail(path + ".name", "duplicates the name of an earlier material (\"" + m.name + "\")");
      if (mj.contains("melanin")) {
        const json& mel = mj.at("melanin");
        const double ce = mel.at("eumelanin").get<double>(), cp = get_number(mel, "pheomelanin", 0.0);
        m.melanin = std::array<double, 2>{ce, cp};
        m.melanin_model = mel.value("model", std::string("rgb"));
        Rgb rgb;
        if (m.melanin_model == "spectral") {
          if (!spectral) spectral = SpectralMelanin::builtin();
          rgb = spectral->sigma_a_rgb(ce, cp);
        } else {
          rgb = melanin_sigma_a_rgb(ce, cp);
        }
        m.sigma_a = {rgb.r, rgb.g, rgb.b};
      } else {
        const auto v = mj.at("sigma_a").get<std::vector<double>>();
        m.sigma_a = {v[0], v[1], v[2]};
      }
      if (c.marschner) {
        // Gaussian widths: R given, TT and TRT given or from Table 1 (β_R/2, 2β_R).
        const json& b = mj.at("beta_deg");
        if (!b.contains("R")) fail(path + ".beta_deg", "must give R for model marschner2003 (TT and TRT default to Table 1's beta_R/2 and 2 beta_R)");
        if (b.contains("residual")) fail(path + ".beta_deg.residual", "model marschner2003 has no residual lobe");
        if (mj.contains("beta_n_deg")) fail(path + ".beta_n_deg", "applies to model deon2011 only (marschner2003 has no azimuthal roughness)");
        for (const auto& [key, value] : b.items()) lobe_index(key, c.lobe_count, path + ".beta_deg." + key);
        const MarschnerLobes table1 = c.marschner->lobes(radians(b.at("R").get<double>()));
        for (int lobe = 0; lobe < c.lobe_count; ++lobe)
          m.beta_m.push_back(b.contains(lobe_name(lobe)) ? radians(b.at(lobe_name(lobe)).get<double>()) : table1.beta[lobe]);
        m.beta_n = m.beta_m;
        scene.materials.push_back(std::move(m));
        continue;
      }
      per_lobe_values(mj.at("beta_deg"), path + ".beta_deg", c.lobe_count, kPi / 180.0, m.beta_m, m.residual_beta_m);
      if (mj.contains("beta_n_deg"))
        per_lobe_values(mj.at("beta_n_deg"), path + ".beta_n_deg", c.lobe_count, kPi / 180.0, m.beta_n, m.residual_beta_n);
      else
        m.beta_n = m.beta_m, m.residual_beta_n = m.residual_beta_m;
      scene.materials.push_back(std::move(m));
    }
    c.scene = std::move(scene);
  }
  if (!c.np_axes && !c.mp_axes && !c.melanin_axes && !c.dual_scattering && !c.engine)
    fail("tables", "must ask for at least one table (np, mp, melanin, dual_scattering or engine)");

  if (doc.contains("validate")) c.validate_thresholds = doc.at("validate").value("thresholds", json::object());
  const json& out = doc.at("output");
  std::filesystem::path dir = out.value("directory", std::string("."));
  c.output.directory = dir.is_absolute() ? dir : (base_dir / dir).lexically_normal();
  c.output.basename = out.at("basename").get<std::string>();
  for (const auto& f : out.at("formats")) (f == "hdf5" ? c.output.hdf5 : c.output.exr) = true;
  const json h5 = out.value("hdf5", json::object());
  c.output.hdf5_double = h5.value("precision", std::string("float32")) == "float64";
  c.output.hdf5_deflate = h5.value("compression", 6);
  const json exr = out.value("exr", json::object());
  c.output.exr_half = exr.value("precision", std::string("float")) == "half";
  c.output.exr_compression = exr.value("compression", std::string("zip"));

  // Normalized form: every default filled in, angles in radians, keys sorted (nlohmann::json).
  json n;
  n["name"] = c.name;
  n["description"] = c.description;
  n["model"] = c.model;
  n["fiber"] = {{"eta", c.eta}, {"absorption_path", to_string(c.path)}};
  if (c.marschner) {
    n["lobes"] = {{"explicit", names}, {"residual", false}};
    n["marschner"] = marschner_json(*c.marschner);
  } else {
    json tilt = json::object();
    for (int p = 0; p < c.lobe_count; ++p) tilt[lobe_name(p)] = c.tilt[static_cast<std::size_t>(p)];
    tilt["residual"] = c.residual_tilt;
    n["lobes"] = {{"explicit", names}, {"residual", c.residual}, {"fold_below", c.fold_below}, {"tilt", tilt}};
    n["quadrature"] = {{"method", to_string(c.quadrature.method)},
                       {"order", c.quadrature.order},
                       {"variable", to_string(c.quadrature.variable)},
                       {"tolerance", c.quadrature.tolerance},
                       {"energy_order", c.quadrature.energy_order}};
  }
  json t = json::object();
  if (c.np_axes) {
    t["np"] = {{"axes", axes_json(*c.np_axes)}};
    if (c.np_target_error) t["np"]["target_error"] = *c.np_target_error;
    if (c.np_normalize_energy) t["np"]["normalize"] = "energy";
    if (c.np_energy_axes) t["np"]["energy_axes"] = axes_json(*c.np_energy_axes);
    if (!c.np_beta_bands.empty()) t["np"]["beta_bands"] = beta_bands_json(c.np_beta_bands);
  }
  if (c.mp_axes) t["mp"] = {{"axes", axes_json(*c.mp_axes)}};
  if (c.melanin_axes) t["melanin"] = {{"axes", axes_json(*c.melanin_axes)}, {"path_length", c.melanin_path_length}};
  if (c.dual_scattering) t["dual_scattering"] = dual_scattering_json(*c.dual_scattering);
  if (c.engine) t["engine"] = engine_json(*c.engine);
  n["tables"] = t;
  if (c.scene) {
    json mats = json::array();
    for (const MaterialConfig& m : c.scene->materials) {
      json mj = {{"name", m.name}, {"sigma_a", m.sigma_a}, {"beta_m", m.beta_m}, {"beta_n", m.beta_n},
                 {"residual_beta_m", m.residual_beta_m}, {"residual_beta_n", m.residual_beta_n}};
      if (m.melanin) mj["melanin"] = {{"eumelanin", (*m.melanin)[0]}, {"pheomelanin", (*m.melanin)[1]}, {"model", m.melanin_model}};
      mats.push_back(mj);
    }
    n["scene"] = {{"mode", c.scene->mode == SceneConfig::Mode::per_material ? "per-material" : "restrict-generic"},
                  {"materials", mats}};
  }
  json formats = json::array();
  if (c.output.hdf5) formats.push_back("hdf5");
  if (c.output.exr) formats.push_back("exr");
  n["output"] = {{"basename", c.output.basename},
                 {"formats", formats},
                 {"hdf5", {{"precision", c.output.hdf5_double ? "float64" : "float32"}, {"compression", c.output.hdf5_deflate}}},
                 {"exr", {{"precision", c.output.exr_half ? "half" : "float"}, {"compression", c.output.exr_compression}}}};
  // The validation thresholds travel with the tables (the stored config), so that a file is judged
  // by the thresholds it was baked with.
  if (c.validate_thresholds.is_object() && !c.validate_thresholds.empty()) n["validate"] = {{"thresholds", c.validate_thresholds}};
  c.normalized = n;
  c.hash = fnv1a64_hex(n.dump() + "\nhairlut " + kVersion);
  return c;
}

}  // namespace

nlohmann::json marschner_json(const MarschnerConfig& m) {
  const CausticParams& k = m.params.caustic;
  return {{"roots", to_string(m.params.roots)},
          {"caustic", {{"k_G", k.k_G}, {"w_c", k.w_c}, {"delta_eta_prime", k.delta_eta_prime}, {"delta_h_max", k.delta_h_max}}},
          {"eccentricity", m.params.eccentricity},
          {"eccentric_fresnel", to_string(m.params.eccentric_fresnel)},
          {"longitudinal", {{"alpha_R", m.alpha_r}, {"argument", m.argument == GaussianArgument::theta_h ? "theta-h" : "2theta-h"},
                            {"relations", "alpha_TT = -alpha_R/2, alpha_TRT = -3 alpha_R/2, beta_TT = beta_R/2, beta_TRT = 2 beta_R (Table 1)"}}}};
}

MarschnerConfig marschner_from_json(const nlohmann::json& j, double eta, AbsorptionPath path) {
  MarschnerConfig m;
  try {
    m.params.eta = eta;
    m.params.path = path;
    m.params.roots = parse_marschner_roots(j.at("roots").get<std::string>(), "marschner.roots");
    const auto& k = j.at("caustic");
    m.params.caustic.k_G = k.at("k_G").get<double>();
    m.params.caustic.w_c = k.at("w_c").get<double>();
    m.params.caustic.delta_eta_prime = k.at("delta_eta_prime").get<double>();
    m.params.caustic.delta_h_max = k.at("delta_h_max").get<double>();
    m.params.eccentricity = j.at("eccentricity").get<double>();
    m.params.eccentric_fresnel = parse_eccentric_fresnel(j.at("eccentric_fresnel").get<std::string>(), "marschner.eccentric_fresnel");
    const auto& l = j.at("longitudinal");
    m.alpha_r = l.at("alpha_R").get<double>();
    const std::string arg = l.at("argument").get<std::string>();
    if (arg != "theta-h" && arg != "2theta-h") throw DomainError("marschner.longitudinal.argument must be theta-h or 2theta-h (got \"" + arg + "\")");
    m.argument = arg == "theta-h" ? GaussianArgument::theta_h : GaussianArgument::two_theta_h;
  } catch (const nlohmann::json::exception& e) {
    throw DomainError(std::string("marschner settings malformed (") + e.what() + ")");
  }
  try {
    m.params.validate();
  } catch (const DomainError& e) {
    throw DomainError("marschner." + std::string(e.what()));
  }
  return m;
}

BakeConfig parse_config(const nlohmann::json& document, const std::string& source, const std::filesystem::path& base_dir) {
  static_assert(sizeof(char) == 1);
  const JsonSchema schema(nlohmann::json::parse(config_schema_text()));
  const auto violations = schema.validate(document, 1);
  if (!violations.empty()) throw ConfigError(source + ": " + violations.front().message);
  try {
    return parse_checked(document, base_dir);
  } catch (const KeyError& e) {
    throw ConfigError(source + ": " + e.path + ": " + e.reason);
  } catch (const DomainError& e) {
    throw ConfigError(source + ": " + e.what());
  } catch (const nlohmann::json::exception& e) {
    // The schema should make this unreachable; keep the message one line anyway.
    throw ConfigError(source + ": " + e.what());
  }
}

BakeConfig load_config(const std::filesystem::path& file) {
  const std::string source = file.string();
  // A config is a small file: refuse directories and devices (/dev/zero never ends), and stop
  // reading past kMaxConfigBytes (a pipe is read up to that bound).
  constexpr std::uintmax_t kMaxConfigBytes = std::uintmax_t{16} << 20;
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (status.type() == std::filesystem::file_type::directory) throw ConfigError(source + ": is a directory, not a config file");
  if (!ec && status.type() != std::filesystem::file_type::regular && status.type() != std::filesystem::file_type::fifo &&
      status.type() != std::filesystem::file_type::not_found)
    throw ConfigError(source + ": not a regular file or pipe (a config is a JSON file)");
  if (const auto bytes = std::filesystem::file_size(file, ec); !ec && bytes > kMaxConfigBytes)
    throw ConfigError(source + ": config file too large (" + std::to_string(bytes) + " bytes; at most 16 MiB)");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ConfigError(source + ": cannot open config file (" + std::string(std::strerror(errno)) + ")");
  std::string text;
  std::vector<char> block(1 << 16);
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    text.append(block.data(), static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxConfigBytes) throw ConfigError(source + ": config file too large (more than 16 MiB)");
  }
  if (in.bad()) throw ConfigError(source + ": cannot read config file");
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::out_of_range& e) {
    throw ConfigError(source + ": invalid JSON: a number is out of range (" + std::string(e.what()) + ")");
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is the offset of the error; turn it into line:column.
    const std::string& s = text;
    std::size_t line = 1, col = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < s.size(); ++i) {
      if (s[i] == '\n') ++line, col = 1;
      else ++col;
    }
    std::string what = e.what();
    const auto pos = what.find("syntax error");
    if (pos != std::string::npos) what = what.substr(pos);
    throw ConfigError(source + ":" + std::to_string(line) + ":" + std::to_string(col) + ": invalid JSON: " + what);
  }
  std::filesystem::path base = file.parent_path();
  if (base.empty()) base = ".";
  return parse_config(doc, source, base);
}

}  // namespace hairlut
