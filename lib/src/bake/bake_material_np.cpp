// The per-material N_p tables: every explicit lobe of each material of a scene over (channel, θd, φ)
// with the material's RGB σa and its own β per lobe, the lobe energies and the residual over
// (channel, θd): the shape renderers precompute per material (material_np.hpp).
#include <algorithm>
#include <cmath>
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
  // Where θd reaches 90° every table stores its quantity divided by its lobe's grazing factor
  // (docs/table-format.md, "Energies at grazing"; the residual last), which lookups multiply back:
  // N_p of the lobes p ≥ 1 vanishes as cos²θd there, and a linear cell ending at 0 would miss it by
  // the whole value. Divided in double before the values are rounded to the table's precision.
  std::vector<sampler::GrazingFactor> factor;
  for (int p = 0; p < lobe_set.size(); ++p) factor.push_back(grazing_factor_of(c, theta_axis, p, p == s.lobes));
  // g of lobe p at θd node it for σa (1 where the lobe's tables store their quantity as is), and a
  // value over it (g underflows only where the value has).
  auto factor_at = [&](int p, double sigma, std::size_t it) {
    const sampler::GrazingFactor& g = factor[static_cast<std::size_t>(p)];
    return g.none() ? 1.0 : g.of_cos(sigma, std::cos(thetas[it]));
  };
  auto over = [](double g, double v) { return g > 0.0 ? v / g : 0.0; };
  // Each material's tables, filled by one parallel loop below.
  struct Pending {
    std::size_t first, energy_first, residual_index;
    std::vector<double> sigmas;
    std::size_t channel0 = 0;  // its first channel among its group's (method "fourier")
  };
  // Materials with the same β per lobe (η, the path and the grids are the scene's) share every
  // node factor but T^p = e^{−pσa'ℓ}: the rule's asin, Fresnel and path lengths, the exit azimuths
  // and detector windows, and R's whole sum (its amplitude f does not depend on σa). One MaterialNp
  // bakes all their channels; each material's values are those of a bake of its own, bit for bit
  // (MaterialNpRequest::channels).
  struct Group {
    std::vector<double> betas, sigmas;
    std::vector<std::size_t> members;  // indices into `pending`
    std::unique_ptr<MaterialNp> np;
  };
  std::vector<Pending> pending;
  std::vector<Group> groups;
  pending.reserve(c.scene->materials.size());
  MaterialNpRules rules_shared;  // the materials share the θd axis and so their quadrature rules
  const bool shared_path = c.quadrature.method == NpQuadratureConfig::Method::fourier;
  for (const MaterialConfig& m : c.scene->materials) {
    const std::string group = "materials/" + m.name;
    const std::size_t first = set.tables.size();
    for (int p = 0; p < s.lobes; ++p) {
      Table t = make_table(group, "np_" + lobe_name(p), "N_p", "1/rad",
                           "N_p of lobe " + lobe_name(p) + " for material " + m.name + " (RGB sigma_a)",
                           {channel, theta_axis, phi_axis}, precision);
      t.attributes = {{"lobe", lobe_name(p)}, {"p", p}, {"material", m.name}, {"beta", m.beta_n[static_cast<std::size_t>(p)]},
                      {"sigma_a", m.sigma_a}};
      t.set_grazing_factor(factor[static_cast<std::size_t>(p)]);
      set.tables.push_back(std::move(t));
    }
    const std::size_t energy_first = set.tables.size();
    for (int p = 0; p < lobe_set.size(); ++p) {
      const std::string lobe = p == s.lobes ? "residual" : lobe_name(p);
      Table t = make_table(group, "energy_" + lobe, "energy", "1", "energy of lobe " + lobe + " for material " + m.name,
                           {channel, theta_axis}, precision);
      t.attributes = {{"lobe", lobe}, {"p", p}, {"material", m.name}, {"sigma_a", m.sigma_a}};
      t.set_grazing_factor(factor[static_cast<std::size_t>(p)]);
      set.tables.push_back(std::move(t));
    }
    std::size_t residual_index = 0;
    if (c.residual) {
      Table t = make_table(group, "np_residual", "N_p", "1/rad",
                           "residual lobes p >= " + std::to_string(s.lobes) + " for material " + m.name + ", uniform in phi",
                           {channel, theta_axis}, precision);
      t.attributes = {{"lobe", "residual"}, {"p_from", s.lobes}, {"material", m.name}, {"sigma_a", m.sigma_a}};
      t.set_grazing_factor(factor.back());
      residual_index = set.tables.size();
      set.tables.push_back(std::move(t));
    }
    const std::vector<double> channel_sigmas(m.sigma_a.begin(), m.sigma_a.end());
    Pending& item = pending.emplace_back(Pending{first, energy_first, residual_index, channel_sigmas});
    if (shared_path) {
      // Every lobe and channel of a θd from one node set, shared with the materials of the same β.
      std::vector<double> betas;
      for (int p = 0; p < s.lobes; ++p) betas.push_back(m.beta_n[static_cast<std::size_t>(p)]);
      auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& x) { return x.betas == betas; });
      if (g == groups.end()) g = groups.insert(groups.end(), Group{betas, {}, {}, nullptr});
      item.channel0 = g->sigmas.size();
      g->sigmas.insert(g->sigmas.end(), channel_sigmas.begin(), channel_sigmas.end());
      g->members.push_back(pending.size() - 1);
    } else {
      unconverged += bake_np_grid(
          {c.eta, c.path, c.quadrature, s.lobes, channel_sigmas, thetas, phis,
           [&](int p) { return std::vector<double>{m.beta_n[static_cast<std::size_t>(p)]}; }, rules, {}},
          opt, "N_p " + m.name, [&](int p, std::size_t ic, std::size_t it, std::size_t, std::size_t ip, double v) {
            set.tables[first + static_cast<std::size_t>(p)].set((ic * nt + it) * nphi + ip, over(factor_at(p, channel_sigmas[ic], it), v));
          });
    }
    report.entries += 3 * nt * (nphi * static_cast<std::size_t>(s.lobes) + static_cast<std::size_t>(lobe_set.size()));
  }
  for (Group& g : groups) {
    MaterialNpRequest mr{c.eta, c.path, g.betas, g.sigmas, thetas, phis, c.quadrature.tolerance, &rules_shared};
    mr.channels = pending[g.members.front()].sigmas.size();
    g.np = std::make_unique<MaterialNp>(std::move(mr));
    if (!g.np->note().empty() && &g == &groups.front()) report.notes.push_back("per-material N_p: " + g.np->note());
  }
  const auto E = static_cast<std::size_t>(lobe_set.size());
  // The energies of one material at θd node it: from N_p's own nodes (e[(channel0 + ic) · E + p])
  // without a residual, else by material_energies (lobe_energies' rule and integrand: the
  // residual's integrand (1 − f)² f^{P−1} T^P / (1 − fT) needs more nodes than N_p's wide lobes have).
  auto store_energies = [&](const Pending& w, std::size_t it, const std::vector<double>* from_np, std::size_t channel0) {
    std::vector<double> own;
    const std::vector<double>* e = from_np;
    if (!e) {
      material_energies(c.eta, thetas[it], c.path, w.sigmas, lobe_set, s.energy_rule, own);
      e = &own, channel0 = 0;
    }
    for (std::size_t ic = 0; ic < w.sigmas.size(); ++ic) {
      const double* ep = e->data() + (channel0 + ic) * E;
      const double sigma = w.sigmas[ic];
      for (std::size_t p = 0; p < E; ++p) set.tables[w.energy_first + p].set(ic * nt + it, over(factor_at(static_cast<int>(p), sigma, it), ep[p]));
      if (c.residual) set.tables[w.residual_index].set(ic * nt + it, over(factor_at(static_cast<int>(E - 1), sigma, it), ep[E - 1] / kTwoPi));
    }
  };
  // One parallel loop over every (group, θd), or (material, θd) for the per-entry methods: N_p of
  // every lobe and channel and the lobe energies of every channel at once. Few large loops rather
  // than two per material: less time in OpenMP's start and spin-waiting.
  const std::size_t units = shared_path ? groups.size() : pending.size();
  std::size_t per_unit = 3 * nphi * static_cast<std::size_t>(s.lobes);
  if (shared_path && !groups.empty()) per_unit *= pending.size() / groups.size();
  parallel_for(units * nt, opt, "N_p and energies (per material)", per_unit, [&](std::size_t item) {
    const std::size_t it = item % nt;
    if (!shared_path) {
      store_energies(pending[item / nt], it, nullptr, 0);
      return;
    }
    const Group& g = groups[item / nt];
    const std::size_t K = g.sigmas.size();
    thread_local std::vector<double> v, e;  // reused: evaluate writes every value
    g.np->evaluate(it, v, c.residual ? nullptr : &e);
    for (const std::size_t member : g.members) {
      const Pending& w = pending[member];
      for (int p = 0; p < s.lobes; ++p) {
        Table& t = set.tables[w.first + static_cast<std::size_t>(p)];
        for (std::size_t ic = 0; ic < w.sigmas.size(); ++ic) {
          const double* src = v.data() + (static_cast<std::size_t>(p) * K + w.channel0 + ic) * nphi;
          const std::size_t dst = (ic * nt + it) * nphi;
          const double gp = factor_at(p, w.sigmas[ic], it);  // once per row
          auto stored = [&](double x) { return over(gp, x); };
          if (t.precision == Precision::float32) std::transform(src, src + nphi, t.f32.data() + dst, [&](double x) { return static_cast<float>(stored(x)); });
          else std::transform(src, src + nphi, t.f64.data() + dst, stored);
        }
      }
      store_energies(w, it, c.residual ? nullptr : &e, w.channel0);
    }
  });
}

}  // namespace hairlut::detail
