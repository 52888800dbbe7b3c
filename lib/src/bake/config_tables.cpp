// The config's table kinds (config_parse.hpp): tables.np, tables.mp, the scene's
// materials, model marschner2003's settings, tables.dual_scattering and tables.engine.
#include <array>
#include <cmath>
#include <optional>
#include <set>
#include <string>

#include "config_parse.hpp"
#include "hairlut/bake/engine_preset.hpp"
#include "hairlut/bake/model_kind.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/physics/melanin.hpp"
#include "hairlut/util/angles.hpp"

namespace hairlut::detail::config_parse {

namespace {

// tables.np.energy_axes: sigma_a and theta_d of the energy and residual tables (each defaults to the
// N_p axis), covering the N_p axes' ranges.
std::vector<GridAxis> energy_axes(const nlohmann::json& ea, const GridAxis& sigma, const GridAxis& theta) {
  const std::string eq = "tables.np.energy_axes.";
  GridAxis es = sigma, et = theta;
  if (ea.contains("sigma_a"))
    es = make_axis(ea.at("sigma_a"), eq + "sigma_a", "sigma_a", false, 0.0, 1e5, "1/radius", "absorption coefficient per unit fiber radius");
  if (ea.contains("theta_d"))
    et = make_axis(ea.at("theta_d"), eq + "theta_d", "theta_d", true, 0.0, kHalfPi, "rad",
                   "longitudinal difference angle theta_d = (theta_r - theta_i)/2");
  if (es.lo > sigma.lo || es.hi < sigma.hi) fail(eq + "sigma_a", "must cover the N_p axis's range (the energies multiply every N_p value)");
  if (et.lo > theta.lo || et.hi < theta.hi) fail(eq + "theta_d", "must cover the N_p axis's range (the energies multiply every N_p value)");
  std::vector<GridAxis> axes{es, et};
  checked([&] { validate_interpolation(axes, "tables.np.energy_axes"); });
  return axes;
}

// tables.np with representation "fourier": the β range (no nodes: β is exact), the σa and θd axes
// of the coefficients, the truncation tolerance; no φ axis (φ is exact), no bands or shape.
void parse_fourier_np(const nlohmann::json& doc, const nlohmann::json& np, BakeConfig& c) {
  const nlohmann::json& ax = np.at("axes");
  const std::string p = "tables.np.axes.";
  const std::string r = "tables.np.representation";
  // Model marschner2003 with fourier: refused by the schema (its allOf states each model's rules).
  if (doc.contains("scene")) fail(r, "fourier applies to generic tables (not to a scene)");
  for (const char* key : {"beta_bands", "normalize"})
    if (np.contains(key)) fail(std::string("tables.np.") + key, "does not apply to representation fourier (beta and phi are exact)");
  if (ax.contains("phi")) fail(p + "phi", "does not apply to representation fourier (phi is exact): remove this axis");
  for (const char* key : {"beta", "sigma_a", "theta_d"})
    if (!ax.contains(key)) fail("tables.np.axes", std::string("missing required key \"") + key + "\" (representation fourier)");
  if (c.quadrature.method != NpQuadratureConfig::Method::fourier)
    fail("quadrature.method", "must be fourier for tables.np.representation fourier (its coefficients are the Fourier method's C_n)");
  FourierNpConfig f;
  // β: a range only; its lower end fixes the terms stored, the range is what the tables are validated over.
  const nlohmann::json& b = ax.at("beta");
  const bool deg = b.contains("range_deg");
  const auto range = b.at(deg ? "range_deg" : "range").get<std::vector<double>>();
  nlohmann::json bj = {{deg ? "range_deg" : "range", range}, {"count", range[0] == range[1] ? 1 : 2}, {"spacing", "log"}};
  const GridAxis beta = make_axis(bj, p + "beta", "beta", true, 1e-6, kPi, "rad", "azimuthal roughness beta (detector width)");
  f.beta_lo = beta.lo, f.beta_hi = beta.hi;
  const GridAxis sigma = make_axis(ax.at("sigma_a"), p + "sigma_a", "sigma_a", false, 0.0, 1e5, "1/radius", "absorption coefficient per unit fiber radius");
  const GridAxis theta = make_axis(ax.at("theta_d"), p + "theta_d", "theta_d", true, 0.0, kHalfPi, "rad",
                                   "longitudinal difference angle theta_d = (theta_r - theta_i)/2");
  if (sigma.spacing != Spacing::uniform && sigma.spacing != Spacing::sqrt) fail(p + "sigma_a.spacing", "must be uniform or sqrt for representation fourier");
  if (theta.spacing != Spacing::uniform && theta.spacing != Spacing::cos) fail(p + "theta_d.spacing", "must be uniform or cos for representation fourier");
  if (sigma.interpolation == Interpolation::geometric || theta.interpolation == Interpolation::geometric)
    fail(p + (sigma.interpolation == Interpolation::geometric ? "sigma_a" : "theta_d") + ".interpolation",
         "must be linear or cubic for representation fourier (the coefficients change sign)");
  f.axes = {theta, sigma};
  const nlohmann::json fj = np.value("fourier", nlohmann::json::object());
  f.tolerance = get_number(fj, "tolerance", 1e-4);  // (0, 0.1]: the schema's bound
  c.np_fourier = f;
  if (np.contains("energy_axes")) c.np_energy_axes = energy_axes(np.at("energy_axes"), sigma, theta);
}

}  // namespace

void parse_np_tables(const nlohmann::json& doc, const nlohmann::json& tables, BakeConfig& c) {
  const nlohmann::json& np_json = tables.at("np");
  if (np_json.contains("representation"))
    c.np_representation = np_json.at("representation").get<std::string>() == "fourier" ? NpRepresentation::fourier : NpRepresentation::tensor;
  if (np_json.contains("fourier") && c.np_representation != NpRepresentation::fourier)
    fail("tables.np.fourier", "applies to representation fourier only (set tables.np.representation to \"fourier\")");
  if (np_json.contains("target_error")) c.np_target_error = np_json.at("target_error").get<double>();  // deon2011 only: the schema
  if (np_json.contains("target_points")) {
    if (!c.np_target_error) fail("tables.np.target_points", "applies with tables.np.target_error only");
    c.np_target_points = np_json.at("target_points").get<std::size_t>();  // [256, 1e7]: the schema's bound
  }
  if (c.np_representation == NpRepresentation::fourier) return parse_fourier_np(doc, np_json, c);
  const nlohmann::json& ax = tables.at("np").at("axes");
  const std::string p = "tables.np.axes.";
  // Per-material scenes take sigma_a and beta from their materials; generic tables need them.
  const bool per_material = doc.contains("scene") && doc.at("scene").value("mode", std::string("per-material")) == "per-material";
  // Every model's N_p has σa (unless a per-material scene gives it), θd and φ; the model adds its
  // own axes (d'Eon's β, an eccentric Marschner fiber's φh) and orders them.
  if (!ax.contains("sigma_a") && !per_material)
    fail("tables.np.axes", "missing required key \"sigma_a\" (needed unless scene.mode is per-material)");
  SharedNpAxes shared;
  shared.sigma_a.name = "sigma_a";
  shared.sigma_a.count = 0;  // unused (per-material scene) unless given
  if (ax.contains("sigma_a"))
    shared.sigma_a = make_axis(ax.at("sigma_a"), p + "sigma_a", "sigma_a", false, 0.0, 1e5, "1/radius",
                               "absorption coefficient per unit fiber radius");
  shared.theta_d = make_axis(ax.at("theta_d"), p + "theta_d", "theta_d", true, 0.0, kHalfPi, "rad",
                             "longitudinal difference angle theta_d = (theta_r - theta_i)/2");
  shared.phi = make_phi_axis(ax.at("phi"), p + "phi");
  shared.per_material = per_material;
  c.np_axes = c.model_kind().np_axes(ax, p, shared, c);
  const GridAxis& sigma_axis = shared.sigma_a;
  const GridAxis& theta_axis = shared.theta_d;
  checked([&] { validate_interpolation(*c.np_axes, "tables.np"); });
  const nlohmann::json& np = tables.at("np");
  if (np.value("normalize", std::string("none")) == "energy") {
    if (per_material) fail("tables.np.normalize", "applies to generic N_p tables (not to a per-material scene)");
    c.np_normalize_energy = true;
  }
  if (np.contains("energy_axes")) {
    if (per_material) fail("tables.np.energy_axes", "applies to generic deon2011 N_p tables only");
    c.np_energy_axes = energy_axes(np.at("energy_axes"), sigma_axis, theta_axis);
  }
  if (np.contains("beta_bands")) {  // β bands (beta_bands.cpp): band 0 becomes the N_p axes
    // Another model's tables: refused by its schema rules.
    if (doc.contains("scene") || c.np_target_error)
      fail("tables.np.beta_bands", "applies to generic deon2011 N_p tables without a scene or target_error");
    const GridAxis beta_axis = c.np_axes->front();  // deon2011's (β, σa, θd, φ)
    checked([&] {
      c.np_beta_bands = parse_beta_bands(np.at("beta_bands"), ax, [&](const nlohmann::json& bx, const std::string& bp) {
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

void parse_mp_tables(const nlohmann::json& doc, const nlohmann::json& tables, BakeConfig& c) {
  const nlohmann::json& ax = tables.at("mp").at("axes");
  const std::string p = "tables.mp.axes.";
  const bool per_material = doc.contains("scene") && doc.at("scene").value("mode", std::string("per-material")) == "per-material";
  if (!ax.contains("beta") && !per_material)
    fail("tables.mp.axes", "missing required key \"beta\" (needed unless scene.mode is per-material)");
  GridAxis beta_axis;
  beta_axis.name = "beta";
  beta_axis.count = 0;  // unused (per-material scene) unless given
  if (ax.contains("beta"))
    beta_axis = make_axis(ax.at("beta"), p + "beta", "beta", true, 1e-6, kPi, "rad",
                          c.model_kind().mp_beta_meaning());
  c.mp_axes = std::vector<GridAxis>{
      beta_axis,
      make_axis(ax.at("theta_i"), p + "theta_i", "theta_i", true, -kHalfPi, kHalfPi, "rad", "incident inclination theta_i"),
      make_axis(ax.at("theta_r"), p + "theta_r", "theta_r", true, -kHalfPi, kHalfPi, "rad", "exit inclination theta_r")};
  checked([&] { validate_interpolation(*c.mp_axes, "tables.mp"); });
}

void parse_scene(const nlohmann::json& doc, BakeConfig& c) {
  const nlohmann::json& s = doc.at("scene");
  SceneConfig scene;
  scene.mode = s.value("mode", std::string("per-material")) == "restrict-generic" ? SceneConfig::Mode::restrict_generic
                                                                               : SceneConfig::Mode::per_material;
  if (!c.np_axes) fail("scene", "needs tables.np: its theta_d and phi axes (and, for restrict-generic, sigma_a and beta counts)");
  std::set<std::string> seen;
  std::optional<SpectralMelanin> spectral;
  for (std::size_t i = 0; i < s.at("materials").size(); ++i) {
    const nlohmann::json& mj = s.at("materials")[i];
    const std::string path = "scene.materials[" + std::to_string(i) + "]";
    MaterialConfig m;
    m.name = mj.at("name").get<std::string>();
    if (!seen.insert(m.name).second) fail(path + ".name", "duplicates the name of an earlier material (\"" + m.name + "\")");
    if (mj.contains("melanin")) {
      const nlohmann::json& mel = mj.at("melanin");
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
    c.model_kind().material_roughness(mj, path, c, m);
    scene.materials.push_back(std::move(m));
  }
  c.scene = std::move(scene);
}


// ---- tables.dual_scattering and tables.engine -------------------------------------------------

// tables.dual_scattering: axes theta_i, beta, sigma_a; lobe_scale per lobe (lobes not listed: 1).
DualScatteringTablesConfig parse_dual_scattering(const nlohmann::json& j, int lobe_count, bool residual) {
  DualScatteringTablesConfig d;
  const nlohmann::json& ax = j.at("axes");
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
EngineConfig parse_engine(const nlohmann::json& j, const std::vector<std::string>& lobe_names) {
  EngineConfig e;
  e.preset = j.at("preset").get<std::string>();
  if (j.contains("textures")) e.textures = j.at("textures").get<std::vector<std::string>>();
  e.density_factor = get_number(j, "density_factor", 0.7);
  // The preset's own keys (lib/presets/<preset>/; another preset's keys: its schema rules).
  checked([&] { e.settings = engine_preset(e.preset).settings(j); });
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

nlohmann::json dual_scattering_json(const DualScatteringTablesConfig& d) {
  return {{"axes", axes_json(d.axes)}, {"lobe_scale", d.lobe_scale}, {"density_factor", d.density_factor}};
}

nlohmann::json engine_json(const EngineConfig& e) {
  nlohmann::json j = {{"preset", e.preset}, {"textures", e.textures}, {"density_factor", e.density_factor}};
  j.update(e.settings);
  return j;
}

}  // namespace hairlut::detail::config_parse
