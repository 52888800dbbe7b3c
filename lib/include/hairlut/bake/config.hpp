// Bake configurations: the JSON that `bake-hair-luts --config FILE` reads, checked against
// schemas/hairlut-config.schema.json (embedded in the library) and then against the rules JSON
// Schema cannot express, with one-line errors that name the file and the key path.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hairlut/physics/attenuation.hpp"
#include "hairlut/physics/azimuthal_np.hpp"
#include "hairlut/bake/engine_presets.hpp"
#include "hairlut/bake/beta_bands.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/tables/grid.hpp"
#include "hairlut/util/hash.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "hairlut/bake/table_kind.hpp"

namespace hairlut {

class ModelKind;
struct ModelSettings;

/// A config that cannot be used. what() is one line: "<file>: <key.path>: <reason>".
class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(const std::string& message) : std::runtime_error(one_line(message)) {}
};

/// How N_p entries are integrated.
struct NpQuadratureConfig {
  /// fourier: the detector's Fourier series with coefficients shared by every β and σa
  /// (azimuthal_fourier.hpp; default); gauss_legendre: a fixed-order rule per entry;
  /// adaptive: the adaptive reference integrator per entry (slow).
  enum class Method { fourier, gauss_legendre, adaptive };
  Method method = Method::fourier;
  int order = 256;                                   ///< Gauss–Legendre order (gauss_legendre)
  IntegrationVariable variable = IntegrationVariable::gamma;
  double tolerance = 1e-12;                          ///< error relative to the lobe peak (fourier) or value (adaptive)
  int energy_order = 128;                            ///< Gauss–Legendre order of lobe energies
};

std::string_view to_string(NpQuadratureConfig::Method method);

/// tables.np.representation: how the generic N_p tables store N_p.
enum class NpRepresentation {
  tensor,   ///< N_p (or its shape N_p / E_p) over (β, σa, θd, φ), optionally in β bands
  fourier   ///< the detector's cosine-series coefficients C_n / F over (θd, σa), β and φ exact (fourier_tables.hpp)
};
std::string_view to_string(NpRepresentation r);

/// tables.np with representation "fourier": what the Fourier N_p tables are baked over.
struct FourierNpConfig {
  double beta_lo = 0.0, beta_hi = 0.0;  ///< the β range [rad]: beta_lo fixes the stored terms, [lo, hi] is the validated domain
  double tolerance = 1e-4;              ///< truncation of the series per lookup (sampler/fourier_np.hpp)
  std::vector<GridAxis> axes;           ///< theta_d, sigma_a: the coefficients' axes (storage order; n is fastest)
};

/// One hair material of a scene.
struct MaterialConfig {
  std::string name;
  std::array<double, 3> sigma_a{};          ///< RGB absorption per unit radius (from melanin if given)
  std::optional<std::array<double, 2>> melanin;  ///< (eumelanin, pheomelanin) when given as melanin
  std::string melanin_model;                ///< "rgb" or "spectral" when given as melanin
  std::vector<double> beta_m;               ///< longitudinal roughness per explicit lobe (radians)
  std::vector<double> beta_n;               ///< azimuthal roughness per explicit lobe (radians)
  double residual_beta_m = 0.0, residual_beta_n = 0.0;
};

struct SceneConfig {
  enum class Mode { per_material, restrict_generic };
  Mode mode = Mode::per_material;
  std::vector<MaterialConfig> materials;
};

/// tables.dual_scattering: mean energy per lobe and Zinke 2008's dual-scattering quantities over
/// generic physical axes (dual_scattering.hpp, docs/dual-scattering.md).
struct DualScatteringTablesConfig {
  std::vector<GridAxis> axes;      ///< sigma_a, beta, theta_i (storage order, theta_i fastest)
  std::vector<double> lobe_scale;  ///< per explicit lobe, then the residual: β_m,p = β_n,p = scale_p β (default 1)
  double density_factor = 0.7;     ///< d_b of Zinke eq. 17
};

struct OutputConfig {
  std::filesystem::path directory;  ///< absolute, or relative to the process's working directory
  std::string basename;
  bool hdf5 = false, exr = false;
  bool hdf5_double = false;         ///< float64 instead of float32
  int hdf5_deflate = 6;
  bool exr_half = false;            ///< half instead of float
  std::string exr_compression = "zip";
  bool sampling_data = true;        ///< the importance sampler's data next to every N_p and M_p table
};

