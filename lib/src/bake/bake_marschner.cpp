// The baker of model "marschner2003": Marschner et al. 2003's N_R, N_TT, N_TRT (smooth fiber,
// exact or cubic paths, caustic replacement, eccentricity) and Gaussian M_p tables, in the same
// layout conventions as the d'Eon tables.
//
// Exact and approximate: every N_p value is eq. 8 / §5.2.2 evaluated at the node (roots to
// rounding, no quadrature); lobe energies are adaptive Gauss–Kronrod integrals in γ to 1e−11.
// The M_p values are the closed-form Gaussians.
#include <chrono>
#include <cmath>

#include "bake_internal.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "hairlut/physics/marschner.hpp"
#include "hairlut/util/version.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;
using detail::axis_named;
using detail::make_table;
using detail::parallel_for;

std::string argument_name(GaussianArgument a) { return a == GaussianArgument::theta_h ? "theta-h" : "2theta-h"; }

// Table attributes of Marschner's M_p of lobe p with Gaussian width ratio·β (or β itself).
json mp_attributes(const MarschnerConfig& m, int p, const MarschnerLobes& lobes, bool per_material) {
  json a = {{"lobe", lobe_name(p)}, {"p", p}, {"model", "marschner2003"}, {"function", "gaussian"},
            {"argument", argument_name(m.argument)}, {"alpha_theta_h", lobes.alpha[p]}};
  if (per_material) a["beta"] = lobes.beta[p];
  else a["beta_ratio"] = lobes.beta[p] / lobes.beta[0];
  return a;
}

// The N_p tables of one σa list (generic axis or a material's RGB) over θd (, φh), φ, plus the lobe
// energies; writes through index(p, k, t, h, j) and energy_index(p, k, t, h).
struct NpTarget {
  std::vector<std::size_t> np, energy;  // table index per lobe
};

void bake_np(const BakeConfig& c, const std::vector<double>& sigmas, const std::vector<double>& thetas, const std::vector<double>& phi_hs,
             const std::vector<double>& phis, int lobes, const NpTarget& target, const BakeOptions& opt, const std::string& stage, TableSet& set) {
  const MarschnerParams& params = c.marschner->params;
  const std::size_t ns = sigmas.size(), nt = thetas.size(), nh = phi_hs.size(), nphi = phis.size();
  // One work item per (θd, φh); R and TT do not depend on φh and are baked in the items with h = 0.
  parallel_for(nt * nh, opt, stage, ns * nphi * static_cast<std::size_t>(lobes), [&](std::size_t item) {
    const std::size_t t = item / nh, h = item % nh;
    const MarschnerAzimuthal az(params, thetas[t], phi_hs[h]);
    std::vector<double> row(ns), e(ns);
    for (int p = 0; p < lobes; ++p) {
      const bool trt = p == 2;
      if (!trt && h != 0) continue;
      Table& np = set.tables[target.np[static_cast<std::size_t>(p)]];
      Table& en = set.tables[target.energy[static_cast<std::size_t>(p)]];
      const std::size_t hh = trt ? h : 0, nhh = trt ? nh : 1;
      for (std::size_t j = 0; j < nphi; ++j) {
        az.np(p, sigmas, phis[j], row);
        for (std::size_t k = 0; k < ns; ++k) np.set(((k * nt + t) * nhh + hh) * nphi + j, row[k]);
      }
      az.energy(p, sigmas, e);
      for (std::size_t k = 0; k < ns; ++k) en.set((k * nt + t) * nhh + hh, e[k]);
    }
  });
}

}  // namespace

