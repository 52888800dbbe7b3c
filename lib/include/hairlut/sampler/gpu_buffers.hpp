// Generic d'Eon tables laid out for lib/shaders/hairlut_generic.glsl: one HairlutGenericSet block
// (which tables serve each lobe, every table's axes, prepared as FixedView<float> prepares them)
// and one float array of every table's values, row-major as stored. Header-only, C++17, on the
// header-only runtime's HairTables (hairlut::hair_tables<float, R>(set) fills them from a loaded
// set, as tests/gpu/test_gpu_generic.cpp does; an engine that reads the files itself fills them
// from the sidecar).
//
// What the shader reconstructs: axes of uniform, cos, sin, log or sqrt spacing that clamp, and
// even azimuths (φ); linear, Catmull–Rom (with mirror and extrapolated ends) and geometric
// interpolation. Sets baked in β bands, Fourier N_p and explicit or periodic axes are refused
// with std::invalid_argument naming the table.
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "hairlut/sampler/sampler_fiber.hpp"

namespace hairlut::gpu {

constexpr int kGenericMaxTables = 24;  // HAIRLUT_GENERIC_MAX_TABLES
constexpr int kGenericMaxAxes = 80;    // HAIRLUT_GENERIC_MAX_AXES

/// The GLSL structs of hairlut_generic.glsl (std140 and std430 alike: every member 16 bytes).
struct GpuAxis {
  float map[4];           // t0, scale, offset, top
  float range[4];         // lo, hi, snap, 0
  std::int32_t mode[4];   // count, spacing, flags, stride
};
struct GpuTable {
  std::int32_t head[4];   // first value, first axis, axes, cos power of the grazing factor
  float grazing[4];       // x_scale, τ, b, c
  float grazing2[4];      // d, e, f, 0
};
struct GpuGenericSet {
  std::int32_t lobes[4];      // explicit lobes, residual (0/1)
  std::int32_t np[8];
  std::int32_t energy[8];
  std::int32_t mp[8];
  std::int32_t residual[4];   // N, its energy factor, M_p
  GpuTable tables[kGenericMaxTables];
  GpuAxis axes[kGenericMaxAxes];
};
static_assert(sizeof(GpuAxis) == 48 && sizeof(GpuTable) == 48, "the GLSL structs are 48 bytes");
static_assert(sizeof(GpuGenericSet) == 128 + 48 * (kGenericMaxTables + kGenericMaxAxes), "HairlutGenericSet's std140 size");

struct GenericBuffers {
  GpuGenericSet set{};
  std::vector<float> data;  // every table's values (a storage buffer)
  int tables = 0, axes = 0;

  GenericBuffers() = default;
  /// Lays out the tables of one set (every explicit lobe's N_p, energy and M_p, the residual's).
  template <class T, class R>
  explicit GenericBuffers(const hairlut::sampler::HairTables<T, R>& t) {
    if (t.beta_bands != 1) throw std::invalid_argument("hairlut_generic.glsl: sets baked in beta bands are not supported");
    if (t.lobes < 1 || t.lobes > 8) throw std::invalid_argument("hairlut_generic.glsl: 1 to 8 explicit lobes");
    for (int k = 0; k < 8; ++k) set.np[k] = set.energy[k] = set.mp[k] = -1;
    set.lobes[0] = t.lobes;
    set.lobes[1] = t.has_residual ? 1 : 0;
    for (int p = 0; p < t.lobes; ++p) {
      const std::string lobe = "lobe " + std::to_string(p);
      if (!t.np[p].valid() || !t.mp[p].valid()) throw std::invalid_argument("hairlut_generic.glsl: " + lobe + " has no N_p or M_p table (Fourier sets are not supported)");
      set.np[p] = add(t.np[p].table(), {}, "N_p of " + lobe);
      if (t.np[p].has_energy()) set.energy[p] = add(t.np[p].energy(), t.np[p].energy_factor(), "energy of " + lobe);
      set.mp[p] = add(t.mp[p].table(), {}, "M_p of " + lobe);
    }
    set.residual[0] = set.residual[1] = set.residual[2] = -1;
    if (t.has_residual) {
      set.residual[0] = add(t.np_residual.table(), t.np_residual.factor(), "the residual's N");
      if (t.np_residual.has_energy()) set.residual[1] = add(t.np_residual.energy(), t.np_residual.energy_factor(), "the residual's energy");
      set.residual[2] = add(t.mp_residual.table(), {}, "the residual's M_p");
    }
  }

