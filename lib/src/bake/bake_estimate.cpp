#include "hairlut/bake/bake_estimate.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "hairlut/bake/dual_scattering_grid.hpp"
#include "hairlut/bake/engine_preset.hpp"
#include "hairlut/bake/engine_presets.hpp"
#include "hairlut/bake/model_kind.hpp"
#include "hairlut/physics/azimuthal_fourier.hpp"
#include "hairlut/sampler/axis_sampling.hpp"

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

const GridAxis* named(const std::vector<GridAxis>& axes, const std::string& name) {
  for (const GridAxis& a : axes)
    if (a.name == name) return &a;
  return nullptr;
}

// Whether the importance sampler supports a table over `axes` sampled along the last
// (table_sampling.cpp writes sampling data exactly for those).
bool sampled(const std::vector<const GridAxis*>& axes) {
  std::vector<sampler::Axis> views;
  for (const GridAxis* a : axes) {
    if (!a) return false;
    views.push_back(a->view());
  }
  return views.size() >= 2 && sampler::AxisSampler<float>::supports(views.data(), static_cast<int>(views.size()));
}

// Whether any of the axes interpolates cubically: only then can an interpolant of non-negative
// values dip below 0, so that the sampler's clamp acts and its bounds are not all 0.
bool cubic(const std::vector<const GridAxis*>& axes) {
  return std::any_of(axes.begin(), axes.end(), [](const GridAxis* a) { return a && a->interpolation == Interpolation::cubic; });
}

// The tally of tables, one call per table (or per `copies` identical tables).
struct Tally {
  std::uint64_t values = 0, table_bytes = 0, sampling_bytes = 0, sampling_values = 0, largest = 0, tables = 0;
  std::uint64_t value_bytes = 4;
  bool sampling = true;
  double deflated = 0.0;  // the bytes of tables and sampling data expected after deflate
  // `n` values per table; `last`: the count of the sampled axis when the sampler's data are
  // written beside it (0: none); `fraction`: what deflate leaves of the table's bytes;
  // `overshoots`: the table has a cubic axis (its clamp bounds are not all 0).
  void table(std::uint64_t n, std::uint64_t copies = 1, std::uint64_t last = 0, double fraction = kDeflatedFraction,
             bool overshoots = true) {
    values = add(values, mul(n, copies));
    table_bytes = add(table_bytes, mul(mul(n, value_bytes), copies));
    deflated += fraction * static_cast<double>(n) * static_cast<double>(value_bytes) * static_cast<double>(copies);
    largest = std::max(largest, mul(n, value_bytes));
    tables = add(tables, copies);
    if (sampling && last > 0) {
      const std::uint64_t slices = n / last;
      sampling_bytes = add(sampling_bytes, mul(add(mul(n, 12), mul(slices, 8)), copies));
      sampling_values = add(sampling_values, mul(add(mul(n, 2), slices), copies));
      deflated += (kDeflatedPrefixFraction * 8.0 * (static_cast<double>(n) + static_cast<double>(slices)) +
                   (overshoots ? kDeflatedClampFraction : 0.0) * 4.0 * static_cast<double>(n)) *
                  static_cast<double>(copies);
      largest = std::max(largest, mul(n, 8));
      tables = add(tables, mul(3, copies));
    }
  }
};

// Tables of a dual-scattering or mean-energy group with L lobe entries (explicit and residual):
// the ten shared dual-scattering quantities and a_f, a_b per lobe; E per lobe and the total.
std::uint64_t dual_scattering_tables(std::uint64_t lobes) { return 10 + 2 * lobes; }
std::uint64_t mean_energy_tables(std::uint64_t lobes) { return lobes + 1; }

