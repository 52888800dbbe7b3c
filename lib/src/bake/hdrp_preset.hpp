// Internal: the presets of Unity HDRP's hair textures (lib/presets/unity_hdrp_hair/ and
// unity_hdrp_hair_deon/): HDRP's axes, texel placement and encodings, and its three textures baked
// from its pre-integration kernels (hdrp_kernels.hpp) with HDRP's functions or the exact ones.
#pragma once

#include <string>

#include "hairlut/bake/engine_preset.hpp"
#include "hairlut/bake/hdrp_kernels.hpp"

namespace hairlut::detail {

class HdrpPreset : public EnginePreset {
 public:
  /// `file_prefix` begins each texture's file suffix ("unity-", "unity-deon-").
  HdrpPreset(std::string name, hdrp::Functions functions, std::string file_prefix, const char* schema)
      : name_(std::move(name)), functions_(functions), file_prefix_(std::move(file_prefix)), schema_(schema) {}
  std::string_view name() const override { return name_; }
  std::string_view schema() const override { return schema_; }
  std::vector<std::string> texture_names() const override { return {"attenuation", "azimuthal", "longitudinal"}; }
  nlohmann::json settings(const nlohmann::json&) const override { return nlohmann::json::object(); }
  /// HDRP's kernels fix η = 1.55.
  void check(const BakeConfig& c) const override;
  std::vector<EngineTableSpec> tables(bool residual) const override;
  std::vector<EngineTexture> textures() const override;
  void bake(const BakeConfig& c, const EngineTableSpec& group, const BakeOptions& opt, TableSet& set, BakeReport& report) const override;
  GroupSize group_size(const EngineTableSpec& group) const override;

 private:
  std::string name_;
  hdrp::Functions functions_;
  std::string file_prefix_;
  const char* schema_;
};

}  // namespace hairlut::detail
