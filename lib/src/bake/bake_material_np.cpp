// The per-material N_p tables: every explicit lobe of each material of a scene over (channel, θd, φ)
// with the material's RGB σa and its own β per lobe, the lobe energies and the residual over
// (channel, θd): the shape renderers precompute per material (material_np.hpp).
#include <memory>
#include <vector>

#include "bake_internal.hpp"
#include "bake_stages.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/physics/material_np.hpp"
#include "hairlut/util/angles.hpp"

namespace hairlut::detail {

void bake_material_np(BakeRun& run, const NpPlan& plan, TableSet& set, BakeReport& report) {
  const BakeConfig& c = *run.config;
  const BakeOptions& opt = run.options;
  const Precision precision = run.precision;
  const BakeRun& s = run;
  const std::vector<GridAxis>& np_axes = plan.axes;
  const LobeSet lobe_set{s.lobes, c.residual};
  const std::shared_ptr<GaussLegendreCache>& rules = run.rules;
  std::size_t& unconverged = run.unconverged;
  const GridAxis theta_axis = axis_named(np_axes, "theta_d"), phi_axis = axis_named(np_axes, "phi");
  const std::vector<double> thetas = theta_axis.nodes(), phis = phi_axis.nodes();
  const GridAxis channel = channel_axis({"R", "G", "B"}, "colour channel (linear sRGB primaries)");
  const std::size_t nt = thetas.size(), nphi = phis.size();
  // Each material's tables and planned N_p, filled by one parallel loop below.
  struct Pending {
    std::size_t first, energy_first, residual_index;
    std::vector<double> sigmas;
    std::unique_ptr<MaterialNp> np;  // null: N_p already baked by bake_np_grid (per-entry methods)
  };
  std::vector<Pending> pending;
  pending.reserve(c.scene->materials.size());
  MaterialNpRules rules_shared;  // the materials share the θd axis and so their quadrature rules
  for (const MaterialConfig& m : c.scene->materials) {
    const std::string group = "materials/" + m.name;
    const std::size_t first = set.tables.size();
    for (int p = 0; p < s.lobes; ++p) {
      Table t = make_table(group, "np_" + lobe_name(p), "N_p", "1/rad",
                           "N_p of lobe " + lobe_name(p) + " for material " + m.name + " (RGB sigma_a)",
                           {channel, theta_axis, phi_axis}, precision);
      t.attributes = {{"lobe", lobe_name(p)}, {"p", p}, {"material", m.name}, {"beta", m.beta_n[static_cast<std::size_t>(p)]},
                      {"sigma_a", m.sigma_a}};
      set.tables.push_back(std::move(t));
    }
    const std::size_t energy_first = set.tables.size();
    for (int p = 0; p < lobe_set.size(); ++p) {
      const std::string lobe = p == s.lobes ? "residual" : lobe_name(p);
      Table t = make_table(group, "energy_" + lobe, "energy", "1", "energy of lobe " + lobe + " for material " + m.name,
                           {channel, theta_axis}, precision);
      t.attributes = {{"lobe", lobe}, {"p", p}, {"material", m.name}};
      set.tables.push_back(std::move(t));
    }
    std::size_t residual_index = 0;
    if (c.residual) {
      Table t = make_table(group, "np_residual", "N_p", "1/rad",
                           "residual lobes p >= " + std::to_string(s.lobes) + " for material " + m.name + ", uniform in phi",
                           {channel, theta_axis}, precision);
      t.attributes = {{"lobe", "residual"}, {"p_from", s.lobes}, {"material", m.name}};
      residual_index = set.tables.size();
      set.tables.push_back(std::move(t));
    }
    const std::vector<double> channel_sigmas(m.sigma_a.begin(), m.sigma_a.end());
    Pending& item = pending.emplace_back(Pending{first, energy_first, residual_index, channel_sigmas, nullptr});
    if (c.quadrature.method == NpQuadratureConfig::Method::fourier) {
      // The material's own path: every lobe and channel of a θd from one node set.
      MaterialNpRequest mr{c.eta, c.path, {}, channel_sigmas, thetas, phis, c.quadrature.tolerance, &rules_shared};
      for (int p = 0; p < s.lobes; ++p) mr.betas.push_back(m.beta_n[static_cast<std::size_t>(p)]);
      item.np = std::make_unique<MaterialNp>(std::move(mr));
      if (!item.np->note().empty() && &m == &c.scene->materials.front()) report.notes.push_back("per-material N_p: " + item.np->note());
    } else {
      unconverged += bake_np_grid(
          {c.eta, c.path, c.quadrature, s.lobes, channel_sigmas, thetas, phis,
           [&](int p) { return std::vector<double>{m.beta_n[static_cast<std::size_t>(p)]}; }, rules, {}},
          opt, "N_p " + m.name, [&](int p, std::size_t ic, std::size_t it, std::size_t, std::size_t ip, double v) {
            set.tables[first + static_cast<std::size_t>(p)].set((ic * nt + it) * nphi + ip, v);
          });
    }
    report.entries += 3 * nt * (nphi * static_cast<std::size_t>(s.lobes) + static_cast<std::size_t>(lobe_set.size()));
  }
  // One parallel loop over every (material, θd): N_p of every lobe and channel, and the lobe
  // energies of every channel at once — from N_p's own nodes on the material's path (MaterialNp)
  // without a residual, else by material_energies (lobe_energies' rule and integrand). Few large loops rather than two
  // per material: less time in OpenMP's start and spin-waiting.
  parallel_for(pending.size() * nt, opt, "N_p and energies (per material)", 3 * nphi * static_cast<std::size_t>(s.lobes), [&](std::size_t item) {
    const Pending& w = pending[item / nt];
    const std::size_t it = item % nt, K = w.sigmas.size();
    std::vector<double> e;
    if (w.np) {
      std::vector<double> v;
      w.np->evaluate(it, v, c.residual ? nullptr : &e);
      for (int p = 0; p < s.lobes; ++p) {
        Table& t = set.tables[w.first + static_cast<std::size_t>(p)];
        for (std::size_t ic = 0; ic < K; ++ic) {
          const double* src = v.data() + (static_cast<std::size_t>(p) * K + ic) * nphi;
          const std::size_t dst = (ic * nt + it) * nphi;
          for (std::size_t ip = 0; ip < nphi; ++ip) t.set(dst + ip, src[ip]);
        }
      }
    }
    // The residual's integrand (1 − f)² f^{P−1} T^P / (1 − fT) needs more nodes than N_p's wide lobes
    // have: with a residual, every energy comes from the energy rule.
    if (!w.np || c.residual) material_energies(c.eta, thetas[it], c.path, w.sigmas, lobe_set, s.energy_rule, e);
    const auto E = static_cast<std::size_t>(lobe_set.size());
    for (std::size_t ic = 0; ic < K; ++ic) {
      for (std::size_t p = 0; p < E; ++p) set.tables[w.energy_first + p].set(ic * nt + it, e[ic * E + p]);
      if (c.residual) set.tables[w.residual_index].set(ic * nt + it, e[ic * E + E - 1] / kTwoPi);
    }
  });
}

}  // namespace hairlut::detail
