// Preset "unity-hdrp-hair-deon": HDRP's three hair textures on HDRP's axes, texel placement and
// encodings, with the exact functions in place of HDRP's approximations (docs/presets/unity-hdrp-hair.md;
// bake/hdrp_preset.hpp): for an engine team that wants HDRP's layout with d'Eon's values.
#include "bake/hdrp_preset.hpp"

namespace hairlut::presets::unity_hdrp_hair_deon {
extern const char* const schema_json;  // schema.json, embedded by the build

const EnginePreset& engine_preset() {
  static const detail::HdrpPreset preset("unity-hdrp-hair-deon", hdrp::Functions::exact, "unity-deon-", schema_json);
  return preset;
}

}  // namespace hairlut::presets::unity_hdrp_hair_deon
