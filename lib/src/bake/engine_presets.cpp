#include "hairlut/bake/engine_presets.hpp"

#include "hairlut/bake/engine_preset.hpp"

#include <algorithm>
#include <cmath>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;

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

// Unreal's roughness parameterisation (docs/presets/unreal-hair-strands.md, to be confirmed by a
// licensee): B = {r², r²/2, 2r²}; lobes beyond TRT and the residual take TRT's. The metadata record
// it by name and the validator rebuilds it, so it is a mapping here, not a part of the preset's folder.
constexpr double kUnrealScale[3] = {1.0, 0.5, 2.0};
double lobe_constant(const double (&c)[3], std::size_t p) { return c[std::min<std::size_t>(p, 2)]; }

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

GridAxis texel_axis(std::string name, std::string units, std::string long_name, Spacing spacing, double lo, double hi, int count) {
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

const EnginePreset& engine_preset(std::string_view name) {
  std::string names;
  for (const EnginePreset* p : engine_presets()) {
    if (p->name() == name) return *p;
    names += (names.empty() ? "\"" : ", \"") + std::string(p->name()) + "\"";
  }
  throw DomainError("tables.engine.preset must be one of " + names + " (got \"" + std::string(name) + "\")");
}

std::vector<std::string> engine_preset_names() {
  std::vector<std::string> names;
  for (const EnginePreset* p : engine_presets()) names.emplace_back(p->name());
  return names;
}

std::vector<std::string> engine_preset_texture_names(const std::string& preset) { return engine_preset(preset).texture_names(); }

std::vector<EngineTableSpec> engine_preset_tables(const EngineConfig& c, bool residual) { return engine_preset(c.preset).tables(residual); }

std::vector<EngineTexture> engine_preset_textures(const EngineConfig& c) {
  const EnginePreset& preset = engine_preset(c.preset);
  const std::vector<std::string> names = preset.texture_names();
  for (const std::string& t : c.textures)
    if (std::find(names.begin(), names.end(), t) == names.end()) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      throw DomainError("tables.engine.textures \"" + t + "\" is not a texture of " + c.preset + " (its textures: " + list + ")");
    }
  std::vector<EngineTexture> out;
  for (EngineTexture& t : preset.textures())
    if (c.textures.empty() || std::find(c.textures.begin(), c.textures.end(), t.name) != c.textures.end()) out.push_back(std::move(t));
  return out;
}

}  // namespace hairlut
