// Validation of baked tables: energy conservation (white furnace), truncation loss, longitudinal
// energies (d'Eon's against Marschner's Gaussian), table accuracy against direct evaluation off
// the nodes (broken down by axis, also for half floats), sanity of values and metadata, and
// absorption. The result is a JSON document (report.json) that report.hpp renders as HTML and
// Markdown.
#pragma once

#include <atomic>
#include <functional>
#include <cstdint>
#include <filesystem>
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
  double accuracy_ds_max_rel = 1e-2;       ///< dual-scattering and mean-energy tables: max relative error (floors: table_truth.hpp)
  double energy_consistency = 1e-2;   ///< max |∫N_table dφ − energy table| / max energy
  double ds_furnace = 1e-4;           ///< max |Σ_p E_p − 1| of a mean-energy table at σa = 0 (uniform roughness, no tilt)
  double ds_consistency = 1e-4;       ///< max |a_f + a_b − Σ_p E_p| between dual-scattering and mean-energy tables
  double ds_accuracy = 1e-4;          ///< max |table − dual_scattering()| of a_f, a_b, E at sampled nodes
  /// The accuracy thresholds of the table kinds of lib/kinds/, by name (TableKind::threshold;
  /// "accuracy_melanin_max_rel"), each at its kind's default unless set.
  std::map<std::string, double> kinds;
  ValidationThresholds();
  /// Names as used on the command line and in report.json ("furnace_table", ...), the kinds' apart.
  static const std::map<std::string, double ValidationThresholds::*>& fields();
  /// Sets one threshold by name (a field or a kind's); throws DomainError naming the key when
  /// unknown or not > 0.
  void set(const std::string& name, double value);
  /// One threshold by name; throws DomainError naming the key when unknown.
  double get(const std::string& name) const;
  nlohmann::ordered_json to_json() const;
};

/// One part of a set validated in parts (validate_tables_in_parts): the tables of `group` whose
/// leading axis is `axis` hold only this part's rows, which reach one node beyond [lo, hi] where
/// the axis goes on (the taps of cubic interpolation), and their accuracy is measured over [lo, hi].
/// The other tables, and the checks of nothing but them, are judged in part 0 alone.
struct ValidationPart {
  std::string group = "np", axis = "beta";
  double lo = 0.0, hi = 0.0;  ///< the range of the axis this part measures, between two of its nodes
  double share = 1.0;         ///< this part's share of the axis's cells: of max_points, the points it draws
  int index = 0, count = 1;   ///< which part, of how many
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
  std::optional<ValidationPart> part;  ///< set by validate_tables_in_parts for each part
};

/// Runs every check that the table set supports and returns report.json's document:
/// {"summary", "checks": [{id, title, status, value, threshold, comparison, detail}], and the
/// figures of each section}. `source` names the validated file. Throws DomainError when the set
/// is not a usable hairlut table set (missing metadata, lobes or axes), BakeCancelled on cancel.
nlohmann::ordered_json validate_tables(const TableSet& set, const std::string& source, const ValidationOptions& options = {});

/// Memory a part's validation takes beside the tables it holds: the program and its libraries, the
/// accuracy measure's points, search and heat maps (measured: 36 MiB of peak RSS beside a part of
/// 36 MiB, at the default 40000 points with the search).
inline constexpr std::uint64_t kValidationPartOverhead = std::uint64_t{64} << 20;

/// The bytes of the values of every table an HDF5 file holds, from its tables' descriptions
/// (no value is read); nullopt for a file that is not HDF5. Throws IoError.
std::optional<std::uint64_t> hdf5_values_bytes(const std::filesystem::path& file);

/// validate_tables for an HDF5 set larger than `memory_budget` bytes, held in parts. The file is
/// checked as load_tables checks it (sidecar, content checksum: streamed) under the directory's
/// shared lock. Every N_p table over β (the bulk of a generic set, as a slabbed bake writes it) is
/// read in parts of consecutive β rows, with the other tables whole; each part is validated over
/// its own β cells (ValidationPart) and the reports are merged: a check fails if it fails in any
/// part, and its value is the worst of the parts' (for the 99th percentile of the N_p error, the
/// largest of the parts', which bounds the whole set's from above). NaN, Inf and negative values
/// are counted over the stream. The report's "parts" says how the set was split. Throws
/// DomainError when no part fits the budget or the set has no N_p tables over β to split (or
/// holds sampling data for them, which a set baked slab by slab does not), IoError, BakeCancelled.
nlohmann::ordered_json validate_tables_in_parts(const std::filesystem::path& file, const std::string& source, std::uint64_t memory_budget,
                                                const ValidationOptions& options = {});

}  // namespace hairlut
