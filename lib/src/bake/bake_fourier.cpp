// The Fourier N_p tables (tables.np.representation "fourier"; fourier_tables.hpp): per explicit
// lobe p the coefficients c_n = C_n / F of the detector's cosine series,
//   C_n(θd, σa) = ½ ∫ A(p, h) cos(n Φ(p, h)) dh,  F = e^{−p σa′ ℓ_min} (least_absorption),
// at every (θd, σa) node for n = 0 … terms − 1, and the residual's one coefficient c_0 = E_{≥P} / F_P
// (it is uniform in φ and β); then the energy and residual tables the tensor representation has.
// Where the θd axis reaches 90°, each table stores its values divided by its lobe's grazing factor
// g (cos²θd for p ≥ 1, the residual's g_res; none for R), which a lookup multiplies back, so the
// coefficients stay finite as the lobes' energies vanish; the 90° node is evaluated at the double
// nearest π/2, where the physics gives the ratio to rounding (docs/table-format.md).
//
// Exact and approximate: the C_n / F are the Fourier method's integrals (azimuthal_fourier.hpp,
// Gauss–Legendre in γ with the nodes its error bound asks for at the quadrature tolerance), F taken
// inside the integral; terms = N(β_min) + 1 at the truncation tolerance, rounded up to a multiple of
// 4 (a lookup sums whole groups of four). Each θd node is one work item writing its own entries,
// so the values are bit-identical for any thread count.
#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "bake_internal.hpp"
#include "bake_stages.hpp"
#include "hairlut/physics/attenuation.hpp"
#include "hairlut/physics/azimuthal_fourier.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/tables/fourier_tables.hpp"

