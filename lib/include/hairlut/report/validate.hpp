// Validation of baked tables: energy conservation (white furnace), truncation loss, longitudinal
// energies (d'Eon's against Marschner's Gaussian), table accuracy against direct evaluation off
// the nodes (broken down by axis, also for half floats), sanity of values and metadata, and
// absorption. The result is a JSON document (report.json) that report.hpp renders as HTML and
// Markdown.
#pragma once

#include <atomic>
#include <functional>
#include <cstdint>
#include <map>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "hairlut/bake/sampled_error.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// Pass/fail thresholds of the checks; every one can be overridden by name.
struct ValidationThresholds {
  double furnace_direct = 1e-6;       ///< max |E(θi) − 1| of the model, σa = 0, all lobes
  double furnace_table = 2e-2;        ///< max |E_table(θi) − E_direct(θi)| from the N_p tables
  double longitudinal_deon = 1e-9;    ///< max |∫M cos θr dθr − 1| of d'Eon's M_p
  double mp_table_energy = 5e-2;      ///< max |∫M_table cos θr − ∫M cos θr| of the M_p tables
  /// Accuracy where a renderer samples (sampled_error.hpp: random points over each table's
  /// declared domain, relative to the local denominator of the table's kind).
  double accuracy_max_rel = 5e-2;     ///< N_p tables of the lobes: max |sampled − direct| / peak over φ of the slice (white floor 1e-3)
  double accuracy_p99_rel = 1e-2;     ///< N_p tables: 99th percentile of the same
  double accuracy_energy_max_rel = 1e-2;   ///< energy tables and the residual's N_p: max relative error (floors 1e-3 × white, 1e-6)
  double accuracy_mp_max_rel = 1e-2;       ///< M_p tables: max error / peak over θr at the same (β, θi)
  double accuracy_melanin_max_rel = 1e-2;  ///< melanin σa tables: max relative error (floor 0.01 per radius)
  double accuracy_ds_max_rel = 1e-2;       ///< dual-scattering and mean-energy tables: max relative error (floors: table_truth.hpp)
  double energy_consistency = 1e-2;   ///< max |∫N_table dφ − energy table| / max energy
  double ds_furnace = 1e-4;           ///< max |Σ_p E_p − 1| of a mean-energy table at σa = 0 (uniform roughness, no tilt)
  double ds_consistency = 1e-4;       ///< max |a_f + a_b − Σ_p E_p| between dual-scattering and mean-energy tables
  double ds_accuracy = 1e-4;          ///< max |table − dual_scattering()| of a_f, a_b, E at sampled nodes
  /// Names as used on the command line and in report.json ("furnace_table", ...).
  static const std::map<std::string, double ValidationThresholds::*>& fields();
  /// Sets one threshold by name; throws DomainError naming the key when unknown or not > 0.
  void set(const std::string& name, double value);
  nlohmann::ordered_json to_json() const;
};

struct ValidationOptions {
  ValidationThresholds thresholds;
  std::size_t max_points = kSampledErrorPoints;  ///< random points per table
  /// The seed of the accuracy measure's points (random points and the worst-point search), mixed
  /// with each table's path. Absent: drawn afresh for every run (std::random_device), so that
  /// every run looks somewhere new; the report records it ("accuracy_search.seed") so a run can be
  /// repeated exactly with it.
  std::optional<std::uint64_t> seed;
  /// After the random points, search for each table's worst point (edges, corners, features,
  /// grazing ends, local maximisation: SampledErrorOptions::search); the accuracy checks judge the
  /// worst found.
  bool search = true;
  int threads = 0;                 ///< OpenMP threads for direct evaluation (0: all)
  std::function<void(std::string_view stage, std::size_t done, std::size_t total)> progress;
  const std::atomic<bool>* cancel = nullptr;
};

/// Runs every check that the table set supports and returns report.json's document:
/// {"summary", "checks": [{id, title, status, value, threshold, comparison, detail}], and the
/// figures of each section}. `source` names the validated file. Throws DomainError when the set
/// is not a usable hairlut table set (missing metadata, lobes or axes), BakeCancelled on cancel.
nlohmann::ordered_json validate_tables(const TableSet& set, const std::string& source, const ValidationOptions& options = {});

}  // namespace hairlut
