// A scattering model that lives in its own folder, lib/models/<name>/ (docs/architecture.md): its
// fragment of the config schema (schema.json: the model's settings key and the rules that say
// which keys it refuses), and here what the config parser, the memory plan, the bake and
// table_truth() ask of it (<name>_bake.cpp); the validator's side is report/model_kind_report.hpp
// (<name>_report.cpp). The library reaches a model only through these interfaces and
// model_kinds(), which the build generates from the folders: adding a model adds a folder.
//
// What every model shares stays outside: the config's fiber, lobes, output and scene keys, the
// axes σa, θd and φ of tables.np, θi and θr of tables.mp, the table kinds of lib/kinds/, the
// file formats and the runtime. d'Eon 2011's stages (bake/bake_stages.hpp) are also what the
// planner, the slabbed writer, dual scattering and the engine presets build on, so they stay in
// lib/src/bake and its folder calls them.
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hairlut/bake/bake.hpp"
#include "hairlut/tables/grid.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

struct TableTruth;
struct MaterialConfig;

/// What a model read from a config or a table set's metadata; each model derives its own.
struct ModelSettings {
  virtual ~ModelSettings() = default;
  /// The settings as the normalized config and the metadata record them under the model's key
  /// (null: a model with no settings of its own).
  virtual nlohmann::json json() const = 0;
};

/// The axes of tables.np.axes that every model reads the same way (already checked).
struct SharedNpAxes {
  GridAxis sigma_a;   ///< count 0 when a per-material scene leaves it out
  GridAxis theta_d;
  GridAxis phi;
  bool per_material = false;
};

/// A table a model's own N_p stage writes, for the memory plan (bake_estimate.cpp): its axes in
/// storage order, and whether the importance sampler's data go beside it (along the last axis).
struct PlannedTable {
  std::vector<GridAxis> axes;
  bool sampled = true;
};

class ModelKind {
 public:
  virtual ~ModelKind() = default;
  /// The config's `model` and the metadata's; short_name() is accepted in configs too.
  virtual std::string_view name() const = 0;
  virtual std::string_view short_name() const = 0;
  /// Its fragment of the config schema: {"description": the model in a sentence for the `model`
  /// key, "properties": top-level keys it owns (its settings), "allOf": its rules, "example": a
  /// whole small config of the model, which the tests bake and check (tests/test_model_kinds.cpp)}.
  virtual std::string_view schema() const = 0;

  // ---- the config (parse_config)
  /// lobes.explicit when the config leaves it out.
  virtual std::vector<std::string> default_lobes() const = 0;
  /// Whether the model has a residual lobe (lobes.residual is then read, default true).
  virtual bool has_residual() const = 0;
  /// Its settings from the whole document (schema-checked), after fiber and lobes are read into c.
  /// A value the schema cannot judge throws through config_error(), naming the key.
  virtual std::shared_ptr<const ModelSettings> parse(const nlohmann::json& document, const BakeConfig& c) const = 0;
  /// Its keys of the normalized form (lobes, its settings, ...) into `normalized`.
  virtual void normalize(const BakeConfig& c, nlohmann::json& normalized) const = 0;
  /// The N_p axes in storage order from tables.np.axes (`axes`, the JSON object; `path` its key
  /// path with a trailing dot) and the shared axes.
  virtual std::vector<GridAxis> np_axes(const nlohmann::json& axes, const std::string& path, const SharedNpAxes& shared,
                                        const BakeConfig& c) const = 0;
  /// What the M_p tables' β axis means (its long name).
  virtual std::string mp_beta_meaning() const = 0;
  /// A scene material's roughness per lobe (beta_m, beta_n and the residual's) from its entry.
  virtual void material_roughness(const nlohmann::json& material, const std::string& path, const BakeConfig& c,
                                  MaterialConfig& m) const = 0;
  /// Its rules over the whole parsed config that need arithmetic (JSON Schema states the rest):
  /// throws through config_error(), naming the key.
  virtual void check(const BakeConfig& c) const = 0;

  // ---- sizes and the bake
  /// Whether tables over the memory budget can be baked slab by slab (bake.hpp's SlabbedTables).
  virtual bool slab_by_slab() const = 0;
  /// The N_p tables of its own stage (empty: d'Eon's, which the planner sizes).
  virtual std::vector<PlannedTable> own_np_tables(const BakeConfig& c) const = 0;
  /// The whole set: its tables, the kinds of lib/kinds/, the sampling data; the report.
  virtual TableSet bake(const BakeConfig& c, const BakeOptions& opt, BakeReport* report, SlabbedTables* slabbed) const = 0;

  // ---- tables read back (the validator)
  /// Its settings from a table set's metadata with the fiber's η and path; throws DomainError.
  virtual std::shared_ptr<const ModelSettings> from_metadata(const nlohmann::json& metadata, double eta, AbsorptionPath path) const = 0;
  /// The exact function behind a table of its own stage, or nullopt (d'Eon's: table_truth's own).
  virtual std::optional<TableTruth> truth(const Table& t, const ModelSettings& s) const = 0;
};

/// Every model under lib/models/, in the order of their folders' names (generated by the build).
std::span<const ModelKind* const> model_kinds();
/// The model named `name` (or its short name); nullptr if none.
const ModelKind* find_model_kind(std::string_view name);

// What the models' parsers share with the config parser (table_kind.hpp has config_error and
// config_value_axis).
/// An angle axis of a config (the schema's `angle_axis`) as a GridAxis over [domain_lo, domain_hi] radians.
GridAxis config_angle_axis(const nlohmann::json& j, const std::string& path, const std::string& name, double domain_lo,
                           double domain_hi, const std::string& long_name);
/// Lobe names → p, the residual as −1; refuses a lobe beyond lobe_count, naming `path`.
int config_lobe_index(const std::string& name, int lobe_count, const std::string& path);
/// Per-lobe values given for some lobes (scaled by `scale`), the rest filled as per_lobe_values does.
void config_per_lobe_values(const nlohmann::json& j, const std::string& path, int lobe_count, double scale, std::vector<double>& out,
                            double& residual_out);

}  // namespace hairlut
