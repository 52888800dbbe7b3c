#include "hairlut/bake/bake_estimate.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "hairlut/physics/azimuthal_fourier.hpp"

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
  const bool generic = !c.marschner && !(c.scene && c.scene->mode == SceneConfig::Mode::per_material);
  std::uint64_t values = 0, slabbable = 0, row = 0;
  if (c.np_axes) {
    const std::uint64_t explicit_lobes = static_cast<std::uint64_t>(std::max(c.lobe_count, 0));
    values = add(values, mul(grid(*c.np_axes), explicit_lobes));                        // N_p per explicit lobe
    if (generic) {
      slabbable = add(slabbable, mul(grid(*c.np_axes), explicit_lobes));
      row = std::max(row, grid(*c.np_axes, {"beta"}));
    }
    values = add(values, mul(grid(*c.np_axes, {"phi", "phi_h"}), lobes + (c.residual ? 1 : 0)));  // energies, residual
  }
  if (c.np_fourier) {  // the coefficients per explicit lobe; the residual's, the energy and residual tables (energy axes)
    const FourierNpConfig& f = *c.np_fourier;
    const auto terms = static_cast<std::uint64_t>((fourier_terms(f.beta_lo, f.tolerance) + 4) / 4 * 4);
    values = add(values, mul(mul(grid(f.axes), terms), static_cast<std::uint64_t>(std::max(c.lobe_count, 0))));
    const std::uint64_t energy = c.np_energy_axes ? grid(*c.np_energy_axes) : grid(f.axes);
    values = add(values, mul(energy, lobes + (c.residual ? 2 : 0)));
  }
  if (c.mp_axes) {
    values = add(values, mul(grid(*c.mp_axes), lobes));
    if (generic) {
      slabbable = add(slabbable, mul(grid(*c.mp_axes), lobes));
      row = std::max(row, grid(*c.mp_axes, {"beta"}));
    }
  }
  if (c.melanin_axes) values = add(values, mul(grid(*c.melanin_axes), 3));              // RGB sigma_a
  if (c.dual_scattering) values = add(values, grid(c.dual_scattering->axes));           // at least one table
  BakeEstimate e;
  e.values = values;
  e.slabbable_values = std::min(slabbable, values);
  e.slabbable_row_values = row;
  const std::uint64_t stored = c.output.hdf5_double ? 8 : 4;
  e.value_bytes = stored;
  e.memory_bytes = mul(values, 2 * stored);
  std::uint64_t per_value = 0;
  if (c.output.hdf5) per_value += stored;
  if (c.output.exr) per_value += c.output.exr_half ? 2 : 4;
  e.disk_bytes = mul(values, per_value);
  return e;
}

MemoryPlan plan_memory(const BakeEstimate& e, std::uint64_t budget) {
  MemoryPlan plan;
  plan.peak_bytes = add(e.memory_bytes, kBakeOverheadBytes);
  if (budget == 0 || plan.peak_bytes <= budget) return plan;
  // Slabbed: the other tables held whole (written to disk directly, no file image), two slabs.
  const std::uint64_t whole = mul(e.values - e.slabbable_values, e.value_bytes);
  constexpr std::uint64_t kMinSlab = std::uint64_t{4} << 20, kMaxSlab = std::uint64_t{256} << 20;
  const std::uint64_t fixed = add(whole, kBakeOverheadBytes);
  const std::uint64_t row_bytes = mul(e.slabbable_row_values, e.value_bytes);
  plan.minimum_bytes = e.slabbable_values == 0 ? plan.peak_bytes : add(fixed, mul(2, std::max(row_bytes, kMinSlab)));
  char buf[240];
  if (e.slabbable_values == 0 || fixed > budget || (budget - fixed) / 2 < kMinSlab) {
    std::snprintf(buf, sizeof buf, "the tables need about %.0f MiB of memory, more than the memory budget of %.0f MiB%s",
                  static_cast<double>(plan.peak_bytes) / 1048576.0, static_cast<double>(budget) / 1048576.0,
                  e.slabbable_values == 0 ? " (none of them can be baked slab by slab)"
                                          : " even with the generic N_p and M_p tables baked slab by slab");
    plan.refused = buf;
    return plan;
  }
  if (row_bytes > (budget - fixed) / 2) {
    std::snprintf(buf, sizeof buf, "one beta row of the generic N_p or M_p tables takes about %.0f MiB; two of them do not fit in the memory "
                  "budget of %.0f MiB beside the rest (about %.0f MiB)",
                  static_cast<double>(row_bytes) / 1048576.0, static_cast<double>(budget) / 1048576.0, static_cast<double>(fixed) / 1048576.0);
    plan.refused = buf;
    return plan;
  }
  plan.slabbed = true;
  plan.slab_bytes = std::max(std::min((budget - fixed) / 2, kMaxSlab), row_bytes);
  // Nothing is gained by slabs larger than the slabbable tables.
  plan.slab_bytes = std::max(std::min(plan.slab_bytes, mul(e.slabbable_values, e.value_bytes)), kMinSlab);
  plan.peak_bytes = add(fixed, 2 * plan.slab_bytes);
  return plan;
}

}  // namespace hairlut
