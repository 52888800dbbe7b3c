// Validator and report sections that live in their own files (internal to the library).
#pragma once

#include <algorithm>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "hairlut/tables/tables.hpp"
#include "hairlut/report/validate.hpp"
#include "hairlut/bake/config.hpp"
#include "hairlut/bake/hdrp_kernels.hpp"
#include "hairlut/report/engine_preset_report.hpp"
#include "hairlut/report/model_kind_report.hpp"
#include "hairlut/util/angles.hpp"

namespace hairlut::detail {

/// The validator's own pieces, shared by its section files (validate.cpp: sanity and the report;
/// validate_energy.cpp: M_p and absorption; validate_accuracy.cpp: the sampled error of every
/// table) and the models' sections (lib/models/<model>/<model>_report.cpp: furnaces, truncation,
/// Marschner's E(θi)).
namespace validation {

using json = nlohmann::ordered_json;

// The model the tables were baked with, from their metadata.
using ModelInfo = TableSetModel;

ModelInfo model_from(const TableSet& set);
/// Whether the values of t may be negative (the sanity check counts negatives elsewhere).
bool may_be_negative(const Table& t);

json check(const std::string& id, const std::string& title, bool pass, double value, double threshold, const std::string& comparison,
           const std::string& detail);
json skipped(const std::string& id, const std::string& title, const std::string& why);
std::string fmt(double v, int digits = 3);
void check_cancel(const ValidationOptions& opt);
std::vector<double> theta_grid_deg();                   // θ in degrees, −89 … 89, denser near grazing
std::vector<double> representative(const GridAxis& a);  // up to three nodes: first, middle, last

// Integrals over φ of tables, exactly as the sampler interpolates along φ (validate_energy.cpp).
/// ∫ N_table(β, σa, θd, φ) dφ of a d'Eon table (read as a renderer reads it: with its factor).
double table_energy(const TableSet& set, const Table& t, double beta, double sigma, double theta_d);
/// ∫ N_table dφ of a Marschner table (σa, θd, [φh,] φ) at φh (ignored without that axis).
double marschner_table_energy(const Table& t, double sigma, double theta_d, double phi_h);
/// e_p,table(θd) on a fine θd grid, for interpolation inside the θr integral.
struct EnergyCurve {
  std::vector<double> values;  // at θd = k (π/2)/n, k = 0 … n
  double at(double theta_d) const {
    const double n = static_cast<double>(values.size() - 1);
    const double s = std::clamp(theta_d / kHalfPi * n, 0.0, n);
    const auto k = std::min(static_cast<std::size_t>(s), values.size() - 2);
    const double w = s - static_cast<double>(k);
    return (1.0 - w) * values[k] + w * values[k + 1];
  }
};

// Engine textures (validate_engine.cpp, hdrp_texels.cpp; the presets' <name>_report.cpp).
/// Texel indices to recompute along an axis of n texels: all, or k evenly spread including both ends.
std::vector<int> texel_spread(int n, int k);
/// Unity HDRP's textures recomputed from HDRP's kernels with `fn` (EnginePresetReport::recompute).
std::string hdrp_texels(const EngineTexture& t, const EngineTableSpec& spec, int per_axis, hdrp::Functions fn, const ValidationOptions& opt,
                        const EnginePresetReport::Compare& compare);
/// The validator's side of an HDRP preset (lib/presets/unity_hdrp_hair*/): hdrp_texels with its functions.
class HdrpPresetReport final : public EnginePresetReport {
 public:
  HdrpPresetReport(std::string_view name, hdrp::Functions fn) : name_(name), fn_(fn) {}
  std::string_view name() const override { return name_; }
  std::string recompute(const EngineTexture& t, const EngineTableSpec& group, int per_axis, const ValidationOptions& opt,
                        const Compare& compare) const override {
    return hdrp_texels(t, group, per_axis, fn_, opt, compare);
  }

 private:
  std::string_view name_;
  hdrp::Functions fn_;
};

// Sections: each appends its checks and returns its part of the report.
json longitudinal_section(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt, std::vector<json>& checks);
json absorption_section(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt, std::vector<json>& checks);
json accuracy_section(const TableSet& set, const ModelInfo& info, const ValidationOptions& opt, std::vector<json>& checks);
json sampling_data_section(const TableSet& set, std::vector<json>& checks);  // validate_sampling.cpp

}  // namespace validation

/// Mean-energy and dual-scattering tables (tables.dual_scattering, tables.engine): the consistency
/// a_f + a_b = Σ_p E_p between the two tables, the white furnace of the mean-energy table where it
/// has σa = 0 and d'Eon's uniform setting, the tables against dual_scattering() (no interpolation)
/// at sampled nodes, and the curves for the plots. Appends its checks; returns report["dual_scattering"].
nlohmann::ordered_json dual_scattering_section(const TableSet& set, const ValidationOptions& options,
                                               std::vector<nlohmann::ordered_json>& checks);

/// The HTML (inline SVG plots) and Markdown of that section; empty when the set has no such tables.
std::string render_dual_scattering_html(const nlohmann::ordered_json& report);
std::string render_dual_scattering_markdown(const nlohmann::ordered_json& report);

}  // namespace hairlut::detail
