#include "hairlut/bake/engine_presets.hpp"

#include <algorithm>
#include <cmath>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;

constexpr const char* kUnreal = "unreal-hair-strands";
constexpr const char* kUnity = "unity-hdrp-hair";
constexpr const char* kUnityDeon = "unity-hdrp-hair-deon";  // HDRP's textures with exact functions (hdrp::Functions::exact)

std::string_view parameter_name(RoughnessParameter p) {
  switch (p) {
    case RoughnessParameter::unreal: return "unreal-roughness";
    default: return "beta";
  }
}

std::string_view parameter_name(AbsorptionParameter p) {
  switch (p) {
    case AbsorptionParameter::unreal_base_color: return "unreal-base-color";
    default: return "sigma_a";
  }
}

// The unreal-hair-strands model (docs/presets/unreal-hair-strands.md, to be confirmed by a licensee):
// B = {r², r²/2, 2r²}, Alpha = {−2·0.035, 0.035, 4·0.035}; lobes beyond TRT and the residual take TRT's.
constexpr double kUnrealScale[3] = {1.0, 0.5, 2.0};
constexpr double kUnrealShift[3] = {-0.07, 0.035, 0.14};
double lobe_constant(const double (&c)[3], std::size_t p) { return c[std::min<std::size_t>(p, 2)]; }

GridAxis make_axis(std::string name, std::string units, std::string long_name, Spacing spacing, double lo, double hi, int count) {
  GridAxis a;
  a.name = std::move(name);
  a.units = std::move(units);
  a.long_name = std::move(long_name);
  a.spacing = spacing;
  a.placement = Placement::centers;
  a.wrap = Wrap::clamp;
  a.lo = lo;
  a.hi = hi;
  a.count = count;
  a.validate("preset axis " + a.name);
  return a;
}

}  // namespace

HairModel table_model(const RoughnessMapping& roughness, const AbsorptionMapping& absorption, double eta, AbsorptionPath path,
                      double roughness_x, double absorption_x) {
  const std::vector<LobeParams> lp = roughness.lobes_at(roughness_x);
  HairModel m;
  m.eta = eta;
  m.path = path;
  m.sigma_a = absorption.sigma_a(absorption_x);
  m.lobes.assign(lp.begin(), lp.begin() + roughness.lobes);
  if (roughness.residual) m.residual = lp.back();
  return m;
}

std::vector<LobeParams> RoughnessMapping::lobes_at(double x) const {
  if (!std::isfinite(x)) throw_domain_error("roughness", "must be finite", x);
  const std::size_t n = static_cast<std::size_t>(lobes) + (residual ? 1 : 0);
  if (tilt.size() != n) throw DomainError("roughness mapping: tilt must list " + std::to_string(n) + " lobes");
  std::vector<LobeParams> out(n);
  for (std::size_t p = 0; p < n; ++p) {
    LobeParams& l = out[p];
    l.alpha = tilt[p];
    switch (parameter) {
      case RoughnessParameter::beta: {
        require_positive("beta", x);
        const double s = p < scale.size() ? scale[p] : 1.0;
        l.beta_m = l.beta_n = s * x;
        break;
      }
      case RoughnessParameter::unreal: {
        require_in_range("unreal roughness", x, 0.0, 1.0, "must lie in [0, 1]");
        const double r = std::clamp(x, 1.0 / 255.0, 1.0);  // the preset's roughness clamp
        l.beta_m = l.beta_n = lobe_constant(kUnrealScale, p) * r * r;
        break;
      }
    }
  }
  return out;
}