namespace hairlut::detail {

namespace {

using detail::make_table;
using detail::parallel_for;

// The terms a Fourier table stores for its β range and tolerance: N(β_min) + 1, rounded up to 4.
int stored_terms(const FourierNpConfig& f) { return (fourier_terms(f.beta_lo, f.tolerance) + 4) / 4 * 4; }

}  // namespace

void bake_fourier_np(BakeRun& run, const NpPlan& plan, TableSet& set, BakeReport& report) {
  const BakeConfig& c = *run.config;
  const FourierNpConfig& f = *plan.fourier;
  const GridAxis &theta_axis = f.axes[0], &sigma_axis = f.axes[1];
  const std::vector<double> thetas = theta_axis.nodes(), sigmas = sigma_axis.nodes();
  const std::size_t nt = thetas.size(), ns = sigmas.size();
  const int terms = stored_terms(f);
  const auto nterms = static_cast<std::size_t>(terms);
  const int lobes = run.lobes;
  // The energy tables' axes (σa, θd): the config's energy_axes, or the coefficients'. The residual's
  // coefficient lives on them: like an energy, it has no φ or β detail, and near grazing θd its
  // 1/(1 − fT) rises steeply at small σa. A geometric σa axis there is read by Catmull–Rom (c_0 is
  // smooth once F is divided out, and the Fourier tables are read linearly or cubically).
  const std::vector<GridAxis> energy_axes = plan.energy_axes ? *plan.energy_axes : std::vector<GridAxis>{sigma_axis, theta_axis};
  GridAxis residual_sigma = energy_axes[0], residual_theta = energy_axes[1];
  for (GridAxis* a : {&residual_sigma, &residual_theta})
    if (a->interpolation == Interpolation::geometric) a->interpolation = a->count >= 3 ? Interpolation::cubic : Interpolation::linear;
  // (The Fourier evaluator reads σa spaced uniformly or in √σa, θd uniformly or in cos θd.)
  const bool readable = (residual_sigma.spacing == Spacing::uniform || residual_sigma.spacing == Spacing::sqrt) &&
                        (residual_theta.spacing == Spacing::uniform || residual_theta.spacing == Spacing::cos);
  if (!readable) residual_sigma = sigma_axis, residual_theta = theta_axis;
  // The tables: np_fourier/<lobe> over (θd, σa, n), np_fourier/residual with its one coefficient.
  const std::size_t first = set.tables.size();
  std::vector<sampler::GrazingFactor> info_grazing;  // per table below, as its attributes record
  for (int p = 0; p <= lobes; ++p) {
    const bool residual = p == lobes;
    if (residual && !c.residual) break;
    FourierTableInfo info;
    info.params.terms = residual ? 1 : terms;
    info.params.beta_min = f.beta_lo;
    info.params.tolerance = f.tolerance;
    info.params.eta = c.eta;
    info.params.absorption_p = p;
    info.params.papers_path = c.path == AbsorptionPath::papers;
    info.params.grazing = grazing_factor_of(c, residual ? residual_theta : theta_axis, p, residual);
    info.beta_max = f.beta_hi;
    info.lobe = residual ? "residual" : lobe_name(p);
    info.p = p;
    const std::string words = residual ? "residual lobes p >= " + std::to_string(p) + ": c_0 = E / F with F = exp(-p sigma_a' l_min), N = c_0 F / (2 pi)"
                                       : "Fourier coefficients c_n = C_n / F of lobe " + info.lobe + ", C_n = 1/2 int A cos(n Phi) dh, F = exp(-p sigma_a' l_min)";
    Table t = make_table(kFourierGroup, info.lobe, kFourierQuantity, "1", words,
                         {residual ? residual_theta : theta_axis, residual ? residual_sigma : sigma_axis, fourier_n_axis(info.params.terms)}, run.precision);
    t.attributes = fourier_attributes(info, std::string(to_string(c.path)));
    t.set_grazing_factor(info.params.grazing);
    info_grazing.push_back(info.params.grazing);
    set.tables.push_back(std::move(t));
  }
  // Gauss–Legendre rules per (θd, lobe), fetched before the parallel loop (the cache is shared).
  const double qtol = c.quadrature.tolerance;
  std::vector<int> order(nt * static_cast<std::size_t>(lobes), 0);
  std::map<int, const GaussLegendreRule*> rules;
  for (std::size_t t = 0; t < nt; ++t) {
    const FiberGeometry g = FiberGeometry::make(c.eta, thetas[t]);
    for (int p = 0; p < lobes; ++p) {
      const int m = fourier_nodes(terms - 1, p, g, qtol);
      order[t * static_cast<std::size_t>(lobes) + static_cast<std::size_t>(p)] = m;
      if (!rules.count(m)) rules[m] = &run.rules->get(m);
    }
  }
  parallel_for(nt, run.options, "N_p Fourier", ns * static_cast<std::size_t>(lobes), [&](std::size_t t) {
    const FiberGeometry g = FiberGeometry::make(c.eta, thetas[t]);
    const double l_min = edge_segment_length(g, c.path);
    std::map<int, FiberNodes> nodes;
    std::vector<double> C;
    for (int p = 0; p < lobes; ++p) {
      const int m = order[t * static_cast<std::size_t>(lobes) + static_cast<std::size_t>(p)];
      auto it = nodes.find(m);
      if (it == nodes.end()) it = nodes.emplace(m, FiberNodes::make(g, c.path, *rules.at(m))).first;
      fourier_coefficients(it->second, g, p, sigmas, terms - 1, C, l_min);  // C_n / F, [n][σa]
      Table& out = set.tables[first + static_cast<std::size_t>(p)];
      const sampler::GrazingFactor& gf = info_grazing[static_cast<std::size_t>(p)];
      for (std::size_t k = 0; k < ns; ++k) {
        const double gk = gf(sigmas[k], thetas[t]);
        for (std::size_t n = 0; n < nterms; ++n) out.set((t * ns + k) * nterms + n, gk > 0.0 ? C[n * ns + k] / gk : 0.0);
      }
    }
  });
  if (c.residual) {  // c_0 = E_{≥P} / F_P at the residual's (θd, σa) nodes
    const std::vector<double> rt = residual_theta.nodes(), rs = residual_sigma.nodes();
    Table& out = set.tables[first + static_cast<std::size_t>(lobes)];
    parallel_for(rt.size(), run.options, "N_p Fourier residual", rs.size(), [&](std::size_t t) {
      for (std::size_t k = 0; k < rs.size(); ++k) {
        const AttenuationSlice slice(c.eta, rt[t], rs[k], c.path);
        const double e = lobe_energies(slice, LobeSet{lobes, true}, run.energy_rule).back(), F = least_absorption(slice, lobes);
        const double g = info_grazing.back()(rs[k], rt[t]);
        out.set(t * rs.size() + k, F > 0.0 && g > 0.0 ? e / F / g : 0.0);  // F and g underflow only where the residual has no energy left
      }
    });
    report.entries += rt.size() * rs.size();
  }
  report.entries += nt * ns * nterms * static_cast<std::size_t>(lobes);
  set.metadata["np_representation"] = "fourier";
  set.metadata["np_fourier"] = {{"tables", std::string(kFourierGroup) + "/<lobe>"},
                                {"terms", terms},
                                {"beta_range", {f.beta_lo, f.beta_hi}},
                                {"tolerance", f.tolerance},
                                {"entries_per_lobe", nt * ns * nterms}};
  // The energy and residual tables, on their own axes or the coefficients' (σa, θd).
  bake_energy_tables(run, energy_axes, set, report);
}

}  // namespace hairlut::detail
