// Direct evaluation of what a baked table approximates: the reference against which the
// validator and the sampled-error measure judge a table, by table kind (d'Eon N_p, residual and
// energies, M_p; each model of lib/models/ with stages of its own and each kind of lib/kinds/
// gives its own).
// Independent of the baker's algorithms where it matters: N_p by Gauss–Legendre of order 1024 in γ (the adaptive reference
// below β = 1°), energies by the adaptive lobe-energy reference at 1e−13.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hairlut/physics/attenuation.hpp"
#include "hairlut/bake/config.hpp"
#include "hairlut/util/quadrature.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

class ModelKind;
struct ModelSettings;

/// The fiber the tables were baked for (from the set's metadata).
struct TruthModel {
  double eta = 1.55;
  AbsorptionPath path = AbsorptionPath::chord;
  int explicit_lobes = 3;                      ///< lobes before the residual (R, TT, TRT, ...)
  /// The model (lib/models/) and its settings from the metadata; a model's own tables are judged
  /// by its ModelKind::truth (unset or without settings: d'Eon's tables only).
  const ModelKind* model = nullptr;
  std::shared_ptr<const ModelSettings> settings;
};

/// The exact value of a table's quantity at a point x (one coordinate per axis of the table).
using PointFunction = std::function<double(const std::vector<double>&)>;

/// The reference of one table and the denominator its errors are divided by.
struct TableTruth {
  /// Points that share these axes' coordinates share one precomputation (make()'s argument is a
  /// full point; only these coordinates are read).
  std::vector<int> slab_axes;
  std::function<PointFunction(const std::vector<double>&)> make;
  /// The same quantity for the white fiber (σa = 0, the rest unchanged); empty when the table has
  /// no absorption.
  std::function<PointFunction(const std::vector<double>&)> make_white;
  /// Denominator: the peak of |exact| along this axis over [peak_lo, peak_hi] at the point's other
  /// coordinates (φ of N_p, θr of M_p); −1: |exact| at the point itself.
  int peak_axis = -1;
  /// Optional: a cheaper evaluation of the same function for the peak search (the Fourier series of
  /// N_p at 1e−10), for a slab and the white fiber (true) or not; make/make_white otherwise.
  std::function<PointFunction(const std::vector<double>&, bool white)> make_fast;
  double peak_lo = 0.0, peak_hi = 0.0;
  /// Optional: where along the peak axis the quantity has features at the point's other
  /// coordinates (N_p: the caustics and the lobe's edges, Φ(p, h) at dΦ/dh = 0 and h = ±1; M_p: the
  /// specular cone θr = α − θi), for the worst-point search to look at and around.
  std::function<std::vector<double>(const std::vector<double>&)> features;
  /// Whether the exact quantity is cheap enough (M_p: one Bessel function) for the search to scan
  /// the peak axis densely at the middle of every cell of the other axes.
  bool sweep_cells = false;
  /// The denominator is at least white_floor × (the same denominator of the white fiber) and at
  /// least absolute_floor.
  double white_floor = 0.0;
  double absolute_floor = 0.0;
  std::string denominator;  ///< the denominator in words, for reports
};

/// The denominators table_truth() gives, for a model's own tables (ModelKind::truth): an N_p's
/// peak over φ (the table's axis phi_axis) floored at 1e-3 of the white fiber's; an energy's own
/// value floored at 1e-3 of the white fiber's and at 1e-6; an M_p's peak over θr in [−π/2, π/2].
TableTruth with_np_denominator(TableTruth t, int phi_axis);
TableTruth with_energy_denominator(TableTruth t);
TableTruth with_mp_denominator(TableTruth t, int theta_r_axis);

/// The reference for table t, or nullopt for a kind without one (dual-scattering, engine tables).
std::optional<TableTruth> table_truth(const Table& t, const TruthModel& model, std::shared_ptr<const GaussLegendreRule> rule);

}  // namespace hairlut

namespace hairlut {

/// dual_scattering() results shared by the tables of the dual-scattering and mean-energy groups
/// (they are sampled at the same points: the same seed and axes give the same points). Thread-safe.
struct DualScatteringMemo;
std::shared_ptr<DualScatteringMemo> make_dual_scattering_memo();

/// The reference of a dual-scattering or mean-energy table (tables.dual_scattering, tables.engine;
/// described by the set's metadata "dual_scattering.groups"): dual_scattering() at the point, with
/// the group's roughness and absorption mappings, no interpolation anywhere. Denominator: the
/// exact value itself (relative error) floored at 1e-3 for attenuations and energies, 1e-3 rad for
/// shifts and widths, 1e-6 rad² for variances. nullopt for other tables.
std::optional<TableTruth> dual_scattering_truth(const TableSet& set, const Table& t, std::shared_ptr<DualScatteringMemo> memo = {});

}  // namespace hairlut
