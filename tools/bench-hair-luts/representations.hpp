// bench-hair-luts, section "representations": entries against worst and p99 sampled error and
// lookup cost per table representation (generic N_p domain; engine-preset budgets).
#pragma once

#include <cstdint>
#include <functional>
#include <hairlut/tables/grid.hpp>
#include <hairlut/tables/tables.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

namespace bench {

/// Bakes each representation in memory and measures it (quick: fewer cases and points).
nlohmann::ordered_json bench_representations(bool quick, bool quiet);
/// Writes representations.json, .csv, .md and .svg (Pareto plot) into out_dir.
void write_representations(const nlohmann::ordered_json& rows, const nlohmann::ordered_json& machine, const std::string& out_dir);

// The measure shared by every N_p representation of the section.

/// Worst and 99th percentile of the relative errors, and where the worst occurs.
struct ErrorStats {
  double worst = 0.0, p99 = 0.0;
  std::vector<double> where;  // coordinates of the worst point
};
ErrorStats error_stats(std::vector<double> errors, std::vector<std::vector<double>> at);

/// A uniformly random coordinate on an axis's declared range (log-uniform on log axes).
double draw(const hairlut::GridAxis& a, std::mt19937_64& rng);

/// The random points of the generic N_p measure over axes (beta, sigma_a, theta_d, phi): per slab
/// a random (σa, θd), 4 random β and 16 random φ; per lobe (index p of `lobes`) each point
/// x = (β, σa, θd, φ), its exact N_p (Fourier method at 1e−12) and its denominator (the peak over φ
/// of the same slice on 721 φ, floored at 1e−3 of the white fiber's peak).
struct NpPoints {
  std::vector<std::string> lobes;
  std::vector<std::vector<std::vector<double>>> x;
  std::vector<std::vector<double>> exact, den;
};
NpPoints np_points(const std::vector<hairlut::GridAxis>& axes, const std::vector<std::string>& lobes, double eta, int slabs, std::uint64_t seed);
/// Per lobe: worst and p99 of |value(p, x) − exact| / denominator over the points.
std::map<std::string, ErrorStats> np_errors(const NpPoints& points, const std::function<double(int p, const std::vector<double>& x)>& value);
/// Per-lobe worst, p99 and worst point into a result row, and their largest over the lobes.
void add_errors(nlohmann::ordered_json& row, const std::map<std::string, ErrorStats>& errors);

/// Bakes a d'Eon set of the generic lobes (R, TT, TRT, TRRT, tilts −4°, 2°, 6°, 10°, η 1.55) with the
/// given "tables" object, in memory.
hairlut::TableSet bake_tables(const nlohmann::ordered_json& tables, const std::string& name);

/// One table of the Fourier representation (tables.np.representation "fourier") over the generic
/// domain to measure: counts, each axis's interpolation, θd's spacing, the truncation tolerance.
struct FourierCase {
  std::string representation, label;
  int theta, sigma;
  std::string theta_interpolation, sigma_interpolation, theta_spacing;
  double tolerance;
  bool compare_lookup;  ///< time it against the plain multilinear lookup (float, double; in and out of cache)
};
/// The Fourier tables the section measures (quick: one).
std::vector<FourierCase> fourier_cases(bool quick);
/// Their rows: errors at `points`, size, lookup ns at random points over `axes` (β, σa, θd, φ), the
/// error of the truncation alone (exact C_n at each point, no table), and for the cases that ask,
/// the lookup against `plain`'s np/TRT read with every axis linear (FixedView) at the same points.
nlohmann::ordered_json fourier_representation_rows(const std::vector<FourierCase>& cases, const NpPoints& points,
                                                   const std::vector<hairlut::GridAxis>& axes, double eta, int lookups, bool quiet,
                                                   const hairlut::TableSet& plain, bool quick);

}  // namespace bench
