// How the generic N_p tables are laid out: the config's axes (restricted to a scene's materials),
// or what tables.np.target_error chooses among the representations (the axes as configured, the
// shape N_p / E_p with cubic interpolation, that shape in β bands, and the Fourier coefficients),
// keeping the fewest entries per lobe; and the weak lobes folded into the residual.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "bake_internal.hpp"
#include "bake_stages.hpp"
#include "hairlut/bake/resolution.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/bake/beta_bands.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut::detail {
namespace {

using json = nlohmann::ordered_json;

// Largest energy of each explicit lobe over the σa values and θd nodes that will be baked.
std::vector<double> max_lobe_energies(const BakeConfig& c, const std::vector<double>& sigmas, const std::vector<double>& thetas,
                                      const GaussLegendreRule& rule) {
  std::vector<double> best(static_cast<std::size_t>(c.lobe_count), 0.0);
  for (double s : sigmas)
    for (double t : thetas) {
      const auto e = lobe_energies(AttenuationSlice(c.eta, t, s, c.path), {c.lobe_count, false}, rule);
      for (std::size_t p = 0; p < e.size(); ++p) best[p] = std::max(best[p], e[p]);
    }
  return best;
}

// The Fourier candidate's lower bounds from tensor axes: their β range, θd over cos θd and σa over
// √σa (the spacings that suit the coefficients), Catmull–Rom, σa mirrored at 0; counts from 2.
FourierNpConfig fourier_bounds(const std::vector<GridAxis>& axes) {
  FourierNpConfig f;
  const GridAxis& beta = axis_named(axes, "beta");
  f.beta_lo = beta.spacing == Spacing::explicit_values ? beta.values.front() : beta.lo;
  f.beta_hi = beta.spacing == Spacing::explicit_values ? beta.values.back() : beta.hi;
  GridAxis theta = axis_named(axes, "theta_d"), sigma = axis_named(axes, "sigma_a");
  for (GridAxis* a : {&theta, &sigma}) {
    if (a->spacing == Spacing::explicit_values) a->lo = a->values.front(), a->hi = a->values.back(), a->values.clear();
    a->placement = Placement::edges;
    a->interpolation = Interpolation::cubic;
    a->lo_end = End::extrapolate;
    a->count = a->lo < a->hi ? 2 : 1;
  }
  theta.spacing = Spacing::cos;
  sigma.spacing = Spacing::sqrt;
  if (sigma.lo == 0.0) sigma.lo_end = End::mirror;
  f.axes = {theta, sigma};
  return f;
}

// Energy tables dense enough not to matter next to a shape or Fourier table: σa on √σa nodes, at
// least 200, Catmull–Rom with the mirror end at σa = 0 (an energy is a smooth function of σa, so an
// even one of √σa); θd at least 512, cubic. (Uniform σa read geometrically, exact for one
// exponential, was 17% off on the residual near σa = 0 at grazing θd, where 1/(1 − f T) is not one.)
std::vector<GridAxis> dense_energy_axes(const std::vector<GridAxis>& np_axes) {
  GridAxis es = axis_named(np_axes, "sigma_a"), et = axis_named(np_axes, "theta_d");
  es.spacing = Spacing::sqrt, es.count = std::max(es.count, 200), es.interpolation = Interpolation::cubic;
  if (es.lo == 0.0) es.lo_end = End::mirror;
  et.count = std::max(et.count, 512), et.interpolation = Interpolation::cubic;
  if (es.lo == es.hi) es.count = 1, es.interpolation = Interpolation::linear;
  if (es.spacing == Spacing::explicit_values || et.spacing == Spacing::explicit_values) return {axis_named(np_axes, "sigma_a"), axis_named(np_axes, "theta_d")};
  return {es, et};
}

// The resolution report of a Fourier plan (what target_error chose and predicted).
void report_fourier_plan(const BakeConfig& c, const FourierResolutionPlan& plan, double target, BakeReport& report) {
  const FourierNpConfig& f = plan.config;
  report.resolution = {{"target_error", *c.np_target_error},
                       {"predicted_error", plan.predicted_error},
                       {"entries_per_lobe", plan.entries},
                       {"representation", "Fourier coefficients C_n / F over (theta_d, sigma_a)"},
                       {"planned_for", target},
                       {"entries_fourier", plan.entries}};
  report.resolution["counts"] = {{"terms", plan.terms}, {"theta_d", f.axes[0].count}, {"sigma_a", f.axes[1].count}};
  report.resolution["predicted_axis_error"] = {{"theta_d", plan.axis_error.at("theta_d")}, {"sigma_a", plan.axis_error.at("sigma_a")},
                                               {"truncation", f.tolerance}};
  report.resolution["fourier"] = {{"beta_range", {f.beta_lo, f.beta_hi}}, {"tolerance", f.tolerance}};
  report.notes.push_back("target_error " + std::to_string(*c.np_target_error) + ": " + report.resolution["representation"].get<std::string>() +
                         ", counts terms " + std::to_string(plan.terms) + ", theta_d " + std::to_string(f.axes[0].count) + ", sigma_a " +
                         std::to_string(f.axes[1].count) + " (" + std::to_string(plan.entries) + " entries per lobe)");
}

}  // namespace

