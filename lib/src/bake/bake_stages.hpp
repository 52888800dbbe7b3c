// Internal: the stages bake() runs for a d'Eon 2011 config, in order (bake.cpp), each in the file of
// its table kind: generic N_p (bake_np.cpp), per-material N_p (bake_material_np.cpp), M_p
// (bake_mp.cpp); then the kinds of lib/kinds/ (table_kind.hpp), and dual scattering and engine
// presets in bake_engine.cpp.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "hairlut/bake/bake.hpp"
#include "hairlut/bake/beta_bands.hpp"
#include "hairlut/util/quadrature.hpp"

namespace hairlut::detail {

// What the stages of one bake share.
struct BakeRun {
  const BakeConfig* config;
  const BakeOptions& options;
  Precision precision;
  SlabbedTables* slabbed;          // non-null: tables over the memory budget are produced slab by slab
  int lobes;                       // explicit lobes after folding; p >= lobes go to the residual
  GaussLegendreRule energy_rule;   // the lobe energies' rule
  std::size_t unconverged = 0;     // adaptive N_p entries that did not reach the tolerance
  std::shared_ptr<GaussLegendreCache> rules = std::make_shared<GaussLegendreCache>();  // shared by the whole bake
};

// The N_p axes a bake uses: the config's (restricted to a scene's materials), or those target_error
// chose, with the representation (N_p or its shape N_p / E_p) and the energy tables' own axes.
struct NpPlan {
  std::vector<GridAxis> axes;  ///< band 0's axes when there are β bands
  bool normalize_energy = false;
  std::optional<std::vector<GridAxis>> energy_axes;
  std::vector<BetaBand> bands;  ///< β bands (the config's, or target_error's choice); empty: none
  /// Set when N_p is baked in the Fourier representation (the config's, or target_error's choice);
  /// axes is then empty and energy_axes (if unset) defaults to the coefficients' σa and θd axes.
  std::optional<FourierNpConfig> fourier;
};

// target_error plans for `planning_target` (the config's target, or a smaller one when a first bake
// missed the target at random points).
NpPlan plan_np_tables(const BakeConfig& config, bool per_material, BakeReport& report, double planning_target = 0.0);
// Explicit lobes whose largest energy over everything baked stays below tables.np.fold_below join
// the residual (run.lobes decreases; report.folded lists them).
void fold_weak_lobes(BakeRun& run, const NpPlan& plan, bool generic_np, BakeReport& report);
void bake_generic_np(BakeRun& run, const NpPlan& plan, TableSet& set, BakeReport& report);
// The Fourier N_p tables np_fourier/<lobe> and np_fourier/residual (bake_fourier.cpp), with the
// energy and residual tables of the tensor representation.
void bake_fourier_np(BakeRun& run, const NpPlan& plan, TableSet& set, BakeReport& report);
// The lobe energies np/energy_<lobe>, np/energy_residual and the residual np/residual over (σa, θd)
// (bake_np.cpp): the tables both representations share.
void bake_energy_tables(const BakeRun& run, const std::vector<GridAxis>& axes, TableSet& set, BakeReport& report);
// Whether a θd axis has its last node at 90°, and the grazing factor g that the energy, residual
// and Fourier tables of lobe p (the residual: residual = true) on such an axis are divided by
// (sampler::GrazingFactor; none where the axis stops short of 90° or for R).
bool reaches_grazing(const GridAxis& theta_d);
sampler::GrazingFactor grazing_factor_of(const BakeConfig& c, const GridAxis& theta_d, int p, bool residual);
void bake_material_np(BakeRun& run, const NpPlan& plan, TableSet& set, BakeReport& report);
void bake_mp_tables(const BakeRun& run, bool per_material, TableSet& set, BakeReport& report);

}  // namespace hairlut::detail