// Bytes of the curves over θd that the dual-scattering grid holds while its group bakes
// (dual_scattering_grid.cpp): per absorption node, the energy of each of the L lobe entries and,
// per explicit lobe, b and f for each distinct azimuthal width (at most one per roughness node),
// as doubles at the grid's J + 1 nodes. Freed before the next group and before the files are
// written.
std::uint64_t dual_scattering_curve_bytes(const std::vector<GridAxis>& axes, const std::string& absorption, const std::string& roughness,
                                          std::uint64_t explicit_lobes, std::uint64_t lobes) {
  const GridAxis* k = named(axes, absorption);
  const GridAxis* r = named(axes, roughness);
  if (!k || !r) return 0;
  const auto nodes = static_cast<std::uint64_t>(DualScatteringGridRequest{}.theta_d_intervals) + 1;
  const std::uint64_t widths = mul(static_cast<std::uint64_t>(std::max(r->count, 0)), explicit_lobes);
  return mul(mul(8, nodes), mul(static_cast<std::uint64_t>(std::max(k->count, 0)), add(lobes, mul(2, widths))));
}

}  // namespace

BakeEstimate estimate_bake(const BakeConfig& c, int threads) {
  const std::uint64_t explicit_lobes = static_cast<std::uint64_t>(std::max(c.lobe_count, 0));
  const std::uint64_t lobes = explicit_lobes + (c.residual ? 1 : 0);
  const bool per_material = c.scene && c.scene->mode == SceneConfig::Mode::per_material;
  const ModelKind& model = c.model_kind();
  const bool generic = model.slab_by_slab() && !per_material;  // d'Eon's generic tables, the ones baked slab by slab
  Tally t;
  t.value_bytes = c.output.hdf5_double ? 8 : 4;
  t.sampling = c.output.sampling_data;
  std::uint64_t slabbable = 0, row = 0;
  if (c.np_axes && generic) {  // N_p over (β, σa, θd, φ) per explicit lobe; energies and the residual over (σa, θd)
    const std::vector<GridAxis>& ax = *c.np_axes;
    const std::vector<const GridAxis*> order = {named(ax, "beta"), named(ax, "sigma_a"), named(ax, "theta_d"), named(ax, "phi")};
    t.table(grid(ax), explicit_lobes, sampled(order) ? static_cast<std::uint64_t>(named(ax, "phi")->count) : 0, kDeflatedFraction,
            cubic(order));
    slabbable = add(slabbable, mul(grid(ax), explicit_lobes));
    row = std::max(row, grid(ax, {"beta"}));
    t.table(c.np_energy_axes ? grid(*c.np_energy_axes) : grid(ax, {"beta", "phi"}), explicit_lobes + (c.residual ? 2 : 0));
  }
  if (c.np_axes && per_material) {  // per material: RGB N_p over (θd, φ) per explicit lobe, the residual's and the energies over θd
    const std::vector<GridAxis>& ax = *c.np_axes;
    const GridAxis rgb = channel_axis({"R", "G", "B"}, "channel");
    const std::vector<const GridAxis*> order = {&rgb, named(ax, "theta_d"), named(ax, "phi")};
    const auto materials = static_cast<std::uint64_t>(c.scene->materials.size());
    const std::uint64_t slice = grid(ax, {"beta", "sigma_a", "phi"});  // θd (the generic axes are not baked)
    t.table(mul(mul(3, slice), grid(ax, {"beta", "sigma_a", "theta_d"})), mul(explicit_lobes, materials),
            sampled(order) ? static_cast<std::uint64_t>(named(ax, "phi")->count) : 0, kDeflatedFraction, cubic(order));
    t.table(mul(3, slice), mul(lobes + (c.residual ? 1 : 0), materials));
  }
  for (const PlannedTable& pt : model.own_np_tables(c)) {  // a model's own N_p stage (lib/models/)
    std::vector<const GridAxis*> order;
    for (const GridAxis& a : pt.axes) order.push_back(&a);
    if (pt.sampled) t.table(grid(pt.axes), 1, sampled(order) ? static_cast<std::uint64_t>(pt.axes.back().count) : 0, kDeflatedFraction, cubic(order));
    else t.table(grid(pt.axes));
  }
  if (c.np_fourier && !per_material) {  // the coefficients per explicit lobe; the residual's, the energy and residual tables (energy axes)
    const FourierNpConfig& f = *c.np_fourier;
    const auto terms = static_cast<std::uint64_t>((fourier_terms(f.beta_lo, f.tolerance) + 4) / 4 * 4);
    t.table(mul(grid(f.axes), terms), explicit_lobes);
    t.table(c.np_energy_axes ? grid(*c.np_energy_axes) : grid(f.axes), lobes + (c.residual ? 2 : 0));
  }
  if (c.mp_axes) {  // M_p per lobe and the residual (per material without β)
    const std::vector<GridAxis>& ax = *c.mp_axes;
    if (per_material) {
      const std::vector<const GridAxis*> order = {named(ax, "theta_i"), named(ax, "theta_r")};
      t.table(grid(ax, {"beta"}), mul(lobes, static_cast<std::uint64_t>(c.scene->materials.size())),
              sampled(order) ? static_cast<std::uint64_t>(named(ax, "theta_r")->count) : 0, kDeflatedMpFraction, cubic(order));
    } else {
      const std::vector<const GridAxis*> order = {named(ax, "beta"), named(ax, "theta_i"), named(ax, "theta_r")};
      t.table(grid(ax), lobes, sampled(order) ? static_cast<std::uint64_t>(named(ax, "theta_r")->count) : 0, kDeflatedMpFraction,
              cubic(order));
      if (generic) {
        slabbable = add(slabbable, mul(grid(ax), lobes));
        row = std::max(row, grid(ax, {"beta"}));
      }
    }
  }
  for (const TableKindRequest& k : c.kinds)
    for (const TableKindSize& s : k.kind->sizes(*k.settings)) t.table(s.values, s.tables);
  std::uint64_t curves = 0;  // the largest dual-scattering grid's curves (one group bakes at a time)
  if (c.dual_scattering) {
    t.table(grid(c.dual_scattering->axes), dual_scattering_tables(lobes) + mean_energy_tables(lobes));
    curves = dual_scattering_curve_bytes(c.dual_scattering->axes, "sigma_a", "beta", explicit_lobes, lobes);
  }
  std::uint64_t texture_bytes = 0;
  double texture_zipped = 0.0;  // what zip is expected to leave of them
  if (c.engine) {
    try {
      for (const EngineTableSpec& spec : engine_preset_tables(*c.engine, c.residual)) {
        const std::uint64_t n = grid(spec.axes);
        // The dual-scattering and mean-energy groups every preset may have; the others, the preset's own kinds.
        const bool shared = spec.kind == "dual_scattering" || spec.kind == "mean_energy";
        const EnginePreset::GroupSize own = shared ? EnginePreset::GroupSize{} : engine_preset(c.engine->preset).group_size(spec);
        const std::uint64_t count = spec.kind == "dual_scattering" ? dual_scattering_tables(lobes)
                                    : spec.kind == "mean_energy"   ? mean_energy_tables(lobes)
                                                                   : own.tables;
        const GridAxis* rough = named(spec.axes, spec.roughness_axis);
        const bool flat = own.repeats_along_roughness && rough && rough->count > 0;
        auto repeated = [&](double fraction) { return flat ? fraction / rough->count + kDeflatedRepeatFraction : fraction; };
        t.table(n, count, 0, repeated(kDeflatedFraction));
        if (spec.kind == "dual_scattering") {  // its grid serves the preset's mean energy too
          const auto p = static_cast<std::uint64_t>(std::max(spec.roughness.lobes, 0));
          curves = std::max(curves, dual_scattering_curve_bytes(spec.axes, spec.absorption_axis, spec.roughness_axis, p,
                                                                p + (spec.roughness.residual ? 1 : 0)));
        }
        // Its textures: RGBA half per texel of the group's grid.
        for (const EngineTexture& tex : engine_preset_textures(*c.engine))
          if (tex.group == spec.group) {
            const std::uint64_t bytes = mul(n, 2 * static_cast<std::uint64_t>(tex.channel_count));
            texture_bytes = add(texture_bytes, bytes);
            texture_zipped += repeated(kHalfZipFraction) * static_cast<double>(bytes);
          }
      }
    } catch (const std::exception&) {
      // An unknown preset or texture: the config's validation refuses it.
    }
  }
  BakeEstimate e;
  e.values = t.values;
  e.slabbable_values = std::min(slabbable, t.values);
  e.slabbable_row_values = row;
  e.value_bytes = t.value_bytes;
  e.table_bytes = t.table_bytes;
  e.sampling_bytes = t.sampling_bytes;
  e.largest_table_bytes = t.largest;
  // The sidecar: about 8 KiB per table (its description and axis values) and 64 KiB of metadata.
  const std::uint64_t sidecar = add(std::uint64_t{64} << 10, mul(t.tables, std::uint64_t{8} << 10));
  const std::uint64_t held = add(t.table_bytes, t.sampling_bytes);
  const std::uint64_t thread_count = static_cast<std::uint64_t>(std::max(threads, 1));
  std::uint64_t writing = 0;  // beyond the tables while the largest file is written
  std::uint64_t disk = sidecar, expected = sidecar;
  // Deflate's share of this config's arrays in HDF5, kind by kind (tables, M_p tables, float64
  // prefix integrals, clamp bounds). OpenEXR stores the prefix integrals as float32 and its zip
  // differs: its float files keep the one fraction measured for them.
  const double fraction = held > 0 ? std::clamp(t.deflated / static_cast<double>(held), 0.0, 1.0) : kDeflatedFraction;
  auto compressed = [fraction](std::uint64_t bytes) { return static_cast<std::uint64_t>(static_cast<double>(bytes) * fraction); };
  if (c.output.hdf5) {
    const std::uint64_t file = add(held, sidecar);
    disk = add(disk, file);
    if (c.output.hdf5_deflate > 0) {
      // The image: the deflated file and one growth step of an eighth of the values; each
      // deflate thread (at most 4) holds a chunk (at most 4 MiB) twice.
      const std::uint64_t chunk = std::min(t.largest, std::uint64_t{4} << 20);
      writing = add(add(compressed(file), file / 8), mul(std::min<std::uint64_t>(thread_count, 4), mul(2, chunk)));
      expected = add(expected, compressed(file));
    } else {
      writing = file;
      expected = add(expected, file);
    }
  }
  if (c.output.exr) {
    // Every table and sampling array at half or float; written in strips of a few MiB per part.
    const std::uint64_t file = mul(add(t.values, t.sampling_values), c.output.exr_half ? 2 : 4);
    disk = add(disk, file);
    expected = add(expected, c.output.exr_compression == "none" ? file
                             : c.output.exr_half                ? static_cast<std::uint64_t>(static_cast<double>(file) * kHalfZipFraction)
                                                                : static_cast<std::uint64_t>(static_cast<double>(file) * kDeflatedFraction));
    writing = std::max(writing, std::min(file, std::uint64_t{16} << 20));
  }
  disk = add(disk, texture_bytes);
  expected = add(expected, static_cast<std::uint64_t>(texture_zipped));
  // The peak is while the files are written, or while a dual-scattering grid holds its curves
  // beside the tables (the sampling data come after it), before the writer has any state: the
  // program then takes kBakeProgramBytes, not kBakeBaseBytes.
  const std::uint64_t grid_phase = add(t.table_bytes, curves), no_writer = kBakeBaseBytes - kBakeProgramBytes;
  e.memory_bytes = add(std::max(add(held, writing), grid_phase > no_writer ? grid_phase - no_writer : 0), mul(thread_count, kBakeThreadBytes));
  e.disk_bytes = disk;
  e.disk_expected_bytes = expected;
  return e;
}

MemoryPlan plan_memory(const BakeEstimate& e, std::uint64_t budget) {
  MemoryPlan plan;
  plan.peak_bytes = add(e.memory_bytes, kBakeBaseBytes);
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
