// Whether two grid axes are the same object field for field, bit for bit: a quick test that
// implies equal GridAxis::to_json() forms (to_json is a function of these fields), without
// building them. It can say "not identical" for axes whose JSON forms agree (e.g. lo = −0.0
// against 0.0, or explicit values that nodes() would rebuild the same), so callers fall back to
// comparing the JSON forms when it fails.
#pragma once

#include <cstring>

#include "hairlut/tables/grid.hpp"

namespace hairlut::detail {

inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

inline bool identical_axes(const GridAxis& a, const GridAxis& b) {
  if (a.name != b.name || a.units != b.units || a.long_name != b.long_name || a.spacing != b.spacing || a.placement != b.placement ||
      a.wrap != b.wrap || a.interpolation != b.interpolation || a.lo_end != b.lo_end || a.count != b.count || !same_bits(a.lo, b.lo) || !same_bits(a.hi, b.hi) ||
      a.values.size() != b.values.size() || a.labels != b.labels)
    return false;
  return a.values.empty() || std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(double)) == 0;
}

}  // namespace hairlut::detail
