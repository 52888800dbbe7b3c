// The texels of Unity HDRP's three textures recomputed from HDRP's kernels (hdrp_kernels.hpp), for
// the presets of lib/presets/unity_hdrp_hair*/ (their <name>_report.cpp).
#include <cmath>

#include "hairlut/bake/hdrp_kernels.hpp"
#include "validate_sections.hpp"

namespace hairlut::detail::validation {

std::string hdrp_texels(const EngineTexture& t, const EngineTableSpec& spec, int per_axis, hdrp::Functions fn, const ValidationOptions& opt,
                        const EnginePresetReport::Compare& compare) {
  constexpr double kTol = 1e-9;  // the preset's quadrature is relative 1e-10
  const int Z = spec.axes[0].count, Y = spec.axes[1].count, X = spec.axes[2].count;
  const std::vector<double> nz = spec.axes[0].nodes(), ny = spec.axes[1].nodes(), nx = spec.axes[2].nodes();
  std::string definition;
  if (t.group == "unity/longitudinal") {
    definition = "HDRP ComputeLongitudinalScattering at every texel";
    for (int z = 0; z < Z; ++z) {
      check_cancel(opt);
      for (int y = 0; y < Y; ++y)
        for (int x = 0; x < X; ++x) {
          const auto m = hdrp::longitudinal_texel(std::sin(nx[static_cast<std::size_t>(x)]), std::sin(ny[static_cast<std::size_t>(y)]),
                                                  nz[static_cast<std::size_t>(z)], fn);
          for (int c = 0; c < 3; ++c) compare(x, y, z, c, m[static_cast<std::size_t>(c)], kTol, 0.0);
        }
    }
  } else if (t.group == "unity/attenuation") {
    definition = "HDRP ComputeAttenuationForward/Backward (exact integrals) at every texel";
    std::vector<double> sin_t = ny;
    for (double& s : sin_t) s = std::sin(s);
    std::vector<double> front, back;
    hdrp::attenuation_table(nx, sin_t, nz, front, back, 1e-10, fn);
    for (int z = 0; z < Z; ++z)
      for (int y = 0; y < Y; ++y)
        for (int x = 0; x < X; ++x) {
          const std::size_t i = (static_cast<std::size_t>(z) * static_cast<std::size_t>(Y) + static_cast<std::size_t>(y)) * static_cast<std::size_t>(X) +
                                static_cast<std::size_t>(x);
          compare(x, y, z, 0, front[i], kTol, 0.0);
          compare(x, y, z, 1, back[i], kTol, 0.0);
        }
  } else if (t.group == "unity/azimuthal") {
    definition = "HDRP ComputeAzimuthalScattering (exact integral over h) at " + std::to_string(per_axis) + "^3 texels";
    for (int z : texel_spread(Z, per_axis)) {
      check_cancel(opt);
      for (int y : texel_spread(Y, per_axis))
        for (int x : texel_spread(X, per_axis))
          for (int c = 0; c < 3; ++c)
            compare(x, y, z, c,
                    hdrp::azimuthal_texel(c, nx[static_cast<std::size_t>(x)], ny[static_cast<std::size_t>(y)], nz[static_cast<std::size_t>(z)], 1e-10, fn),
                    kTol, 0.0);
    }
  }
  return definition;
}

}  // namespace hairlut::detail::validation
