// Preset "unreal-hair-strands" in the validator: its texels are the mean-energy and dual-scattering
// quantities of dual_scattering() at the texel's model (Unreal's roughness and BaseColor mappings).
#include <algorithm>
#include <cmath>

#include "hairlut/physics/dual_scattering.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/report/engine_preset_report.hpp"
#include "hairlut/util/error.hpp"
#include "report/validate_sections.hpp"

namespace hairlut::presets::unreal_hair_strands {
namespace {

using detail::validation::texel_spread;

class Report final : public EnginePresetReport {
 public:
  std::string_view name() const override { return "unreal-hair-strands"; }
  std::string recompute(const EngineTexture& t, const EngineTableSpec& group, int per_axis, const ValidationOptions& opt,
                        const Compare& compare) const override {
    const EngineTableSpec* spec = &group;
    const int Z = group.axes[0].count, Y = group.axes[1].count, X = group.axes[2].count;
    const std::vector<double> nz = group.axes[0].nodes(), ny = group.axes[1].nodes(), nx = group.axes[2].nodes();
    std::string definition;
    // Unreal: the mean-energy and dual-scattering quantities from dual_scattering() at the texel's model.
    const double tol = opt.thresholds.ds_accuracy;
    const int k = std::max(2, per_axis / 3);
    definition = "dual_scattering() of the preset's model at " + std::to_string(k) + "^3 texels (tolerance ds_accuracy)";
    for (int z : texel_spread(Z, k)) {
      detail::validation::check_cancel(opt);
      for (int y : texel_spread(Y, k)) {
        const std::vector<LobeParams> lobes = spec->roughness.lobes_at(ny[static_cast<std::size_t>(y)]);
        HairModel m;
        m.sigma_a = spec->absorption.sigma_a(nz[static_cast<std::size_t>(z)]);
        m.lobes.assign(lobes.begin(), lobes.begin() + spec->roughness.lobes);
        if (spec->roughness.residual) m.residual = lobes.back();
        for (int x : texel_spread(X, k)) {
          const DualScatteringPoint p = dual_scattering(m, nx[static_cast<std::size_t>(x)]);
          for (int c = 0; c < t.channel_count; ++c) {
            const std::string& tb = t.channels[c].table;
            if (tb.empty()) continue;
            const std::string q = tb.substr(tb.rfind('/') + 1);
            double v = q == "a_f" ? p.a_f : q == "a_b" ? p.a_b : q == "E_R" ? p.energy[0] : q == "E_TT" ? p.energy[1] : q == "E_TRT" ? p.energy[2] : NAN;
            if (!std::isfinite(v)) throw DomainError(t.name + ": no definition for channel table " + tb);
            v = t.channels[c].scale * v;
            if (t.channels[c].saturate) v = std::clamp(v, 0.0, 1.0);
            compare(x, y, z, c, v, 0.0, tol);
          }
        }
      }
    }
    return definition;
  }
};

}  // namespace

const EnginePresetReport& report() {
  static const Report r;
  return r;
}

}  // namespace hairlut::presets::unreal_hair_strands