json RoughnessMapping::describe() const {
  json j;
  j["parameter"] = parameter_name(parameter);
  switch (parameter) {
    case RoughnessParameter::beta:
      j["formula"] = "beta_m,p = beta_n,p = scale_p * x (x in radians)";
      break;
    case RoughnessParameter::unreal:
      j["formula"] = "r = clamp(x, 1/255, 1); beta_m,p = beta_n,p = {1, 1/2, 2} r^2 for R, TT, TRT (the unreal-hair-strands preset's B, "
                     "the width of a Gaussian in sin(theta_i) + sin(theta_r), i.e. in theta_i + theta_r as d'Eon's beta); "
                     "tilt {-0.07, 0.035, 0.14} rad (angles measured towards the "
                     "strand tangent T); lobes beyond TRT and the residual take TRT's";
      break;
  }
  j["lobes"] = lobes;
  j["residual"] = residual;
  j["scale"] = scale;
  j["tilt"] = tilt;
  return j;
}

RoughnessMapping RoughnessMapping::from_json(const nlohmann::json& j) {
  RoughnessMapping m;
  try {
    const std::string p = j.at("parameter").get<std::string>();
    m.parameter = p == "unreal-roughness"             ? RoughnessParameter::unreal
                  : p == "beta"                       ? RoughnessParameter::beta
                                                      : throw DomainError("roughness mapping: unknown parameter \"" + p + "\"");
    m.lobes = j.at("lobes").get<int>();
    m.residual = j.at("residual").get<bool>();
    m.scale = j.at("scale").get<std::vector<double>>();
    m.tilt = j.at("tilt").get<std::vector<double>>();
  } catch (const nlohmann::json::exception& e) {
    throw DomainError(std::string("roughness mapping: malformed (") + e.what() + ")");
  }
  if (m.lobes < 1 || m.lobes > 64) throw DomainError("roughness mapping: lobes must lie in [1, 64]");
  return m;
}

bool RoughnessMapping::uniform() const {
  if (parameter != RoughnessParameter::beta) return false;
  for (double a : tilt)
    if (a != 0.0) return false;
  for (double s : scale)
    if (s != 1.0) return false;
  return true;
}

double AbsorptionMapping::sigma_a(double x) const {
  switch (parameter) {
    case AbsorptionParameter::unreal_base_color:
      require_in_range("unreal base colour", x, 0.0, 1.0, "must lie in [0, 1]");
      return -0.25 * std::log(std::max(x, 1e-4));  // the unreal-hair-strands preset's colour mapping
    default:
      require_non_negative("sigma_a", x);
      return x;
  }
}

json AbsorptionMapping::describe() const {
  json j;
  j["parameter"] = parameter_name(parameter);
  switch (parameter) {
    case AbsorptionParameter::unreal_base_color:
      j["formula"] = "sigma_a = -ln(max(c, 1e-4)) / 4 per unit radius (the unreal-hair-strands preset's mapping: a chord of two radii "
                     "at normal incidence transmits sqrt(c); to be confirmed against the engine)";
      break;
    default: j["formula"] = "sigma_a = x (per unit fiber radius)"; break;
  }
  return j;
}

AbsorptionMapping AbsorptionMapping::from_json(const nlohmann::json& j) {
  AbsorptionMapping m;
  try {
    const std::string p = j.at("parameter").get<std::string>();
    m.parameter = p == "unreal-base-color"     ? AbsorptionParameter::unreal_base_color
                  : p == "sigma_a"             ? AbsorptionParameter::sigma_a
                                               : throw DomainError("absorption mapping: unknown parameter \"" + p + "\"");
  } catch (const nlohmann::json::exception& e) {
    throw DomainError(std::string("absorption mapping: malformed (") + e.what() + ")");
  }
  return m;
}

const std::vector<std::string>& engine_preset_names() {
  static const std::vector<std::string> names = {kUnreal, kUnity, kUnityDeon};
  return names;
}

std::vector<std::string> engine_preset_texture_names(const std::string& preset) {
  if (preset == kUnreal) return {"dual-scattering", "mean-energy"};
  if (preset == kUnity || preset == kUnityDeon) return {"attenuation", "azimuthal", "longitudinal"};
  throw DomainError("tables.engine.preset must be \"unreal-hair-strands\", \"unity-hdrp-hair\" or \"unity-hdrp-hair-deon\" (got \"" + preset + "\")");
}