TableSet bake_marschner(const BakeConfig& c, const BakeOptions& opt, BakeReport* report_out) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!c.marschner) throw DomainError("internal: bake_marschner needs the marschner settings");
  const MarschnerConfig& m = *c.marschner;
  BakeReport report;
  TableSet set;
  const Precision precision = c.output.hdf5_double ? Precision::float64 : Precision::float32;
  const bool per_material = c.scene && c.scene->mode == SceneConfig::Mode::per_material;
  const int lobes = c.lobe_count;
  report.explicit_lobes = lobes;

  set.metadata["hairlut_version"] = kVersion;
  set.metadata["model"] = c.model;
  set.metadata["name"] = c.name;
  set.metadata["description"] = c.description;
  set.metadata["conventions"] =
      "Marschner et al. 2003 with hairlut's angles (docs/conventions.md): S = sum_p M_p N_p with M_p = g(beta_p; theta_h - alpha_p)/cos^2(theta_d) "
      "(alpha shifts theta_h, Marschner's Table 1 sign), energy measure cos^2(theta_r) dtheta_r dphi; N_p = sum over paths A(p,h)/|2 dPhi/dh| with "
      "Phi(p,h) = 2p gamma_t - 2 gamma_i + p pi, A with the Bravais eta', eta'' Fresnel factors; TRT with the caustic replacement of sec. 5.2.2 "
      "and eta*(phi_h) of sec. 5.2.3; sigma_a per unit fiber radius";
  set.metadata["eta"] = c.eta;
  set.metadata["absorption_path"] = to_string(c.path);
  set.metadata["lobes"] = json::array();
  for (int p = 0; p < lobes; ++p) set.metadata["lobes"].push_back(lobe_name(p));
  set.metadata["residual"] = false;
  set.metadata["folded_lobes"] = json::array();
  set.metadata["quadrature"] = {{"method", "smooth-fiber paths (no quadrature)"},
                                {"roots", to_string(m.params.roots)},
                                {"energy_method", "adaptive gauss-kronrod in gamma, rel 1e-11"}};
  set.metadata["marschner"] = marschner_json(m);
  set.metadata["config_hash"] = c.hash;
  set.metadata["config"] = c.normalized.dump();
  set.metadata["precision"] = precision == Precision::float32 ? "float32" : "float64";

  const bool eccentric = m.params.eccentricity != 1.0;
  // ---- N_p and lobe energies.
  if (c.np_axes) {
    std::vector<GridAxis> np_axes = restricted_np_axes(c, &report.notes);
    const GridAxis theta_axis = axis_named(np_axes, "theta_d"), phi_axis = axis_named(np_axes, "phi");
    std::vector<double> phi_hs = {0.0};
    std::vector<GridAxis> h_axes;  // the φh axis of an eccentric TRT, if any
    if (eccentric) {
      h_axes.push_back(axis_named(np_axes, "phi_h"));
      phi_hs = h_axes.front().nodes();
    }
    auto axes_for = [&](int p, std::vector<GridAxis> lead, bool with_phi) {
      lead.push_back(theta_axis);
      if (p == 2) lead.insert(lead.end(), h_axes.begin(), h_axes.end());
      if (with_phi) lead.push_back(phi_axis);
      return lead;
    };
    auto add_np_tables = [&](const std::string& group, const std::string& prefix, const GridAxis& lead, const json& extra) {
      NpTarget target;
      for (int p = 0; p < lobes; ++p) {
        Table t = make_table(group, prefix + lobe_name(p), "N_p", "1/rad",
                             "Marschner 2003 azimuthal scattering function N_p of lobe " + lobe_name(p) +
                                 (p == 2 ? " (caustic replacement" + std::string(eccentric ? ", eta*(phi_h))" : ")") : ""),
                             axes_for(p, {lead}, true), precision);
        t.attributes = {{"lobe", lobe_name(p)}, {"p", p}, {"model", "marschner2003"}};
        t.attributes.update(extra);
        target.np.push_back(set.tables.size());
        set.tables.push_back(std::move(t));
      }
      for (int p = 0; p < lobes; ++p) {
        Table t = make_table(group, "energy_" + lobe_name(p), "energy", "1",
                             "energy int N_p dphi of Marschner's lobe " + lobe_name(p), axes_for(p, {lead}, false), precision);
        t.attributes = {{"lobe", lobe_name(p)}, {"p", p}, {"model", "marschner2003"}};
        t.attributes.update(extra);
        target.energy.push_back(set.tables.size());
        set.tables.push_back(std::move(t));
      }
      return target;
    };
    const std::vector<double> thetas = theta_axis.nodes(), phis = phi_axis.nodes();
    if (!per_material) {
      const GridAxis sigma_axis = axis_named(np_axes, "sigma_a");
      const NpTarget target = add_np_tables("np", "", sigma_axis, json::object());
      bake_np(c, sigma_axis.nodes(), thetas, phi_hs, phis, lobes, target, opt, "N_p", set);
      report.entries += sigma_axis.nodes().size() * thetas.size() * (phis.size() + 1) * static_cast<std::size_t>(lobes);
    } else {
      const GridAxis channel = channel_axis({"R", "G", "B"}, "colour channel (linear sRGB primaries)");
      for (const MaterialConfig& mat : c.scene->materials) {
        const NpTarget target = add_np_tables("materials/" + mat.name, "np_", channel, {{"material", mat.name}, {"sigma_a", mat.sigma_a}});
        const std::vector<double> sigmas(mat.sigma_a.begin(), mat.sigma_a.end());
        bake_np(c, sigmas, thetas, phi_hs, phis, lobes, target, opt, "N_p " + mat.name, set);
        report.entries += 3 * thetas.size() * (phis.size() + 1) * static_cast<std::size_t>(lobes);
      }
    }
  }

  // ---- Gaussian M_p: generic over (β_R, θi, θr) per lobe with Table 1's ratios; per material over (θi, θr).
  if (c.mp_axes) {
    const GridAxis ti_axis = axis_named(*c.mp_axes, "theta_i"), tr_axis = axis_named(*c.mp_axes, "theta_r");
    const std::vector<double> tis = ti_axis.nodes(), trs = tr_axis.nodes();
    const std::size_t ni = tis.size(), nr = trs.size();
    auto fill = [&](std::size_t first, const std::vector<MarschnerLobes>& per_beta, const std::string& stage) {
      const std::size_t nb = per_beta.size();
      parallel_for(nb * ni, opt, stage, nr * static_cast<std::size_t>(lobes), [&](std::size_t k) {
        const std::size_t ib = k / ni, ii = k % ni;
        const MarschnerLobes& l = per_beta[ib];
        for (int p = 0; p < lobes; ++p) {
          Table& t = set.tables[first + static_cast<std::size_t>(p)];
          for (std::size_t ir = 0; ir < nr; ++ir)
            t.set((ib * ni + ii) * nr + ir, longitudinal_gaussian(l.beta[p], l.alpha[p], tis[ii], trs[ir], m.argument));
        }
      });
      report.entries += nb * ni * nr * static_cast<std::size_t>(lobes);
    };
    if (!per_material) {
      const std::vector<double> betas = axis_named(*c.mp_axes, "beta").nodes();
      const std::size_t first = set.tables.size();
      const MarschnerLobes unit = m.lobes(1.0);
      for (int p = 0; p < lobes; ++p) {
        Table t = make_table("mp", lobe_name(p), "M_p", "1/rad",
                             "Marschner Gaussian longitudinal function g(beta_p; theta_h - alpha_p)/cos^2(theta_d) of lobe " + lobe_name(p) +
                                 ", beta_p = beta_ratio * beta (beta = beta_R)",
                             *c.mp_axes, precision);
        t.attributes = mp_attributes(m, p, unit, false);
        set.tables.push_back(std::move(t));
      }
      std::vector<MarschnerLobes> per_beta;
      for (double b : betas) per_beta.push_back(m.lobes(b));
      fill(first, per_beta, "M_p");
    } else {
      for (const MaterialConfig& mat : c.scene->materials) {
        MarschnerLobes l = m.lobes(mat.beta_m[0]);
        for (int p = 0; p < lobes; ++p) l.beta[p] = mat.beta_m[static_cast<std::size_t>(p)];
        const std::size_t first = set.tables.size();
        for (int p = 0; p < lobes; ++p) {
          Table t = make_table("materials/" + mat.name, "mp_" + lobe_name(p), "M_p", "1/rad",
                               "Marschner Gaussian M_p of lobe " + lobe_name(p) + " for material " + mat.name, {ti_axis, tr_axis}, precision);
          t.attributes = mp_attributes(m, p, l, true);
          t.attributes["material"] = mat.name;
          set.tables.push_back(std::move(t));
        }
        fill(first, {l}, "M_p " + mat.name);
      }
    }
  }

  for (const TableKindRequest& k : c.kinds) k.kind->bake(*k.settings, precision, set, report);  // lib/kinds/
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  report.threads = opt.threads;
  set.metadata["notes"] = report.notes;
  if (report_out) *report_out = report;
  return set;
}

}  // namespace hairlut
