// Preset "unity-hdrp-hair" in the validator: its texels recomputed from HDRP's kernels
// (report/hdrp_texels.cpp).
#include "report/validate_sections.hpp"

namespace hairlut::presets::unity_hdrp_hair {

const EnginePresetReport& report() {
  static const detail::validation::HdrpPresetReport r("unity-hdrp-hair", hdrp::Functions::hdrp);
  return r;
}

}  // namespace hairlut::presets::unity_hdrp_hair