std::vector<EngineTableSpec> engine_preset_tables(const EngineConfig& c, bool residual) {
  std::vector<EngineTableSpec> out;
  const std::size_t n = 3 + (residual ? 1 : 0);
  if (c.preset == kUnreal) {
    // The preset's layout (to be confirmed against the engine, docs/presets/unreal-hair-strands.md):
    // a 64 (X: sin theta) x 64 (Y: roughness) x 16 (Z: absorption) texture,
    // each texel at its centre, (i + 1/2)/count; Z is u = sqrt(BaseColor) (BaseColor = u^2).
    EngineTableSpec s;
    s.axes = {make_axis("base_color", "1", "hair Base Color c (linear); texel z at sqrt(c) = (z + 1/2)/16", Spacing::sqrt, 0.0, 1.0, 16),
              make_axis("roughness", "1", "hair Roughness; texel y at (y + 1/2)/64", Spacing::uniform, 0.0, 1.0, 64),
              make_axis("theta_i", "rad", "incident inclination (sin = dot(L, T)); texel x at sin(theta_i) = (x + 1/2)/64",
                        Spacing::sin, 0.0, kHalfPi, 64)};
    s.roughness.parameter = RoughnessParameter::unreal;
    s.roughness.lobes = 3;
    s.roughness.residual = residual;
    for (std::size_t p = 0; p < n; ++p) s.roughness.tilt.push_back(lobe_constant(kUnrealShift, p));
    s.absorption.parameter = AbsorptionParameter::unreal_base_color;
    s.absorption_axis = "base_color", s.roughness_axis = "roughness", s.theta_axis = "theta_i";
    s.group = "unreal/dual_scattering", s.kind = "dual_scattering";
    out.push_back(s);
    s.group = "unreal/mean_energy", s.kind = "mean_energy";
    out.push_back(s);
    return out;
  }
  if (c.preset == kUnity || c.preset == kUnityDeon) {
    // HairMultipleScatteringPreIntegration.compute: every kernel evaluates texel id at UVW = (id + 0.5) / 64
    // and HDRP samples the 3D textures with normalised coordinates, so every axis is texel-centred.
    // Attenuation (ComputeAttenuationForward/Backward): X perceptual smoothness, Y sin(theta) of the
    // light (the shader passes |sin theta_i|), Z diffuse colour of one channel.
    EngineTableSpec s;
    s.axes = {make_axis("diffuse_color", "1", "HDRP hair diffuse colour d (one channel); texel z at (z + 1/2)/64", Spacing::uniform, 0.0, 1.0, 64),
              make_axis("theta_i", "rad", "inclination of the light to the normal plane (sin = dot(T, L), T root to tip; the shader "
                        "passes |sin|); texel y at sin(theta_i) = (y + 1/2)/64", Spacing::sin, 0.0, kHalfPi, 64),
              make_axis("smoothness", "1", "HDRP hair perceptual smoothness; texel x at (x + 1/2)/64", Spacing::uniform, 0.0, 1.0, 64)};
    s.group = "unity/attenuation", s.kind = "hdrp_attenuation";
    s.absorption_axis = "diffuse_color", s.roughness_axis = "smoothness", s.theta_axis = "theta_i";
    out.push_back(s);
    // Azimuthal (ComputeAzimuthalScattering): X phi = 4pi u - 2pi, Y cos(theta_d), Z radial roughness,
    // read by GetRoughenedAzimuthalScatteringDistribution with the same coordinates.
    EngineTableSpec a;
    a.axes = {make_axis("radial_roughness", "1", "HDRP perceptual radial (azimuthal) roughness beta_n; texel z at (z + 1/2)/64", Spacing::uniform, 0.0, 1.0, 64),
              make_axis("cos_theta_d", "1", "cos(theta_d); texel y at (y + 1/2)/64", Spacing::uniform, 0.0, 1.0, 64),
              make_axis("phi", "rad", "relative azimuth phi over [-2pi, 2pi]; texel x at (phi + 2pi)/4pi = (x + 1/2)/64", Spacing::uniform,
                        -kTwoPi, kTwoPi, 64)};
    a.group = "unity/azimuthal", a.kind = "hdrp_azimuthal";
    a.roughness_axis = "radial_roughness", a.theta_axis = "cos_theta_d";
    out.push_back(a);
    // Longitudinal (ComputeLongitudinalScattering): X sin theta_i = 2u - 1, Y sin theta_o = 2u - 1, Z the
    // longitudinal roughness beta_m fed to LongitudinalVarianceFromBeta (GetEnergyConservingLongitudinalScattering
    // samples X = 0.5 + 0.5 sin theta_i, Y = 0.5 + 0.5 sin theta_o, Z = perceptual roughness).
    EngineTableSpec m;
    m.axes = {make_axis("roughness", "1", "HDRP hair perceptual roughness beta_m (Chiang's longitudinal roughness); texel z at (z + 1/2)/64",
                        Spacing::uniform, 0.0, 1.0, 64),
              make_axis("theta_o", "rad", "inclination of the view; texel y at 0.5 + 0.5 sin(theta_o) = (y + 1/2)/64", Spacing::sin, -kHalfPi, kHalfPi, 64),
              make_axis("theta_i", "rad", "inclination of the light; texel x at 0.5 + 0.5 sin(theta_i) = (x + 1/2)/64", Spacing::sin, -kHalfPi, kHalfPi, 64)};
    m.group = "unity/longitudinal", m.kind = "hdrp_longitudinal";
    m.roughness_axis = "roughness", m.theta_axis = "theta_i";
    out.push_back(m);
    return out;
  }
  engine_preset_texture_names(c.preset);  // throws the one-line error
  return out;
}

