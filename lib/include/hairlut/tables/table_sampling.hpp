// The sampling data stored next to a table set's N_p and M_p tables (docs/table-format.md,
// "Sampling data"): made, found and checked. The renderer runtime (hair_views.hpp,
// hair_scattering) reads the N_p tables' data along φ.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hairlut/util/error.hpp"
#include "hairlut/sampler/axis_sampling.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// The measure along the sampled axis when t is a table the runtime samples (N_p over φ:
/// plain; M_p over θr: cos θr; generic or per material, values present), else nullopt.
std::optional<sampler::Measure> sampled_measure(const Table& t);
/// Where t's sampling data live: "sampling/<group>/<name>_<what>", what = cdf, mass or clamp_bound.
std::string sampling_path(const Table& t, const std::string& what);
/// The sampling data of every sampled table of the set whose axes the sampler supports, as tables
/// (AxisSampler::build_data of the stored values): <name>_cdf (float64, the table's axes),
/// <name>_mass (float64) over the other axes and <name>_clamp_bound (float32, the table's axes).
/// The clamp bounds are computed on `threads` OpenMP threads (0: all cores); the values do not
/// depend on the thread count. `progress` (optional) hears ("sampling data", tables done, tables).
using SamplingProgress = std::function<void(std::string_view stage, std::size_t done, std::size_t total)>;
std::vector<Table> sampling_tables(const TableSet& set, int threads = 0, const SamplingProgress& progress = {});
/// Appends sampling_tables(set, threads, progress) to the set (the baker does, after the tables
/// are complete).
void append_sampling_tables(TableSet& set, int threads = 0, const SamplingProgress& progress = {});
/// The stored sampling data of table t (pointers into the set), or empty when the set has none of
/// the right precision and shape, or when they are not t's own (AxisSampler::matches: prefix masses
/// recomputed from t's values, clamp bounds finite and ≥ 0); the sampler then computes them.
sampler::AxisData stored_sampling_data(const TableSet& set, const Table& t);

/// Stored sampling data against what the sampler computes from the stored values.
struct SamplingDataCheck {
  std::string table;                   ///< the sampled table
  bool present = false;                ///< sampling data stored for it
  std::string problem;                 ///< why none could be read ("" when read)
  double max_cdf_difference = 0.0;     ///< largest |stored − computed| prefix, over the slice's largest |prefix|
  double max_mass_difference = 0.0;    ///< the same for the slices' masses
  std::size_t bound_mismatches = 0;     ///< clamp bounds that differ
  std::size_t unclamped = 0, cells = 0;  ///< cells of the other axes with every clamp bound 0, and all of them
};
/// Every sampled table's stored data against the sampler's, recomputed on `threads` OpenMP threads
/// (0: all cores).
std::vector<SamplingDataCheck> check_sampling_data(const TableSet& set, int threads = 0);

}  // namespace hairlut
