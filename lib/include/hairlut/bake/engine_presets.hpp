// Roughness and absorption parameterisations (one engine parameter → hairlut's per-lobe β_m, β_n,
// tilt and σa), the table groups and config of the export presets, and the calls that reach the
// presets of lib/presets/ (engine_preset.hpp) by name. A preset reproduces the axes, resolutions,
// encodings and texel placement of a real-time engine's hair look-up textures (a texture's layout:
// io/engine_texture.hpp); docs/presets/<name>.md describes each and the engine files it follows.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hairlut/io/engine_texture.hpp"
#include "hairlut/tables/grid.hpp"
#include "hairlut/physics/hair_model.hpp"

namespace hairlut {

/// What a table's roughness axis means.
enum class RoughnessParameter {
  beta,   ///< x = β in radians; β_m,p = β_n,p = s_p x (s_p per lobe, default 1)
  unreal  ///< x = the Hair shading model's Roughness in [0, 1] (docs/presets/unreal-hair-strands.md)
};

/// One roughness parameter x → the lobe parameters of R, TT, TRT, ... and the residual.
struct RoughnessMapping {
  RoughnessParameter parameter = RoughnessParameter::beta;
  int lobes = 3;                 ///< explicit lobes P
  bool residual = true;
  std::vector<double> scale;     ///< beta: s_p per explicit lobe, then the residual's (default all 1)
  std::vector<double> tilt;      ///< α_p per explicit lobe, then the residual's (radians, hairlut's θr shift)

  /// The P (+ 1) lobe parameters at x. Domain: beta: x > 0; the engine parameters: x in [0, 1]
  /// (clamped as the engines clamp them). Throws DomainError.
  std::vector<LobeParams> lobes_at(double x) const;
  /// Formulas and constants, for metadata and the validator.
  nlohmann::ordered_json describe() const;
  /// Reads describe()'s form back (the validator rebuilds the model from table metadata).
  static RoughnessMapping from_json(const nlohmann::json& j);
  /// True when every lobe has the same β_m = β_n and no tilt (d'Eon's white-furnace setting).
  bool uniform() const;
};

/// What a table's absorption axis means.
enum class AbsorptionParameter {
  sigma_a,           ///< x = σa per unit fiber radius
  unreal_base_color  ///< x = Unreal hair BaseColor c (linear); σa = −ln(max(c, 1e−4))/4
};

struct AbsorptionMapping {
  AbsorptionParameter parameter = AbsorptionParameter::sigma_a;
  /// σa per unit radius at x (≥ 0, finite). Throws DomainError for x outside the parameter's domain.
  double sigma_a(double x) const;
  nlohmann::ordered_json describe() const;
  static AbsorptionMapping from_json(const nlohmann::json& j);
};

/// The fiber a mean-energy or dual-scattering table entry stands for: η and the absorption path,
/// σa from the absorption axis's value, the lobes (and residual) from the roughness axis's value.
HairModel table_model(const RoughnessMapping& roughness, const AbsorptionMapping& absorption, double eta, AbsorptionPath path,
                      double roughness_x, double absorption_x);


/// tables.engine of a config: which preset, which of its textures, and the few constants an engine
/// team may need to match its own build.
struct EngineConfig {
  std::string preset;                  ///< a preset of lib/presets/ by name ("unreal-hair-strands", "unity-hdrp-hair", ...)
  std::vector<std::string> textures;   ///< a subset of the preset's textures (empty: all)
  double density_factor = 0.7;         ///< d_b of Zinke eq. 17 (also recorded for d_f)
  /// The preset's own keys of tables.engine, every default filled in (EnginePreset::settings):
  /// unity-hdrp-hair's "unity" block; an empty object for the others.
  nlohmann::json settings = nlohmann::json::object();
};

/// One group of tables of a preset, over one set of axes (storage order: the texture's Z, Y, X).
struct EngineTableSpec {
  std::string group;   ///< "unreal/dual_scattering", "unity/azimuthal", ...
  std::string kind;    ///< "dual_scattering", "mean_energy", "hdrp_attenuation", "hdrp_azimuthal", "hdrp_longitudinal"
  std::vector<GridAxis> axes;
  RoughnessMapping roughness;    ///< dual_scattering, mean_energy, longitudinal
  AbsorptionMapping absorption;  ///< dual_scattering, mean_energy
  std::string roughness_axis, absorption_axis, theta_axis;  ///< axis names of the three parameters
};

/// An axis of an engine texture: texel-centred ((i + 1/2)/count of the mapped range), clamped.
GridAxis texel_axis(std::string name, std::string units, std::string long_name, Spacing spacing, double lo, double hi, int count);

/// Names of the presets (lib/presets/, engine_preset.hpp).
std::vector<std::string> engine_preset_names();

/// The table groups a preset bakes for explicit lobes R, TT, TRT (the presets' lobes) and the
/// residual if `residual`. Throws DomainError for an unknown preset.
std::vector<EngineTableSpec> engine_preset_tables(const EngineConfig& config, bool residual);

/// Textures a preset writes (all, or config.textures). Throws DomainError naming an unknown texture.
std::vector<EngineTexture> engine_preset_textures(const EngineConfig& config);

/// The texture names of a preset.
std::vector<std::string> engine_preset_texture_names(const std::string& preset);

}  // namespace hairlut
