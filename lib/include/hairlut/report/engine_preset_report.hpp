// The validator's side of an engine preset in lib/presets/<name>/ (bake/engine_preset.hpp): the
// values its textures' texels must hold, recomputed from their definition (HDRP's kernels for the
// Unity presets, dual_scattering() for Unreal's). validate-hair-luts's engine-texture check reaches
// a preset only through this interface and engine_preset_reports(), which the build generates from
// the folders that have a <name>_report.cpp.
#pragma once

#include <functional>
#include <span>
#include <string>
#include <string_view>

#include "hairlut/bake/engine_presets.hpp"
#include "hairlut/report/validate.hpp"

namespace hairlut {

class EnginePresetReport {
 public:
  virtual ~EnginePresetReport() = default;
  /// The preset's name (EnginePreset::name).
  virtual std::string_view name() const = 0;
  /// Texel (x, y, z), channel c, its exact value, and the tolerance on top of half rounding:
  /// relative `tol` and absolute `abs_tol`.
  using Compare = std::function<void(int x, int y, int z, int c, double value, double tol, double abs_tol)>;
  /// Recomputes texels of `texture` (over `group`'s axes; at most about `per_axis` per axis where a
  /// texel is costly) and hands each to `compare`; returns the definition in words for the report.
  virtual std::string recompute(const EngineTexture& texture, const EngineTableSpec& group, int per_axis, const ValidationOptions& opt,
                                const Compare& compare) const = 0;
};

/// Every preset under lib/presets/ with a validator side, in the order of their folders' names.
std::span<const EnginePresetReport* const> engine_preset_reports();

}  // namespace hairlut
