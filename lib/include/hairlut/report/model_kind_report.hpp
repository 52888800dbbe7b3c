// The validator's side of a model in lib/models/<name>/ (bake/model_kind.hpp): its energy
// sections of report.json, which say what conservation means for it (d'Eon 2011: the white
// furnace and the truncation of the explicit lobes; Marschner 2003, which does not conserve: its
// E(θi) through the tables against direct evaluation, and the comparison with d'Eon's). The
// validator reaches a model only through this interface and model_kind_reports(), which the build
// generates from the folders that have a <name>_report.cpp.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hairlut/bake/model_kind.hpp"
#include "hairlut/report/validate.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// The model a table set was baked with, as its metadata records it.
struct TableSetModel {
  std::string model = "deon2011";
  double eta = 1.55;
  AbsorptionPath path = AbsorptionPath::chord;
  std::vector<std::string> lobes;  ///< explicit lobes R, TT, ...
  int explicit_lobes = 0;
  bool residual = false;
  int energy_order = 128;
  const ModelKind* kind = nullptr;                ///< the model's folder (lib/models/)
  std::shared_ptr<const ModelSettings> settings;  ///< its settings from the metadata (null: none of its own)
};

class ModelKindReport {
 public:
  virtual ~ModelKindReport() = default;
  /// The model's name (ModelKind::name).
  virtual std::string_view name() const = 0;
  /// Its energy sections, as keys of `report`, appending their checks to `checks`; reports its
  /// progress as steps 1 and 2 of the validator's 6.
  virtual void energy_sections(const TableSet& set, const TableSetModel& model, const ValidationOptions& opt,
                               std::vector<nlohmann::ordered_json>& checks, nlohmann::ordered_json& report) const = 0;
  /// Those sections as HTML for report.html, from the whole report.json.
  virtual std::string html(const nlohmann::ordered_json& report) const = 0;

  /// The exact longitudinal energy of one of its M_p tables over (β, θi, θr), for the check of the
  /// tables' ∫ M cos^k θr dθr: the value at (β, θi), the model's measure k (1: d'Eon's M_p; 2: the
  /// curve scattering functions of Marschner and Kajiya–Kay), where along θr the lobe peaks (a
  /// breakpoint of the integration) and the table's shift α as its attributes record it.
  struct MpEnergy {
    double exact = 0.0;
    int cos_power = 1;
    double peak = 0.0;
    double shift = 0.0;
  };
  virtual MpEnergy mp_energy(const Table& t, double beta, double theta_i) const = 0;
};

/// Every model under lib/models/ with a validator side, in the order of their folders' names.
std::span<const ModelKindReport* const> model_kind_reports();

}  // namespace hairlut
