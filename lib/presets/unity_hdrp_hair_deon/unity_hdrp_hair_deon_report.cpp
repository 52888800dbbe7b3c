// Preset "unity-hdrp-hair-deon" in the validator: its texels recomputed from HDRP's kernels with the exact functions
// (report/hdrp_texels.cpp).
#include "report/validate_sections.hpp"

namespace hairlut::presets::unity_hdrp_hair_deon {

const EnginePresetReport& report() {
  static const detail::validation::HdrpPresetReport r("unity-hdrp-hair-deon", hdrp::Functions::exact);
  return r;
}

}  // namespace hairlut::presets::unity_hdrp_hair_deon
