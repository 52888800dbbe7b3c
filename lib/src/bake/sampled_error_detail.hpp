// What the sampled-error measure (sampled_error.cpp) and its worst-point search
// (worst_point_search.cpp) share: the seeded draws along an axis, a point's record, the peak of
// the truth along a line, and the search itself.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hairlut/bake/sampled_error.hpp"

namespace hairlut::detail::sampled {

inline constexpr std::size_t kLinesPerSlab = 4;
inline constexpr std::size_t kPointsPerLine = 8;
inline constexpr std::size_t kPointsPerSlab = kLinesPerSlab * kPointsPerLine;

inline std::uint64_t mix(std::uint64_t z) {  // splitmix64 finalizer
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

struct Random {
  std::uint64_t state;
  double uniform() {  // [0, 1)
    state += 0x9e3779b97f4a7c15ULL;
    return static_cast<double>(mix(state) >> 11) * 0x1.0p-53;
  }
};

/// The domain measured along an axis: its range, except that a θd axis ending within 2° short of
/// 90° is measured up to 90° (a renderer asks up to grazing; beyond the last node it reads that
/// node, or the limit where the table stores E / cos^n θd). Axes of smaller ranges are subsets the
/// config chose.
double domain_hi(const GridAxis& a);
/// Whether the axis is measured at its nodes only (channels, labelled values, a single node).
bool on_nodes(const GridAxis& a);
/// A uniform draw along the axis (log along a log axis; a node where on_nodes).
double draw(const GridAxis& a, Random& r);
/// Largest |f| along axis k over [lo, hi] with the other coordinates of x: a grid, then golden
/// section on the two cells around the grid's largest value.
double peak_along(const PointFunction& f, std::vector<double> x, int k, double lo, double hi);

struct Sample {
  std::vector<double> x;
  double sampled, exact, denominator, rel, rel_half;
};

/// A stage's record: its name, points, and the worst of them and where.
SearchStage stage_of(const std::string& name, const std::vector<Sample>& s);

/// The stages after the random points (`all`, to which every point evaluated is appended): the
/// first and last cell of every axis and every corner, known features, every cell where the exact
/// value is cheap, grazing ends, then local maximisation from the worst points found.
std::vector<SearchStage> worst_point_search(const Table& t, const PointFunction& sampled, const TableTruth& truth, const SampledErrorOptions& opt,
                                            int threads, std::vector<Sample>& all);

}  // namespace hairlut::detail::sampled
