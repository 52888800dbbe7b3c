// Table axes: where the nodes of a baked table lie, with names and units that describe them.
// The node placement and the interpolation rule are those of the header-only sampler
// (hairlut/sampler/sampler.hpp), so that what is baked and what is sampled agree exactly.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "hairlut/sampler/sampler.hpp"

namespace hairlut {

using sampler::Placement;
using sampler::Spacing;
using sampler::Wrap;
using sampler::Interpolation;
using sampler::End;

std::string_view to_string(Spacing s);
std::string_view to_string(Placement p);
std::string_view to_string(Wrap w);
/// Parsers of the names above; throw DomainError naming `what` on an unknown name.
Spacing parse_spacing(std::string_view text, std::string_view what);
Placement parse_placement(std::string_view text, std::string_view what);
Wrap parse_wrap(std::string_view text, std::string_view what);
std::string_view to_string(Interpolation i);
Interpolation parse_interpolation(std::string_view text, std::string_view what);
std::string_view to_string(End e);
End parse_end(std::string_view text, std::string_view what);

/// One axis of a table.
struct GridAxis {
  std::string name;       ///< identifier, e.g. "theta_d" (also the HDF5 dimension-scale name)
  std::string units;      ///< "rad", "1/radius" (absorption per unit fiber radius), "1" ...
  std::string long_name;  ///< human-readable description
  Spacing spacing = Spacing::uniform;
  Placement placement = Placement::edges;
  Wrap wrap = Wrap::clamp;
  Interpolation interpolation = Interpolation::linear;  ///< along this axis (see sampler.hpp)
  End lo_end = End::extrapolate;  ///< mirror: cubic taps beyond lo mirror (sqrt axes from 0 only)
  double lo = 0.0, hi = 1.0;
  int count = 1;
  std::vector<double> values;  ///< explicit nodes (Spacing::explicit_values only)
  std::vector<std::string> labels;  ///< optional node labels (e.g. "R", "G", "B" of a channel axis)

  /// The axis as the sampler sees it (points into `values`; valid while this object lives).
  sampler::Axis view() const;
  /// The node coordinates, in increasing order.
  std::vector<double> nodes() const;
  /// Throws DomainError("<where>.<field> ...") when the axis is not well formed: count < 1,
  /// lo ≥ hi, a mapping undefined on [lo, hi] (log of x ≤ 0, sqrt of x < 0, cos outside [0, π],
  /// sin outside [−π/2, π/2]), non-increasing explicit values, periodic without uniform spacing.
  void validate(const std::string& where) const;

  nlohmann::ordered_json to_json() const;
  /// Reads to_json()'s form back; throws DomainError naming `where` on missing or bad fields.
  static GridAxis from_json(const nlohmann::json& j, const std::string& where);
};

/// Throws DomainError naming `where` unless the axes' interpolations form a valid table: cubic
/// only on mapped (not explicit) axes with at least 3 nodes, at most one geometric axis.
void validate_interpolation(const std::vector<GridAxis>& axes, const std::string& where);

/// A channel axis of `labels.size()` entries (values 0, 1, 2, ...), e.g. {"R", "G", "B"}.
GridAxis channel_axis(std::vector<std::string> labels, std::string long_name);

/// Nodes first … first + count − 1 of a clamped axis as an axis of their own: the same spacing and
/// interpolation over the part's range, whose nodes are a's to rounding (a part of a table read
/// slab by slab). Throws DomainError naming `where` for nodes outside the axis, a periodic or a
/// labelled axis.
GridAxis narrowed_axis(const GridAxis& a, int first, int count, const std::string& where);

/// Product of the axes' counts, checked against overflow and a limit of 2^40 entries.
std::size_t grid_size(const std::vector<GridAxis>& axes);

}  // namespace hairlut
