// The error of a table as a renderer sees it: at random points over the whole declared domain of
// every axis, the table interpolated with the reconstruction its metadata declare (and its factor
// table, TableSet::sample_value), against direct evaluation of the same quantity, relative to a
// local denominator (the peak of the same N_p or M_p slice, or the value itself, with floors; see
// TableTruth). Worst case, 99th percentile, mean, and where the worst occurs.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hairlut/bake/table_truth.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// Random points per table of the validator's default run, by which target_error also accepts a
/// bake: both report the same figures for the same table.
inline constexpr std::size_t kSampledErrorPoints = 40000;
/// The seed of a table's random points (FNV-1a 64 of its path): the same points for a table in
/// every run, in the validator and in target_error.
std::uint64_t sampled_error_seed(const std::string& table_path);

struct SampledErrorOptions {
  std::size_t points = 20000;  ///< random points (rounded up to whole groups of 32 sharing a slab)
  std::uint64_t seed = 1;      ///< same seed, same points and figures, for any thread count
  int threads = 0;             ///< OpenMP threads (0: all)
  bool half_float = false;     ///< also measure the values (and factor) rounded to half floats
  bool keep_points = false;    ///< return every point and its error (for heat maps)
  const std::atomic<bool>* cancel = nullptr;  ///< polled; the figures are incomplete when it is set
  /// After the random points, search for the worst point (worst_point_search below): the first and
  /// last cell of every axis and every corner, known features, every cell where the exact value is
  /// cheap (TableTruth::sweep_cells) and grazing ends, then coordinate search from the worst points
  /// found. Its points come from `seed` too.
  bool search = false;
  int climb_starts = 8;         ///< worst points (in distinct cells) the local maximisation starts from
  int climb_evaluations = 160;  ///< evaluations per start at most
};

/// One stage of the worst-point search: how many points it evaluated and the worst it found there.
struct SearchStage {
  std::string name;  ///< "random", "edges", "corners", "features", "grazing", "climb"
  std::size_t points = 0;
  double worst = 0.0;
  std::vector<double> at;  ///< coordinates of its worst point (empty when it evaluated none)
};

/// |sampled − exact| / denominator over the points.
struct SampledErrorStats {
  std::size_t points = 0;
  double worst = 0.0, p99 = 0.0, mean = 0.0;
  double worst_abs = 0.0;  ///< largest |sampled − exact| (absolute, in the table's units)
};

struct SampledError {
  std::string path;
  std::string denominator;   ///< TableTruth::denominator
  SampledErrorStats error;   ///< the table as stored
  SampledErrorStats half;    ///< rounded to half floats (points = 0 unless asked)
  /// The worst point found: of the random points alone, or of every stage of the search when
  /// options.search (then `found` ≥ error.worst and `stages` tells where each stage looked).
  double found = 0.0;
  std::vector<SearchStage> stages;
  std::vector<double> worst_at;  ///< coordinates of the worst point found (one per axis)
  double worst_sampled = 0.0, worst_exact = 0.0, worst_denominator = 0.0;
  /// Per axis: the worst error among the points in each cell between two nodes (count − 1 cells;
  /// one entry for a single-node or channel axis, whose points lie on nodes).
  std::vector<std::vector<double>> per_axis_cells;
  std::vector<std::vector<double>> x;  ///< every point (keep_points)
  std::vector<double> rel;             ///< its relative error (keep_points)
};

/// Cell of axis a that x falls in (0 … count − 2), after the axis's wrap rule; 0 for a
/// single-node axis.
int cell_of(const GridAxis& a, double x);

/// Measures table t of `set` against `truth` (table_truth(t, ...)). Points: slabs of the truth's
/// slab axes drawn at random, 4 lines per slab (the axes other than the slab and peak axes), 8
/// points per line along the peak axis (32 per slab without a peak axis). Each coordinate is
/// uniform over the axis's declared range [lo, hi] (log-uniform on log axes, a random node on
/// channel and other explicit axes with labels, uniform between the ends on other explicit axes),
/// so each point is uniform over the domain. The peak along the peak axis (of truth.make_fast when
/// given, e.g. N_p's Fourier series, else of the reference): 129 points, then golden section on the
/// two cells around the largest (exact to ~1e−8 of the axis for a peak the 129-point grid
/// resolves; a narrower peak between grid points is underestimated, which overstates the error).
/// Throws DomainError (naming the table) when an evaluation throws; on options.cancel it returns
/// early with the points measured so far.
SampledError measure_sampled_error(const TableSet& set, const Table& t, const TableTruth& truth, const SampledErrorOptions& options = {});
/// The same measure of a function that is not one table of a set (N_p of a Fourier table through
/// its evaluator, fourier_tables.hpp): the points are drawn over `domain`'s axes (their ranges and
/// spacings; the counts only delimit the cells of per_axis_cells), `sampled` is called at each,
/// from several threads at once, and its path names it. No half-float figures (half.points = 0).
SampledError measure_sampled_error(const Table& domain, const PointFunction& sampled, const TableTruth& truth, const SampledErrorOptions& options = {});

}  // namespace hairlut
