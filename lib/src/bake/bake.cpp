// bake(): the stages of one d'Eon 2011 bake, in order. Each stage lives in the file of its table
// kind (bake_stages.hpp); Marschner 2003 configs go to bake_marschner.cpp.
#include "hairlut/bake/bake.hpp"

#include <chrono>
#include <memory>

#include "bake_internal.hpp"
#include "bake_stages.hpp"
#include "hairlut/bake/bake_engine.hpp"
#include "hairlut/bake/resolution.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/tables/table_sampling.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/util/version.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;

json quadrature_json(const NpQuadratureConfig& q) {
  return {{"method", to_string(q.method)},
          {"order", q.order},
          {"variable", to_string(q.variable)},
          {"tolerance", q.tolerance},
          {"energy_order", q.energy_order},
          {"energy_method", "gauss-legendre in gamma over [0, pi/2]"}};
}

}  // namespace

// Tables larger than the memory budget are baked slab by slab, which every checksummed note must
// precede: refuse what needs whole tables.
void check_slab_by_slab(const BakeConfig& c) {
  if (c.marschner) throw DomainError("model marschner2003: tables larger than the memory budget cannot be baked slab by slab (raise --memory-budget)");
  if (c.output.sampling_data)
    throw DomainError("output.sampling_data: the sampling data are computed from whole tables; tables larger than the memory budget "
                      "cannot carry them (set output.sampling_data false, or raise --memory-budget)");
  if (c.np_target_error)
    throw DomainError("tables.np.target_error: the achieved error is measured on whole tables; tables larger than the memory budget "
                      "cannot use it (raise --memory-budget or give the axes' counts)");
  if (c.np_axes && c.quadrature.method == NpQuadratureConfig::Method::adaptive)
    throw DomainError("tables.np.quadrature.method adaptive: tables larger than the memory budget are baked slab by slab, which needs "
                      "the fourier or gauss-legendre method (or raise --memory-budget)");
}

namespace {

// The table set's self-description: model, conventions, lobes (after folding), quadrature, config.
void describe(const BakeConfig& c, const detail::BakeRun& s, const BakeReport& report, Precision precision, TableSet& set) {
  set.metadata["hairlut_version"] = kVersion;
  set.metadata["model"] = c.model;
  set.metadata["name"] = c.name;
  set.metadata["description"] = c.description;
  set.metadata["conventions"] =
      "hairlut conventions (docs/conventions.md): angles in radians; S = sum_p M_p N_p; int M cos(theta_r) dtheta_r = 1; "
      "N_p(phi) = 1/2 int A(p,h) D_beta(phi - Phi(p,h)) dh; sigma_a per unit fiber radius; tilt shifts theta_r";
  set.metadata["eta"] = c.eta;
  set.metadata["absorption_path"] = to_string(c.path);
  set.metadata["lobes"] = json::array();
  for (int p = 0; p < s.lobes; ++p) set.metadata["lobes"].push_back(lobe_name(p));
  set.metadata["residual"] = c.residual;
  set.metadata["residual_from_p"] = s.lobes;
  set.metadata["folded_lobes"] = json::array();
  for (const auto& f : report.folded) set.metadata["folded_lobes"].push_back({{"lobe", f.lobe}, {"max_energy", f.max_energy}});
  set.metadata["quadrature"] = quadrature_json(c.quadrature);
  set.metadata["config_hash"] = c.hash;
  set.metadata["config"] = c.normalized.dump();
  set.metadata["precision"] = precision == Precision::float32 ? "float32" : "float64";
}

}  // namespace

TableSet bake(const BakeConfig& c, const BakeOptions& opt, BakeReport* report_out, SlabbedTables* slabbed) {
  if (slabbed) check_slab_by_slab(c);
  if (c.marschner) {
    TableSet m = bake_marschner(c, opt, report_out);
    if (c.output.sampling_data) append_sampling_tables(m, opt.threads, opt.progress);  // the importance sampler's data next to every N_p and M_p table
    return m;
  }
  const auto t0 = std::chrono::steady_clock::now();
  // target_error plans from per-axis error probes; the bake is then measured at random points. A
  // plan that misses the target is planned again for a proportionally smaller target (at most
  // three times), so the reported error is the one a renderer sees, not the prediction.
  double planning_target = c.np_target_error.value_or(0.0);
  for (int attempt = 1;; ++attempt) {
    BakeReport report;
    TableSet set;
    const Precision precision = c.output.hdf5_double ? Precision::float64 : Precision::float32;
    const bool per_material = c.scene && c.scene->mode == SceneConfig::Mode::per_material;
    const bool generic_np = (c.np_axes || c.np_fourier) && !per_material;
    detail::BakeRun run{&c, opt, precision, slabbed, c.lobe_count, GaussLegendreRule(c.quadrature.energy_order)};

    const detail::NpPlan np = detail::plan_np_tables(c, per_material, report, planning_target);  // N_p axes; target_error chooses them
    detail::fold_weak_lobes(run, np, generic_np, report);  // weak lobes join the residual
    report.explicit_lobes = run.lobes;
    describe(c, run, report, precision, set);
    if (generic_np && np.fourier) detail::bake_fourier_np(run, np, set, report);  // C_n / F over (θd, σa, n), energies, residual
    else if (generic_np) detail::bake_generic_np(run, np, set, report);           // N_p over (β, σa, θd, φ), energies, residual
    if (per_material) detail::bake_material_np(run, np, set, report);  // N_p over (channel, θd, φ) per material
    if (c.mp_axes) detail::bake_mp_tables(run, per_material, set, report);
    for (const TableKindRequest& k : c.kinds) k.kind->bake(*k.settings, precision, set, report);  // lib/kinds/
    bake_dual_scattering_tables(c, opt, set, report);  // mean energy, dual scattering, engine presets
    if (c.output.sampling_data) append_sampling_tables(set, opt.threads, opt.progress);  // the importance sampler's data next to every N_p and M_p table

    if (run.unconverged) report.notes.push_back(std::to_string(run.unconverged) + " adaptive N_p entries did not reach the tolerance");
    if (!report.resolution.is_null() && generic_np) {
      // The validator's measure on points the plan never probed (random, then the worst-point
      // search): the bake is accepted on the worst found.
      const AchievedError achieved = measure_np_error(set, c.eta, c.path, c.np_target_points.value_or(kSampledErrorPoints), opt.threads);
      report.resolution["achieved_error"] = achieved.worst;
      report.resolution["achieved_p99"] = achieved.p99;
      report.resolution["attempts"] = attempt;
      if (achieved.worst > *c.np_target_error && attempt < 4) {
        planning_target *= std::min(0.8, 0.9 * *c.np_target_error / achieved.worst);
        continue;
      }
      if (achieved.worst > *c.np_target_error)
        report.notes.push_back("target_error " + std::to_string(*c.np_target_error) + " not reached after " + std::to_string(attempt) +
                               " plans: lower the target or narrow the ranges");
      report.notes.push_back("target_error: achieved sampled error " + std::to_string(achieved.worst) + " (worst found by random points and a worst-point search, " + achieved.worst_table + "), p99 " +
                             std::to_string(achieved.p99) + " at the random points, relative to " + achieved.denominator);
      set.metadata["resolution"] = report.resolution;
    }
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    report.threads = opt.threads;
    set.metadata["notes"] = report.notes;
    if (report_out) *report_out = report;
    return set;
  }
}

}  // namespace hairlut
