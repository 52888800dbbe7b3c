// Preset "unity-hdrp-hair": Unity HDRP's three hair LUTs as its pre-integration kernels compute
// them (docs/presets/unity-hdrp-hair.md; the layout and the bake are HDRP's, bake/hdrp_preset.hpp).
// Its own config keys are the "unity" block, which states the constants HDRP's kernels fix.
#include "bake/hdrp_preset.hpp"
#include "hairlut/bake/table_kind.hpp"  // config_error

namespace hairlut::presets::unity_hdrp_hair {
extern const char* const schema_json;  // schema.json, embedded by the build

namespace {

// ConfigureFiberSurface's perceptual radial smoothness, the kernels' cuticle angle (cuticleAngle −3°
// negated by Hair.hlsl) and the attenuation kernel's final 1/π.
constexpr double kRadialSmoothness = 0.7, kCuticleAngleDeg = 3.0, kAttenuationScale = 0.31830988618379067;

class Preset final : public detail::HdrpPreset {
 public:
  Preset() : HdrpPreset("unity-hdrp-hair", hdrp::Functions::hdrp, "unity-", schema_json) {}
  nlohmann::json settings(const nlohmann::json& engine) const override {
    const nlohmann::json u = engine.value("unity", nlohmann::json::object());
    return {{"unity",
             {{"radial_smoothness", u.value("radial_smoothness", kRadialSmoothness)},
              {"cuticle_angle_deg", u.value("cuticle_angle_deg", kCuticleAngleDeg)},
              {"attenuation_scale", u.value("attenuation_scale", kAttenuationScale)}}}};
  }
  // The block may only restate HDRP's constants: the kernels reproduced here fix them.
  void check(const BakeConfig& c) const override {
    HdrpPreset::check(c);
    const nlohmann::json& u = c.engine->settings.at("unity");
    if (u.at("radial_smoothness").get<double>() != kRadialSmoothness || u.at("cuticle_angle_deg").get<double>() != kCuticleAngleDeg ||
        u.at("attenuation_scale").get<double>() != kAttenuationScale)
      config_error("tables.engine.unity", "unity-hdrp-hair reproduces HDRP's kernels, which fix radial smoothness 0.7, cuticle angle 3 deg and "
                                          "the attenuation's 1/pi; remove the block");
  }
};

}  // namespace

const EnginePreset& engine_preset() {
  static const Preset preset;
  return preset;
}

}  // namespace hairlut::presets::unity_hdrp_hair