NpPlan plan_np_tables(const BakeConfig& c, bool per_material, BakeReport& report, double planning_target) {
  NpPlan chosen;
  if (c.np_fourier) {  // representation fourier: its axes, or the counts target_error chooses for them
    chosen.fourier = c.np_fourier;
    chosen.energy_axes = c.np_energy_axes;
    if (c.np_target_error) {
      const double target = planning_target > 0.0 ? planning_target : *c.np_target_error;
      const FourierResolutionPlan plan = plan_fourier_resolution(*c.np_fourier, c.eta, c.path, c.lobe_count, target);
      chosen.fourier = plan.config;
      report_fourier_plan(c, plan, target, report);
    }
    return chosen;
  }
  std::vector<GridAxis>& np_axes = chosen.axes;
  bool& normalize_energy = chosen.normalize_energy;
  std::optional<std::vector<GridAxis>>& energy_axes = chosen.energy_axes;
  if (c.np_axes) np_axes = restricted_np_axes(c, &report.notes);
  normalize_energy = c.np_normalize_energy;
  energy_axes = c.np_energy_axes;
  chosen.bands = c.np_beta_bands;
  if (c.np_axes && c.np_target_error && !per_material) {
    const double target = planning_target > 0.0 ? planning_target : *c.np_target_error;
    // Three representations compete and the fewest entries per lobe win: the axes as configured;
    // the shape N_p / E_p with cubic interpolation on every axis, σa uniform, and dense energy
    // tables; and that shape table split into β bands of at most an octave each (beta_bands.hpp),
    // each band with counts of its own (N_p's θd and φ detail scales as 1/β, so one tensor table
    // pays the smallest β's density at every β node).
    std::optional<ResolutionPlan> configured, shape;
    std::vector<ResolutionPlan> banded;
    std::size_t banded_entries = 0;
    // The Fourier representation competes unless the config chose the tensor one, asks for EXR
    // output (which has no layout for it) or another quadrature than the Fourier method's (whose
    // C_n the coefficients are).
    std::optional<FourierResolutionPlan> fourier;
    if (!c.np_representation && !c.output.exr && c.quadrature.method == NpQuadratureConfig::Method::fourier) {
      try {
        fourier = plan_fourier_resolution(fourier_bounds(np_axes), c.eta, c.path, c.lobe_count, target);
      } catch (const DomainError&) {
      }
    }
    try {
      configured = plan_np_resolution(np_axes, c.eta, c.path, c.lobe_count, target, std::size_t{1} << 31, normalize_energy);
    } catch (const DomainError&) {
    }
    std::vector<GridAxis> cubic = np_axes;
    for (GridAxis& a : cubic) {
      if (a.spacing == Spacing::explicit_values) continue;
      if (a.name == "sigma_a") a.spacing = Spacing::uniform;
      a.interpolation = Interpolation::cubic;
    }
    try {
      shape = plan_np_resolution(cubic, c.eta, c.path, c.lobe_count, target, std::size_t{1} << 31, true);
    } catch (const DomainError&) {
      if (!configured && !fourier) throw;
    }
    const GridAxis& beta = cubic[0];
    const int band_count = beta.spacing != Spacing::explicit_values && beta.lo > 0.0 && beta.hi > 2.5 * beta.lo && c.np_beta_bands.empty()
                               ? static_cast<int>(std::ceil(std::log(beta.hi / beta.lo) / std::log(2.0) - 1e-9))
                               : 0;
    if (band_count > 1) {
      try {
        for (int k = 0; k < band_count; ++k) {
          std::vector<GridAxis> axes = cubic;
          for (GridAxis& a : axes)
            if (a.spacing != Spacing::explicit_values && a.count > 1) a.count = 2;  // the planner raises each count as needed
          axes[0].placement = Placement::edges;
          axes[0].lo = k == 0 ? beta.lo : beta.lo * std::pow(beta.hi / beta.lo, static_cast<double>(k) / band_count);
          axes[0].hi = k + 1 == band_count ? beta.hi : beta.lo * std::pow(beta.hi / beta.lo, static_cast<double>(k + 1) / band_count);
          banded.push_back(plan_np_resolution(axes, c.eta, c.path, c.lobe_count, target, std::size_t{1} << 31, true));
          banded_entries += banded.back().entries;
        }
      } catch (const DomainError&) {
        banded.clear();
      }
    }
    const std::size_t none = std::numeric_limits<std::size_t>::max();
    const std::size_t e_configured = configured ? configured->entries : none, e_shape = shape ? shape->entries : none,
                      e_banded = banded.empty() ? none : banded_entries;
    if (fourier && fourier->entries < std::min({e_configured, e_shape, e_banded})) {
      if (!energy_axes) energy_axes = dense_energy_axes(np_axes);
      chosen.axes.clear();  // (np_axes refers to it)
      chosen.bands.clear();
      chosen.normalize_energy = false;
      chosen.fourier = fourier->config;
      report_fourier_plan(c, *fourier, target, report);
      if (configured) report.resolution["entries_as_configured"] = configured->entries;
    if (fourier) report.resolution["entries_fourier"] = fourier->entries;
      if (shape) report.resolution["entries_shape_cubic"] = shape->entries;
      if (!banded.empty()) report.resolution["entries_beta_bands"] = banded_entries;
      return chosen;
    }
    const bool use_bands = e_banded < e_shape && e_banded < e_configured;
    const bool use_shape = !use_bands && e_shape < e_configured;
    const ResolutionPlan& plan = use_bands ? banded.front() : use_shape ? *shape : *configured;
    if ((use_shape || use_bands) && !normalize_energy) {
      normalize_energy = true;
      if (!energy_axes) energy_axes = dense_energy_axes(np_axes);
    }
    np_axes = plan.axes;
    const std::size_t entries = use_bands ? banded_entries : plan.entries;
    double predicted = plan.predicted_error;
    if (use_bands)
      for (const ResolutionPlan& b : banded) predicted = std::max(predicted, b.predicted_error);
    report.resolution = {{"target_error", *c.np_target_error},
                         {"predicted_error", predicted},
                         {"entries_per_lobe", entries},
                         {"representation", use_bands    ? "shape N_p / E_p, cubic, " + std::to_string(band_count) + " beta bands"
                                            : use_shape ? std::string("shape N_p / E_p, cubic")
                                                        : std::string("as configured")},
                         {"planned_for", target}};
    if (configured) report.resolution["entries_as_configured"] = configured->entries;
    if (fourier) report.resolution["entries_fourier"] = fourier->entries;
    if (shape) report.resolution["entries_shape_cubic"] = shape->entries;
    if (!banded.empty()) report.resolution["entries_beta_bands"] = banded_entries;
    for (const GridAxis& a : np_axes) {
      report.resolution["counts"][a.name] = a.count;
      report.resolution["predicted_axis_error"][a.name] = plan.axis_error.at(a.name);
    }
    std::string counts;
    if (use_bands) {
      report.resolution["bands"] = json::array();
      for (const ResolutionPlan& b : banded) {
        chosen.bands.push_back(BetaBand{b.axes});
        json band = {{"range_deg", {b.axes[0].lo * 180.0 / kPi, b.axes[0].hi * 180.0 / kPi}}, {"entries_per_lobe", b.entries}};
        for (const GridAxis& a : b.axes) band["counts"][a.name] = a.count;
        report.resolution["bands"].push_back(band);
        counts += (counts.empty() ? "" : "; ") + std::to_string(b.axes[0].count) + " x " + std::to_string(b.axes[1].count) + " x " +
                  std::to_string(b.axes[2].count) + " x " + std::to_string(b.axes[3].count);
      }
    } else {
      counts = "beta " + std::to_string(np_axes[0].count) + ", sigma_a " + std::to_string(np_axes[1].count) + ", theta_d " +
               std::to_string(np_axes[2].count) + ", phi " + std::to_string(np_axes[3].count);
    }
    report.notes.push_back("target_error " + std::to_string(*c.np_target_error) + ": " + report.resolution["representation"].get<std::string>() +
                           ", counts " + counts + " (" + std::to_string(entries) + " entries per lobe)");
  }
  return chosen;
}

void fold_weak_lobes(BakeRun& s, const NpPlan& plan, bool generic_np, BakeReport& report) {
  const BakeConfig& c = *s.config;
  // The Fourier tables' σa and θd nodes, or the tensor tables'.
  const std::vector<GridAxis> np_axes = plan.fourier ? plan.fourier->axes : plan.axes;
  if ((c.np_axes || c.np_fourier) && c.fold_below > 0.0) {
    std::vector<double> sigmas;
    if (generic_np) sigmas = axis_named(np_axes, "sigma_a").nodes();
    else
      for (const MaterialConfig& m : c.scene->materials) sigmas.insert(sigmas.end(), m.sigma_a.begin(), m.sigma_a.end());
    const auto best = max_lobe_energies(c, sigmas, axis_named(np_axes, "theta_d").nodes(), s.energy_rule);
    while (s.lobes > 1 && best[static_cast<std::size_t>(s.lobes - 1)] < c.fold_below) {
      report.folded.push_back({lobe_name(s.lobes - 1), best[static_cast<std::size_t>(s.lobes - 1)]});
      --s.lobes;
    }
    std::reverse(report.folded.begin(), report.folded.end());
  }
}


}  // namespace hairlut::detail
