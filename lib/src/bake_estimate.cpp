#include "hairlut/bake_estimate.hpp"

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

namespace hairlut {
namespace {

constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();

std::uint64_t mul(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r = 0;
  return __builtin_mul_overflow(a, b, &r) ? kMax : r;
}
std::uint64_t add(std::uint64_t a, std::uint64_t b) { return a > kMax - b ? kMax : a + b; }

// Product of the axis counts, leaving out the axes named in `skip`.
std::uint64_t grid(const std::vector<GridAxis>& axes, const std::vector<std::string>& skip = {}) {
  std::uint64_t n = 1;
  for (const GridAxis& a : axes)
    if (std::find(skip.begin(), skip.end(), a.name) == skip.end()) n = mul(n, static_cast<std::uint64_t>(std::max(a.count, 0)));
  return n;
}

}  // namespace

BakeEstimate estimate_bake(const BakeConfig& c) {
  const std::uint64_t lobes = static_cast<std::uint64_t>(std::max(c.lobe_count, 0)) + (c.residual ? 1 : 0);
  std::uint64_t values = 0;
  if (c.np_axes) {
    values = add(values, mul(grid(*c.np_axes), lobes));                                 // N_p per lobe
    values = add(values, mul(grid(*c.np_axes, {"phi", "phi_h"}), lobes));               // lobe energies
  }
  if (c.mp_axes) values = add(values, mul(grid(*c.mp_axes), lobes));
  if (c.melanin_axes) values = add(values, mul(grid(*c.melanin_axes), 3));              // RGB sigma_a
  if (c.dual_scattering) values = add(values, grid(c.dual_scattering->axes));           // at least one table
  BakeEstimate e;
  e.values = values;
  const std::uint64_t stored = c.output.hdf5_double ? 8 : 4;
  e.memory_bytes = mul(values, 2 * stored);
  std::uint64_t per_value = 0;
  if (c.output.hdf5) per_value += stored;
  if (c.output.exr) per_value += c.output.exr_half ? 2 : 4;
  e.disk_bytes = mul(values, per_value);
  return e;
}

}  // namespace hairlut