 private:
  template <class T, int D, class R>
  int add(const hairlut::sampler::FixedView<T, D, R>& view, const hairlut::sampler::GrazingFactor& g, const std::string& what) {
    using namespace hairlut::sampler;
    if (tables >= kGenericMaxTables || axes + D > kGenericMaxAxes) throw std::invalid_argument("hairlut_generic.glsl: too many tables");
    GpuTable& tb = set.tables[tables];
    tb.head[0] = static_cast<std::int32_t>(data.size());
    tb.head[1] = axes;
    tb.head[2] = D;
    tb.head[3] = g.cos_power;
    const float gz[8] = {static_cast<float>(g.x_scale), static_cast<float>(g.tau), static_cast<float>(g.b), static_cast<float>(g.c),
                         static_cast<float>(g.d), static_cast<float>(g.e), static_cast<float>(g.f), 0.0f};
    for (int k = 0; k < 4; ++k) tb.grazing[k] = gz[k], tb.grazing2[k] = gz[4 + k];
    std::size_t n = 1;
    for (int d = 0; d < D; ++d) {
      const Axis& a = view.axis(d).axis();
      const std::string name = what + ", axis " + std::to_string(d);
      if (a.count > 1 && (a.spacing == Spacing::explicit_values || a.wrap == Wrap::periodic || a.wrap == Wrap::reflect))
        throw std::invalid_argument("hairlut_generic.glsl: " + name + " has explicit nodes or a periodic or reflecting wrap");
      const PreparedAxis p(a);
      GpuAxis& g_axis = set.axes[axes++];
      g_axis.map[0] = static_cast<float>(p.t0), g_axis.map[1] = static_cast<float>(p.scale), g_axis.map[2] = static_cast<float>(p.offset);
      g_axis.map[3] = static_cast<float>(a.count > 1 ? a.count - 1 : 0);
      // FixedAxis<float>'s snapping distance: a few ulps of the largest node index.
      g_axis.range[0] = static_cast<float>(a.lo), g_axis.range[1] = static_cast<float>(a.hi);
      g_axis.range[2] = static_cast<float>(8.0 * 1.1920928955078125e-07 * (a.count > 1 ? a.count : 1));
      const double pi = 3.14159265358979323846;
      const bool even = a.wrap == Wrap::even, cos_spaced = a.spacing == Spacing::cos;
      int flags = 0;
      if (a.interpolation == Interpolation::cubic) flags |= 1;
      if (a.interpolation == Interpolation::geometric) flags |= 2;
      if (even) flags |= 4;
      if ((even && !cos_spaced && a.lo == 0.0) || a.lo_end == End::mirror) flags |= 8;  // sampler.hpp's wrapped_index
      if (even && !cos_spaced && a.hi == pi) flags |= 16;
      if (a.placement == Placement::centers) flags |= 32;
      g_axis.mode[0] = a.count, g_axis.mode[1] = static_cast<std::int32_t>(a.spacing), g_axis.mode[2] = flags;
      g_axis.mode[3] = static_cast<std::int32_t>(view.axis(d).stride());
      n *= static_cast<std::size_t>(a.count);
    }
    // Values that are NaN or infinite would poison every sum they enter: stored as 0 (the loaders
    // refuse such files; a set built in memory is the caller's).
    for (std::size_t i = 0; i < n; ++i) {
      const float v = static_cast<float>(view.data()[i]);
      data.push_back(std::isfinite(v) ? v : 0.0f);
    }
    return tables++;
  }
};

}  // namespace hairlut::gpu
