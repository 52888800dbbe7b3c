// Model "deon2011": d'Eon et al. 2011's energy-conserving M_p and roughened N_p (docs/conventions.md).
// Its config keys (lobes with tilts and folding, quadrature), its N_p axes over β, and its bake: the
// stages of bake/bake_stages.hpp in order, which the planner (target_error), the slabbed writer,
// dual scattering and the engine presets share, so they stay in lib/src/bake.
#include <chrono>
#include <memory>

#include "bake/bake_internal.hpp"
#include "bake/bake_stages.hpp"
#include "hairlut/bake/bake.hpp"
#include "hairlut/bake/bake_engine.hpp"
#include "hairlut/bake/model_kind.hpp"
#include "hairlut/bake/resolution.hpp"
#include "hairlut/bake/sampled_error.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/tables/table_sampling.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/util/version.hpp"

namespace hairlut::models::deon2011 {
extern const char* const schema_json;  // schema.json, embedded by the build

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


// The table set's self-description: model, conventions, lobes (after folding), quadrature, config.
void describe(const BakeConfig& c, const detail::BakeRun& s, const BakeReport& report, Precision precision, TableSet& set) {
  detail::open_set_description(
      c,
      "hairlut conventions (docs/conventions.md): angles in radians; S = sum_p M_p N_p; int M cos(theta_r) dtheta_r = 1; "
      "N_p(phi) = 1/2 int A(p,h) D_beta(phi - Phi(p,h)) dh; sigma_a per unit fiber radius; tilt shifts theta_r",
      set);
  set.metadata["lobes"] = json::array();
  for (int p = 0; p < s.lobes; ++p) set.metadata["lobes"].push_back(lobe_name(p));
  set.metadata["residual"] = c.residual;
  set.metadata["residual_from_p"] = s.lobes;
  set.metadata["folded_lobes"] = json::array();
  for (const auto& f : report.folded) set.metadata["folded_lobes"].push_back({{"lobe", f.lobe}, {"max_energy", f.max_energy}});
  set.metadata["quadrature"] = quadrature_json(c.quadrature);
  detail::close_set_description(c, precision, set);
}


TableSet bake_stages(const BakeConfig& c, const BakeOptions& opt, BakeReport* report_out, SlabbedTables* slabbed) {
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

class Model final : public ModelKind {
 public:
  std::string_view name() const override { return "deon2011"; }
  std::string_view short_name() const override { return "deon"; }
  std::string_view schema() const override { return schema_json; }

  std::vector<std::string> default_lobes() const override { return {"R", "TT", "TRT", "TRRT"}; }
  bool has_residual() const override { return true; }
  // Its settings are the config's lobes and quadrature, which BakeConfig holds for the stages.
  std::shared_ptr<const ModelSettings> parse(const nlohmann::json&, const BakeConfig&) const override { return nullptr; }
  void normalize(const BakeConfig& c, nlohmann::json& n) const override {
    std::vector<std::string> names;
    nlohmann::json tilt = nlohmann::json::object();
    for (int p = 0; p < c.lobe_count; ++p) {
      names.push_back(lobe_name(p));
      tilt[lobe_name(p)] = c.tilt[static_cast<std::size_t>(p)];
    }
    tilt["residual"] = c.residual_tilt;
    n["lobes"] = {{"explicit", names}, {"residual", c.residual}, {"fold_below", c.fold_below}, {"tilt", tilt}};
    n["quadrature"] = {{"method", to_string(c.quadrature.method)},
                       {"order", c.quadrature.order},
                       {"variable", to_string(c.quadrature.variable)},
                       {"tolerance", c.quadrature.tolerance},
                       {"energy_order", c.quadrature.energy_order}};
  }
  // N_p over (β, σa, θd, φ): generic tables need the β axis, a per-material scene takes β from its materials.
  std::vector<GridAxis> np_axes(const nlohmann::json& axes, const std::string& path, const SharedNpAxes& shared,
                                const BakeConfig&) const override {
    if (!axes.contains("beta") && !shared.per_material)
      config_error(path.substr(0, path.size() - 1), "missing required key \"beta\" (needed unless scene.mode is per-material)");
    GridAxis beta;
    beta.name = "beta";
    beta.count = 0;  // unused (per-material scene) unless given
    if (axes.contains("beta"))
      beta = config_angle_axis(axes.at("beta"), path + "beta", "beta", 1e-6, kPi, "azimuthal roughness beta (detector width)");
    return {beta, shared.sigma_a, shared.theta_d, shared.phi};
  }
  std::string mp_beta_meaning() const override { return "longitudinal roughness beta, v = beta^2"; }
  // β_m per lobe from beta_deg, β_n from beta_n_deg (else β_m), the residual's from its own entry or the highest lobe's.
  void material_roughness(const nlohmann::json& mj, const std::string& path, const BakeConfig& c, MaterialConfig& m) const override {
    config_per_lobe_values(mj.at("beta_deg"), path + ".beta_deg", c.lobe_count, kPi / 180.0, m.beta_m, m.residual_beta_m);
    if (mj.contains("beta_n_deg"))
      config_per_lobe_values(mj.at("beta_n_deg"), path + ".beta_n_deg", c.lobe_count, kPi / 180.0, m.beta_n, m.residual_beta_n);
    else
      m.beta_n = m.beta_m, m.residual_beta_n = m.residual_beta_m;
  }

  void check(const BakeConfig&) const override {}  // its rules are the schema's and the N_p axes'

  bool slab_by_slab() const override { return true; }
  std::vector<PlannedTable> own_np_tables(const BakeConfig&) const override { return {}; }
  TableSet bake(const BakeConfig& c, const BakeOptions& opt, BakeReport* report, SlabbedTables* slabbed) const override {
    return bake_stages(c, opt, report, slabbed);
  }

  std::shared_ptr<const ModelSettings> from_metadata(const nlohmann::json&, double, AbsorptionPath) const override { return nullptr; }
  // Its tables' references are table_truth()'s own (bake/table_truth.cpp), which the stages' planner uses too.
  std::optional<TableTruth> truth(const Table&, const ModelSettings&) const override { return std::nullopt; }
};

}  // namespace

const ModelKind& model_kind() {
  static const Model model;
  return model;
}

}  // namespace hairlut::models::deon2011
