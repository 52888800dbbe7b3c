// Preset "unreal-hair-strands": the dual-scattering and mean-energy LUTs of Unreal Engine's hair
// strands in the layout docs/presets/unreal-hair-strands.md describes (to be confirmed by a
// licensee): a 64 (X: sin θ) × 64 (Y: roughness) × 16 (Z: √BaseColor) texture, texel-centred, with
// Unreal's roughness and BaseColor mappings. Both groups are dual_scattering and mean_energy groups,
// which bake_engine.cpp bakes for every preset: the preset has no kinds of its own.
#include <algorithm>

#include "hairlut/bake/engine_preset.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut::presets::unreal_hair_strands {
extern const char* const schema_json;  // schema.json, embedded by the build

namespace {

// The unreal-hair-strands model (docs/presets/unreal-hair-strands.md, to be confirmed by a licensee):
// B = {r², r²/2, 2r²}, Alpha = {−2·0.035, 0.035, 4·0.035}; lobes beyond TRT and the residual take TRT's.
constexpr double kUnrealShift[3] = {-0.07, 0.035, 0.14};
double lobe_constant(const double (&c)[3], std::size_t p) { return c[std::min<std::size_t>(p, 2)]; }

class Preset final : public EnginePreset {
 public:
  std::string_view name() const override { return "unreal-hair-strands"; }
  std::string_view schema() const override { return schema_json; }
  std::vector<std::string> texture_names() const override { return {"dual-scattering", "mean-energy"}; }
  nlohmann::json settings(const nlohmann::json&) const override { return nlohmann::json::object(); }
  void check(const BakeConfig&) const override {}

  std::vector<EngineTableSpec> tables(bool residual) const override {
    std::vector<EngineTableSpec> out;
    const std::size_t n = 3 + (residual ? 1 : 0);
    // The preset's layout (to be confirmed against the engine, docs/presets/unreal-hair-strands.md):
    // a 64 (X: sin theta) x 64 (Y: roughness) x 16 (Z: absorption) texture,
    // each texel at its centre, (i + 1/2)/count; Z is u = sqrt(BaseColor) (BaseColor = u^2).
    EngineTableSpec s;
    s.axes = {texel_axis("base_color", "1", "hair Base Color c (linear); texel z at sqrt(c) = (z + 1/2)/16", Spacing::sqrt, 0.0, 1.0, 16),
              texel_axis("roughness", "1", "hair Roughness; texel y at (y + 1/2)/64", Spacing::uniform, 0.0, 1.0, 64),
              texel_axis("theta_i", "rad", "incident inclination (sin = dot(L, T)); texel x at sin(theta_i) = (x + 1/2)/64",
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

  std::vector<EngineTexture> textures() const override {
    auto table = [](std::string path, double scale, bool saturate) { return EngineChannel{std::move(path), 0.0, scale, saturate}; };
    auto constant = [](double v) { return EngineChannel{"", v, 1.0, false}; };
    std::vector<EngineTexture> out;
    EngineTexture t;
    t.preset = std::string(name());
    t.tiles_per_row = 4;  // a 4 x 4 atlas, four tiles per row
    t.flip_y = false;
    t.engine_format = "RGBA16F, 64 x 64 x 16 (X sin theta, Y roughness, Z sqrt(BaseColor)); layout to be confirmed by a licensee";
    {
      t.name = "dual-scattering", t.file_suffix = "unreal-dual-scattering", t.group = "unreal/dual_scattering";
      t.channels[0] = table("unreal/dual_scattering/a_f", 1.0, true);
      t.channels[1] = table("unreal/dual_scattering/a_b", 1.0, true);
      t.channels[2] = constant(0.0);
      t.channels[3] = constant(1.0);
      t.description = "dual-scattering LUT: .x = forward average attenuation a_f, .y = backward a_b, per colour channel, from which "
                      "the shader builds Zinke's A_b, delta_b, sigma_b (docs/presets/unreal-hair-strands.md lists what to confirm)";
      out.push_back(t);
    }
    {
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

  void bake(const BakeConfig&, const EngineTableSpec& group, const BakeOptions&, TableSet&, BakeReport&) const override {
    throw DomainError("internal: unreal-hair-strands has no table kind " + group.kind + " of its own");
  }
  GroupSize group_size(const EngineTableSpec&) const override { return {}; }
};

}  // namespace

const EnginePreset& engine_preset() {
  static const Preset preset;
  return preset;
}

}  // namespace hairlut::presets::unreal_hair_strands