/// A validated config, with defaults applied and angles in radians.
struct BakeConfig {
  std::string name, description;
  std::string model = "deon2011";   ///< a model of lib/models/ by its full name
  /// What the model read from the config (null for a model with no settings of its own, d'Eon's);
  /// its json() is what the normalized config and the table metadata record.
  std::shared_ptr<const ModelSettings> model_settings;
  double eta = 1.55;
  AbsorptionPath path = AbsorptionPath::chord;
  int lobe_count = 4;                ///< explicit lobes p = 0 … lobe_count − 1
  bool residual = true;
  double fold_below = 0.0;
  std::vector<double> tilt;          ///< α_p per explicit lobe (radians)
  double residual_tilt = 0.0;
  NpQuadratureConfig quadrature;
  /// Table axes, in storage order (row-major, last fastest).
  /// beta, sigma_a, theta_d, phi (deon2011); sigma_a, theta_d, phi and, for an eccentric fiber,
  /// phi_h (marschner2003: TRT over sigma_a, theta_d, phi_h, phi)
  std::optional<std::vector<GridAxis>> np_axes;
  std::optional<double> np_target_error;              ///< choose the N_p counts for this off-node error
  /// tables.np.target_points: random points per N_p table by which target_error accepts a bake
  /// (unset: kSampledErrorPoints, the validator's default, so that both report the same figures).
  std::optional<std::size_t> np_target_points;
  /// tables.np.representation as given (absent: tensor tables; with target_error every
  /// representation competes, and a given one restricts the choice to it).
  std::optional<NpRepresentation> np_representation;
  /// Set exactly when the representation is fourier (np_axes is then unset).
  std::optional<FourierNpConfig> np_fourier;
  /// tables.np.normalize "energy": N_p tables store N_p / E_p with np/energy_<lobe> as their factor.
  bool np_normalize_energy = false;
  /// tables.np.energy_axes: sigma_a, theta_d of the energy and residual tables (default: the N_p axes).
  std::optional<std::vector<GridAxis>> np_energy_axes;
  /// tables.np.beta_bands (beta_bands.hpp): N_p per β band; band 0's axes are np_axes.
  std::vector<BetaBand> np_beta_bands;
  std::optional<std::vector<GridAxis>> mp_axes;       ///< beta (β_R for marschner2003), theta_i, theta_r
  /// The table kinds of lib/kinds/ that the config asks for (table_kind.hpp: tables.melanin), in
  /// the order of table_kinds().
  std::vector<TableKindRequest> kinds;
  std::optional<SceneConfig> scene;
  std::optional<DualScatteringTablesConfig> dual_scattering;  ///< tables.dual_scattering
  std::optional<EngineConfig> engine;                         ///< tables.engine (export presets)
  OutputConfig output;

  nlohmann::json validate_thresholds;  ///< "validate": {"thresholds": {...}} for validate-hair-luts (may be null)

  nlohmann::json normalized;  ///< the config with every default filled in, angles in radians
  std::string hash;           ///< FNV-1a 64 of normalized + library version, 16 hex digits

  /// The model named by `model` (bake/model_kind.hpp); throws DomainError for a name no folder has.
  const ModelKind& model_kind() const;
};

/// Parses and validates a config document. `source` names it in error messages (the file name).
/// `base_dir` resolves a relative output.directory. Throws ConfigError.
BakeConfig parse_config(const nlohmann::json& document, const std::string& source,
                        const std::filesystem::path& base_dir);

/// Reads, parses and validates a config file (JSON syntax errors report line and column).
BakeConfig load_config(const std::filesystem::path& file);

/// The config schema: the library's own (lib/src/bake/config.schema.json) with each model's
/// fragment (model_kind.hpp: its name in `model`, its settings key, its rules in allOf), each table kind's
/// fragment (table_kind.hpp) under properties.tables.properties.<kind> and its threshold under
/// validate.thresholds. schemas/hairlut-config.schema.json
/// publishes it (a test keeps the two equal).
nlohmann::ordered_json config_schema();

}  // namespace hairlut