std::vector<EngineTexture> engine_preset_textures(const EngineConfig& c) {
  const std::vector<std::string> names = engine_preset_texture_names(c.preset);
  for (const std::string& t : c.textures)
    if (std::find(names.begin(), names.end(), t) == names.end()) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      throw DomainError("tables.engine.textures \"" + t + "\" is not a texture of " + c.preset + " (its textures: " + list + ")");
    }
  if ((c.preset == kUnity || c.preset == kUnityDeon) && (c.radial_smoothness != 0.7 || c.cuticle_angle_deg != 3.0 || c.attenuation_scale != 0.31830988618379067))
    throw DomainError("tables.engine.unity: unity-hdrp-hair reproduces HDRP's kernels, which fix radial smoothness 0.7, cuticle angle "
                      "3 deg and the attenuation's 1/pi; remove the block");
  auto wanted = [&](const std::string& n) { return c.textures.empty() || std::find(c.textures.begin(), c.textures.end(), n) != c.textures.end(); };
  std::vector<EngineTexture> out;
  auto table = [](std::string path, double scale, bool saturate) { return EngineChannel{std::move(path), 0.0, scale, saturate}; };
  auto constant = [](double v) { return EngineChannel{"", v, 1.0, false}; };
  if (c.preset == kUnreal) {
    EngineTexture t;
    t.preset = c.preset;
    t.tiles_per_row = 4;  // a 4 x 4 atlas, four tiles per row
    t.flip_y = false;
    t.engine_format = "RGBA16F, 64 x 64 x 16 (X sin theta, Y roughness, Z sqrt(BaseColor)); layout to be confirmed by a licensee";
    if (wanted("dual-scattering")) {
      t.name = "dual-scattering", t.file_suffix = "unreal-dual-scattering", t.group = "unreal/dual_scattering";
      t.channels[0] = table("unreal/dual_scattering/a_f", 1.0, true);
      t.channels[1] = table("unreal/dual_scattering/a_b", 1.0, true);
      t.channels[2] = constant(0.0);
      t.channels[3] = constant(1.0);
      t.description = "dual-scattering LUT: .x = forward average attenuation a_f, .y = backward a_b, per colour channel, from which "
                      "the shader builds Zinke's A_b, delta_b, sigma_b (docs/presets/unreal-hair-strands.md lists what to confirm)";
      out.push_back(t);
    }
    if (wanted("mean-energy")) {
      t.name = "mean-energy", t.file_suffix = "unreal-mean-energy", t.group = "unreal/mean_energy";
      t.channels[0] = table("unreal/mean_energy/E_R", 1.0, true);
      t.channels[1] = table("unreal/mean_energy/E_TT", 1.0, true);
      t.channels[2] = table("unreal/mean_energy/E_TRT", 1.0, true);
      t.channels[3] = constant(1.0);
      t.description = "mean-energy LUT: .xyz = E_R, E_TT, E_TRT, the directional albedo of each lobe (docs/presets/unreal-hair-strands.md "
                      "lists what to confirm)";
      out.push_back(t);
    }
    return out;
  }
  EngineTexture t;
  t.preset = c.preset;
  // 8 x 8 cells of 64 x 64 (a 512 x 512 image, within Unity's 2048 import limit), read by Unity's
  // flipbook import (Texture Shape 3D, Columns 8, Rows 8) as slices in reading order; Unity's
  // texture origin is the bottom-left corner, so texel row 0 is the bottom row of its cell.
  t.tiles_per_row = 8;
  t.flip_y = true;
  const std::string variant = c.preset == kUnityDeon ? "unity-deon-" : "unity-";
  if (wanted("attenuation")) {
    t.name = "attenuation", t.file_suffix = variant + "attenuation", t.group = "unity/attenuation";
    t.channel_count = 2;
    t.channels[0] = table("unity/attenuation/front", 1.0, false);
    t.channels[1] = table("unity/attenuation/back", 1.0, false);
    t.channels[2] = constant(0.0);
    t.channels[3] = constant(0.0);
    t.engine_format = "R16G16_SFloat (RG half), 64 x 64 x 64; HDRP reads .xy only";
    t.description = "_HairAttenuation (HDRenderPipelineRuntimeTextures.hairAttenuationLUT): ComputeDualScattering samples (X min(smoothness, 0.6), "
                    "Y |sin theta_i|, Z diffuse colour) once per colour channel and reads .x = front and .y = back average attenuation "
                    "as ComputeAttenuationForward/Backward define them";
    out.push_back(t);
  }
  t.channel_count = 4;
  t.engine_format = "R16G16B16A16_SFloat (RGBA half), 64 x 64 x 64";
  if (wanted("azimuthal")) {
    t.name = "azimuthal", t.file_suffix = variant + "azimuthal", t.group = "unity/azimuthal";
    t.channels[0] = table("unity/azimuthal/N_R", 1.0, false);
    t.channels[1] = table("unity/azimuthal/N_TT", 1.0, false);
    t.channels[2] = table("unity/azimuthal/N_TRT", 1.0, false);
    t.channels[3] = constant(1.0);
    t.description = "_HairAzimuthalScattering (hairAzimuthalScatteringLUT): GetRoughenedAzimuthalScatteringDistribution reads .xyz = N_R, "
                    "N_TT, N_TRT, the trimmed-logistic azimuthal distributions averaged over h (ComputeAzimuthalScattering)";
    out.push_back(t);
  }
  if (wanted("longitudinal")) {
    t.name = "longitudinal", t.file_suffix = variant + "longitudinal", t.group = "unity/longitudinal";
    t.channels[0] = table("unity/longitudinal/M_R", 1.0, false);
    t.channels[1] = table("unity/longitudinal/M_TT", 1.0, false);
    t.channels[2] = table("unity/longitudinal/M_TRT", 1.0, false);
    t.channels[3] = constant(1.0);
    t.description = "_HairLongitudinalScattering (hairLongitudinalScatteringLUT): GetEnergyConservingLongitudinalScattering (Marschner "
                    "cinematic) reads .xyz = M_R, M_TT, M_TRT as ComputeLongitudinalScattering defines them";
    out.push_back(t);
  }
  return out;
}

}  // namespace hairlut
