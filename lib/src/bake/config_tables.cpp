// The config's table kinds (config_parse.hpp): tables.np, tables.mp, the scene's
// materials, model marschner2003's settings, tables.dual_scattering and tables.engine.
#include <array>
#include <cmath>
#include <optional>
#include <set>
#include <string>

#include "config_parse.hpp"
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
  // A β axis with model marschner2003, and φh with model deon2011: refused by the schema.
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
  const GridAxis theta_axis = make_axis(ax.at("theta_d"), p + "theta_d", "theta_d", true, 0.0, kHalfPi, "rad",
                                        "longitudinal difference angle theta_d = (theta_r - theta_i)/2");
  if (c.marschner) {
    // N_R, N_TT over (sigma_a, theta_d, phi); an eccentric TRT also over phi_h (before phi).
    c.np_axes = std::vector<GridAxis>{sigma_axis, theta_axis, make_phi_axis(ax.at("phi"), p + "phi")};
    const bool eccentric = c.marschner->params.eccentricity != 1.0;
    if (ax.contains("phi_h") && !eccentric)
      fail(p + "phi_h", "applies to an eccentric fiber only (marschner.eccentricity is 1)");
    if (eccentric) {
      const nlohmann::json def = {{"count", 9}, {"range_deg", {0, 90}}};
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
    if (c.marschner || doc.contains("scene") || c.np_target_error)
      fail("tables.np.beta_bands", "applies to generic deon2011 N_p tables without a scene or target_error");
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
                          c.marschner ? "width beta_R of the R lobe's Gaussian (lobe p uses Table 1's beta_p = ratio_p beta_R)"
                                      : "longitudinal roughness beta, v = beta^2");
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
    if (c.marschner) {
      // Gaussian widths: R given, TT and TRT given or from Table 1 (β_R/2, 2β_R).
      // R present, no residual and no beta_n_deg: the schema's rules of model marschner2003.
      const nlohmann::json& b = mj.at("beta_deg");
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


// The settings of model marschner2003.
MarschnerConfig parse_marschner(const nlohmann::json& doc, const BakeConfig& c) {
  // At most R, TT and TRT, no residual, tilts, fold_below or quadrature: the schema's rules of model
  // marschner2003 (its allOf), applied before this runs.
  const nlohmann::json mj = doc.value("marschner", nlohmann::json::object());
  MarschnerConfig m;
  m.params.eta = c.eta;
  m.params.path = c.path;
  m.params.roots = parse_marschner_roots(mj.value("roots", std::string("exact")), "marschner.roots");
  const nlohmann::json k = mj.value("caustic", nlohmann::json::object());
  m.params.caustic.k_G = get_number(k, "k_G", 0.5);
  // At least 0.5 degrees by the schema: a narrower caustic is finer than any table's phi spacing,
  // and the validator's integration over it grows without bound as it narrows (1e-10 degrees:
  // over ten minutes).
  m.params.caustic.w_c = radians(get_number(k, "w_c_deg", 15.0));
  m.params.caustic.delta_eta_prime = get_number(k, "delta_eta_prime", 0.3);
  m.params.caustic.delta_h_max = get_number(k, "delta_h_max", 0.5);
  m.params.eccentricity = get_number(mj, "eccentricity", 1.0);
  m.params.eccentric_fresnel = parse_eccentric_fresnel(mj.value("eccentric_fresnel", std::string("eta")), "marschner.eccentric_fresnel");
  const nlohmann::json l = mj.value("longitudinal", nlohmann::json::object());
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
  if (j.contains("unity")) {
    if (e.preset != "unity-hdrp-hair") fail("tables.engine.unity", "applies to the unity-hdrp-hair preset only (preset is " + e.preset + ")");
    const nlohmann::json& u = j.at("unity");
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

nlohmann::json dual_scattering_json(const DualScatteringTablesConfig& d) {
  return {{"axes", axes_json(d.axes)}, {"lobe_scale", d.lobe_scale}, {"density_factor", d.density_factor}};
}

nlohmann::json engine_json(const EngineConfig& e) {
  nlohmann::json j = {{"preset", e.preset}, {"textures", e.textures}, {"density_factor", e.density_factor}};
  if (e.preset == "unity-hdrp-hair")
    j["unity"] = {{"radial_smoothness", e.radial_smoothness}, {"cuticle_angle_deg", e.cuticle_angle_deg}, {"attenuation_scale", e.attenuation_scale}};
  return j;
}

}  // namespace hairlut::detail::config_parse
