#include "hairlut/bake/beta_bands.hpp"

#include <cmath>

#include "bake_internal.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/physics/attenuation.hpp"
#include "hairlut/bake/config.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/util/quadrature.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

std::vector<BetaBand> parse_beta_bands(const nlohmann::json& bands, const nlohmann::json& np_axes_json,
                                       const std::function<std::vector<GridAxis>(const nlohmann::json&, const std::string&)>& make_axes) {
  const std::string where = "tables.np.beta_bands";
  if (!bands.is_array() || bands.empty()) throw DomainError(where + " must list at least one band");
  std::vector<BetaBand> out;
  for (std::size_t k = 0; k < bands.size(); ++k) {
    const std::string p = where + "[" + std::to_string(k) + "]";
    const nlohmann::json& b = bands[k];
    if (!b.is_object() || !b.contains("beta")) throw DomainError(p + ".beta is required (the band's beta axis)");
    nlohmann::json merged = np_axes_json;
    for (const auto& [key, value] : b.items()) {
      if (key != "beta" && key != "sigma_a" && key != "theta_d" && key != "phi")
        throw DomainError(p + "." + key + " is not an N_p axis (beta, sigma_a, theta_d, phi)");
      // The band's beta axis replaces the base one whole (a count with another range, or values);
      // the other axes take the band's keys over the base axis's.
      if (key == "beta" || !merged.contains(key)) merged[key] = value;
      else merged[key].merge_patch(value);
    }
    BetaBand band{make_axes(merged, p + ".")};
    const GridAxis& beta = band.axes.front();
    if (beta.placement != Placement::edges) throw DomainError(p + ".beta.placement must be edges (a shared band edge is a node of both bands)");
    if (beta.count < 2) throw DomainError(p + ".beta.count must be >= 2 (a band spans a range)");
    if (!out.empty()) {
      const double prev = out.back().hi();
      if (std::abs(beta.lo - prev) > 1e-12 * std::max(1.0, prev))
        throw DomainError(p + ".beta.range must start where band " + std::to_string(k - 1) + " ends (" + std::to_string(degrees(prev)) +
                          " deg; got " + std::to_string(degrees(beta.lo)) + " deg)");
      band.axes.front().lo = prev;  // exactly the shared edge
      const BetaBand& first = out.front();
      for (std::size_t a = 1; a <= 2; ++a)
        if (band.axes[a].lo != first.axes[a].lo || band.axes[a].hi != first.axes[a].hi)
          throw DomainError(p + "." + band.axes[a].name + ".range must equal band 0's (the energy tables are shared by the bands)");
    }
    out.push_back(std::move(band));
  }
  return out;
}

nlohmann::json beta_bands_json(const std::vector<BetaBand>& bands) {
  nlohmann::json a = nlohmann::json::array();
  for (const BetaBand& b : bands) {
    nlohmann::json axes = nlohmann::json::object();
    for (const GridAxis& g : b.axes) axes[g.name] = g.to_json();
    a.push_back({{"range", {b.lo(), b.hi()}}, {"axes", axes}});
  }
  return a;
}

void append_beta_band_tables(const BakeConfig& c, const std::vector<BetaBand>& bands, int lobes, bool normalize_energy, Precision precision,
                             const BakeOptions& opt, TableSet& set, BakeReport& report) {
  const int n = static_cast<int>(bands.size());
  auto band_json = [&](int k) {
    return nlohmann::ordered_json{{"index", k}, {"count", n}, {"range", {bands[static_cast<std::size_t>(k)].lo(), bands[static_cast<std::size_t>(k)].hi()}}};
  };
  nlohmann::ordered_json meta = nlohmann::ordered_json::array();
  for (int k = 0; k < n; ++k) meta.push_back({{"range", band_json(k)["range"]}, {"suffix", beta_band_suffix(k)}});
  set.metadata["np_beta_bands"] = meta;
  for (int p = 0; p < lobes; ++p)
    for (Table& t : set.tables)
      if (t.group == "np" && t.name == lobe_name(p)) t.attributes["beta_band"] = band_json(0);
  const GaussLegendreRule energy_rule(c.quadrature.energy_order);
  const auto rules = std::make_shared<GaussLegendreCache>();
  for (int k = 1; k < n; ++k) {
    const std::vector<GridAxis>& axes = bands[static_cast<std::size_t>(k)].axes;
    const std::vector<double> betas = axes[0].nodes(), sigmas = axes[1].nodes(), thetas = axes[2].nodes(), phis = axes[3].nodes();
    const std::size_t ns = sigmas.size(), nt = thetas.size(), nphi = phis.size();
    // The lobe energies at this band's (σa, θd) nodes: N_p / E_p is exact at every node.
    std::vector<double> energy;
    if (normalize_energy) {
      energy.assign(static_cast<std::size_t>(lobes) * ns * nt, 0.0);
      detail::parallel_for(ns * nt, opt, "energies", 1, [&](std::size_t item) {
        const std::size_t is = item / nt, it = item % nt;
        const auto e = lobe_energies(AttenuationSlice(c.eta, thetas[it], sigmas[is], c.path), LobeSet{lobes, false}, energy_rule);
        for (int p = 0; p < lobes; ++p) energy[(static_cast<std::size_t>(p) * ns + is) * nt + it] = e[static_cast<std::size_t>(p)];
      });
    }
    const std::size_t first = set.tables.size();
    for (int p = 0; p < lobes; ++p) {
      const std::string lobe = lobe_name(p);
      Table t = detail::make_table("np", lobe + beta_band_suffix(k), "N_p", "1/rad",
                                   (normalize_energy ? "shape N_p / E_p of lobe " + lobe + " (N_p = this x np/energy_" + lobe + ")"
                                                     : "azimuthal scattering function N_p of lobe " + lobe) +
                                       ", beta band " + std::to_string(k),
                                   axes, precision);
      t.attributes = {{"lobe", lobe}, {"p", p}};
      if (normalize_energy) t.attributes["factor"] = "np/energy_" + lobe;
      t.attributes["beta_band"] = band_json(k);
      set.tables.push_back(std::move(t));
    }
    bake_np_grid({c.eta, c.path, c.quadrature, lobes, sigmas, thetas, phis, [&](int) { return betas; }, rules, {}}, opt,
                 "N_p band " + std::to_string(k), [&](int p, std::size_t is, std::size_t it, std::size_t ib, std::size_t ip, double v) {
                   if (!energy.empty()) {
                     const double e = energy[(static_cast<std::size_t>(p) * ns + is) * nt + it];
                     v = e > 1e-300 ? v / e : 0.0;  // a lobe absorbed to nothing has no shape
                   }
                   set.tables[first + static_cast<std::size_t>(p)].set(((ib * ns + is) * nt + it) * nphi + ip, v);
                 });
    report.entries += betas.size() * ns * nt * nphi * static_cast<std::size_t>(lobes);
  }
}

}  // namespace hairlut
