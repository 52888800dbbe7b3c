#include "hairlut/bake/bake_engine.hpp"


#include <algorithm>
#include <cmath>
#include <optional>

#include "hairlut/util/angles.hpp"
#include "hairlut/physics/azimuthal_fourier.hpp"
#include "hairlut/bake/dual_scattering_grid.hpp"
#include "hairlut/bake/engine_preset.hpp"
#include "hairlut/bake/engine_presets.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "bake_internal.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;

// A table with its attributes (detail::make_table allocates it).
Table new_table(const std::string& group, const std::string& name, const std::string& quantity, const std::string& units,
                const std::string& long_name, const std::vector<GridAxis>& axes, Precision precision, json attributes) {
  Table t = detail::make_table(group, name, quantity, units, long_name, axes, precision);
  t.attributes = std::move(attributes);
  return t;
}

std::size_t axis_position(const std::vector<GridAxis>& axes, const std::string& name) {
  for (std::size_t i = 0; i < axes.size(); ++i)
    if (axes[i].name == name) return i;
  throw DomainError("internal: no axis named " + name);
}

// Row-major strides of the axes (last fastest).
std::vector<std::size_t> strides(const std::vector<GridAxis>& axes) {
  std::vector<std::size_t> s(axes.size(), 1);
  for (std::size_t k = axes.size(); k-- > 1;) s[k - 1] = s[k] * static_cast<std::size_t>(axes[k].count);
  return s;
}

// ---- Mean energy and dual scattering over (absorption, roughness, incidence) ------------------

struct DsGroup {
  std::string ds_group, me_group;  // table groups (either may be empty)
  std::vector<GridAxis> axes;
  std::string absorption_axis, roughness_axis, theta_axis;
  RoughnessMapping roughness;
  AbsorptionMapping absorption;
  double density_factor = 0.7;
};

// The definition of each table, with Zinke 2008's equation numbers (docs/dual-scattering.md).
const char* definition_of(const std::string& quantity_name) {
  if (quantity_name == "a_f")
    return "forward average attenuation: sum_p int M_p(theta_i, theta_r) [int_{pi/2 < |phi| <= pi} N_p dphi] cos(theta_r) dtheta_r "
           "(Zinke 2008 eq. 6 with hairlut's S for f_s)";
  if (quantity_name == "a_b")
    return "backward average attenuation: the same over |phi| <= pi/2 (Zinke 2008's backward analogue of eq. 6)";
  if (quantity_name == "alpha_f") return "sum_p a_f,p alpha_p / a_f: average shift of theta_r of the forward lobes (Zinke 2008 eq. 12-13)";
  if (quantity_name == "alpha_b") return "sum_p a_b,p alpha_p / a_b: average shift of theta_r of the backward lobes (Zinke 2008 eq. 12-13)";
  if (quantity_name == "beta_f2") return "sum_p a_f,p beta_m,p^2 / a_f: average longitudinal variance in theta_r, forward (Zinke 2008 eq. 12-13)";
  if (quantity_name == "beta_b2") return "sum_p a_b,p beta_m,p^2 / a_b: average longitudinal variance in theta_r, backward (Zinke 2008 eq. 12-13)";
  if (quantity_name == "A_b") return "A_b = a_b a_f^2 / (1 - a_f^2) + a_b^3 a_f^2 / (1 - a_f^2)^3 (Zinke 2008 eq. 14)";
  if (quantity_name == "delta_b")
    return "Delta_b = alpha_b (1 - 2 a_b^2 / (1 - a_f^2)^2) + alpha_f (2 (1 - a_f^2)^2 + 4 a_f^2 a_b^2) / (1 - a_f^2)^3 (Zinke 2008 eq. 16)";
  if (quantity_name == "sigma_b")
    return "sigma_b = (1 + d_b a_f^2) (a_b sqrt(2 beta_f^2 + beta_b^2) + a_b^3 sqrt(2 beta_f^2 + 3 beta_b^2)) / (a_b + a_b^3) "
           "(Zinke 2008 eq. 17: the a_b- and a_b^3-weighted mean of the spreads of the paths with one and three backward events)";
  if (quantity_name == "sigma_b_mixed")
    return "as sigma_b with the denominator a_b + a_b^3 (2 beta_f + 3 beta_b) of real-time implementations (e.g. Unity HDRP's "
           "HairMultipleScattering.hlsl): adds an angle to a number, kept for comparison only";
  if (quantity_name == "E_total") return "sum of the lobes' mean energies: the directional albedo E(theta_i)";
  return "";
}

json ds_definitions() {
  json d;
  for (const char* n : {"a_f", "a_b", "alpha_f", "alpha_b", "beta_f2", "beta_b2", "A_b", "delta_b", "sigma_b", "sigma_b_mixed", "E_total"})
    d[n] = definition_of(n);
  d["a_f_<lobe>, a_b_<lobe>"] = "lobe p's part of a_f and a_b (the weights of eq. 12-13)";
  d["E_<lobe>"] = "mean energy (directional albedo) of lobe p: int M_p(theta_i, theta_r) e_p(theta_d) cos(theta_r) dtheta_r, e_p = 1/2 int A(p, h) dh";
  return d;
}

void bake_ds_group(const BakeConfig& c, const DsGroup& g, const BakeOptions& opt, TableSet& set, BakeReport& report, json& groups) {
  const Precision precision = c.output.hdf5_double ? Precision::float64 : Precision::float32;
  const std::size_t ia = axis_position(g.axes, g.absorption_axis), ir = axis_position(g.axes, g.roughness_axis),
                    it = axis_position(g.axes, g.theta_axis);
  const auto st = strides(g.axes);
  const std::vector<double> a_nodes = g.axes[ia].nodes(), r_nodes = g.axes[ir].nodes(), t_nodes = g.axes[it].nodes();

  DualScatteringGridRequest rq;
  rq.eta = c.eta;
  rq.path = c.path;
  rq.lobes = g.roughness.lobes;
  rq.residual = g.roughness.residual;
  for (double x : a_nodes) rq.sigmas.push_back(g.absorption.sigma_a(x));
  for (double x : r_nodes) rq.roughness.push_back(g.roughness.lobes_at(x));
  rq.thetas = t_nodes;
  rq.options.density_factor = g.density_factor;
  rq.options.energy_order = c.quadrature.energy_order;

  std::vector<std::string> lobes;
  for (int p = 0; p < rq.lobes; ++p) lobes.push_back(lobe_name(p));
  if (rq.residual) lobes.push_back("residual");
  const json mapping = {{"roughness_axis", g.roughness_axis}, {"roughness_mapping", g.roughness.describe()},
                        {"absorption_axis", g.absorption_axis}, {"absorption_mapping", g.absorption.describe()},
                        {"theta_axis", g.theta_axis}, {"lobes", lobes}, {"density_factor", g.density_factor}};

  // Tables, in a fixed order; `slot` maps each quantity to its table.
  const std::size_t first = set.tables.size();
  struct Slot {
    std::size_t table;
    std::function<double(const DualScatteringPoint&)> value;
  };
  std::vector<Slot> slots;
  auto add = [&](const std::string& group, const std::string& name, const std::string& quantity, const std::string& units,
                 const std::string& long_name, std::function<double(const DualScatteringPoint&)> value, json extra = json::object()) {
    json attributes = {{"definition", definition_of(name)}};
    for (auto& [k, v] : extra.items()) attributes[k] = v;
    attributes["parameters"] = mapping;
    slots.push_back({set.tables.size(), std::move(value)});
    set.tables.push_back(new_table(group, name, quantity, units, long_name, g.axes, precision, attributes));
  };
  if (!g.ds_group.empty()) {
    const std::string& G = g.ds_group;
    add(G, "a_f", "attenuation", "1", "forward average attenuation a_f (Zinke 2008 eq. 6)", [](const auto& p) { return p.a_f; });
    add(G, "a_b", "attenuation", "1", "backward average attenuation a_b", [](const auto& p) { return p.a_b; });
    for (std::size_t l = 0; l < lobes.size(); ++l) {
      const json lobe = {{"lobe", lobes[l]}, {"definition", "lobe " + lobes[l] + "'s part of a_f (the weights of Zinke eq. 12-13)"}};
      add(G, "a_f_" + lobes[l], "attenuation", "1", "forward attenuation of lobe " + lobes[l], [l](const auto& p) { return p.forward[l]; }, lobe);
      json lobe_b = lobe;
      lobe_b["definition"] = "lobe " + lobes[l] + "'s part of a_b (the weights of Zinke eq. 12-13)";
      add(G, "a_b_" + lobes[l], "attenuation", "1", "backward attenuation of lobe " + lobes[l], [l](const auto& p) { return p.backward[l]; }, lobe_b);
    }
    add(G, "alpha_f", "shift", "rad", "average forward shift alpha_f of theta_r", [](const auto& p) { return p.alpha_f; });
    add(G, "alpha_b", "shift", "rad", "average backward shift alpha_b of theta_r", [](const auto& p) { return p.alpha_b; });
    add(G, "beta_f2", "variance", "rad^2", "average forward longitudinal variance beta_f^2", [](const auto& p) { return p.beta_f2; });
    add(G, "beta_b2", "variance", "rad^2", "average backward longitudinal variance beta_b^2", [](const auto& p) { return p.beta_b2; });
    add(G, "A_b", "attenuation", "1", "backscattering attenuation A_b (Zinke 2008 eq. 14)", [](const auto& p) { return p.backscatter.A_b; });
    add(G, "delta_b", "shift", "rad", "backscattering shift Delta_b of theta_r (Zinke 2008 eq. 16)", [](const auto& p) { return p.backscatter.delta_b; });
    add(G, "sigma_b", "width", "rad", "backscattering spread sigma_b in theta_r (Zinke 2008 eq. 17)", [](const auto& p) { return p.backscatter.sigma_b; });
    add(G, "sigma_b_mixed", "width", "rad", "sigma_b with the public implementations' denominator (comparison only)",
        [](const auto& p) { return p.backscatter.sigma_b_mixed; });
  }
  if (!g.me_group.empty()) {
    for (std::size_t l = 0; l < lobes.size(); ++l)
      add(g.me_group, "E_" + lobes[l], "energy", "1", "mean energy (directional albedo) of lobe " + lobes[l], [l](const auto& p) { return p.energy[l]; },
          {{"lobe", lobes[l]}, {"definition", "int M_p(theta_i, theta_r) e_p(theta_d) cos(theta_r) dtheta_r of lobe " + lobes[l]}});
    add(g.me_group, "E_total", "energy", "1", "directional albedo E(theta_i): the sum of the lobes' mean energies", [](const auto& p) { return p.energy_total; });
  }
  const DualScatteringGridStats stats =
      dual_scattering_grid(rq, opt, g.ds_group.empty() ? g.me_group : g.ds_group, [&](std::size_t k, std::size_t r, std::size_t t, const DualScatteringPoint& p) {
        const std::size_t index = k * st[ia] + r * st[ir] + t * st[it];
        for (const Slot& s : slots) set.tables[s.table].set(index, s.value(p));
      });
  report.entries += stats.cells * slots.size();
  if (stats.unconverged)
    report.notes.push_back(std::to_string(stats.unconverged) + " dual-scattering integrals of " + (g.ds_group.empty() ? g.me_group : g.ds_group) +
                           " missed their tolerance");
  json entry = mapping;
  entry["tables"] = json::array();
  for (std::size_t i = first; i < set.tables.size(); ++i) entry["tables"].push_back(set.tables[i].path());
  entry["fourier_widths"] = stats.fourier_widths;
  entry["direct_widths"] = stats.direct_widths;
  entry["unconverged"] = stats.unconverged;
  groups[g.ds_group.empty() ? g.me_group : g.ds_group] = entry;
}

}  // namespace

void unit_attenuation_np(double eta, int p, double theta_d, std::span<const double> betas, std::span<const double> phis,
                         double tolerance, std::vector<double>& out, GaussLegendreCache* rules) {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  for (double b : betas) require_positive("beta", b);
  for (double f : phis)
    if (!std::isfinite(f)) throw_domain_error("phi", "must be finite", f);
  out.assign(betas.size() * phis.size(), 0.0);
  if (betas.empty() || phis.empty()) return;
  const FiberGeometry g = FiberGeometry::make(eta, theta_d);
  const double beta_min = *std::min_element(betas.begin(), betas.end());
  const int N = fourier_terms(beta_min, tolerance);
  const int order = fourier_nodes(N, p, g, tolerance);
  std::optional<GaussLegendreRule> own;
  if (!rules) own.emplace(order);
  const GaussLegendreRule& rule = rules ? rules->get(order) : *own;
  // Node phases Φ_i and weights w_i π/4 cos γ_i on γ in [0, π/2].
  const auto x = rule.nodes();
  const auto w = rule.weights();
  const std::size_t m = x.size();
  std::vector<double> phase(m), weight(m);
  for (std::size_t i = 0; i < m; ++i) {
    const double gamma = 0.25 * kPi * (1.0 + x[i]);
    phase[i] = exit_azimuth(p, gamma, std::asin(std::sin(gamma) * g.inv_eta_prime));
    weight[i] = w[i] * 0.25 * kPi * std::cos(gamma);
  }
  // c_n = Σ_i w_i cos(n Φ_i), rotating e^{inΦ_i} and re-anchoring every 32 steps (as fourier_coefficients).
  std::vector<double> coeff(static_cast<std::size_t>(N) + 1), zr(m), zi(m), sr(m), si(m);
  for (std::size_t i = 0; i < m; ++i) sr[i] = std::cos(phase[i]), si[i] = std::sin(phase[i]);
  for (int n = 0; n <= N; ++n) {
    if (n % 32 == 0)
      for (std::size_t i = 0; i < m; ++i) zr[i] = std::cos(n * phase[i]), zi[i] = std::sin(n * phase[i]);
    double sum = 0.0;
    for (std::size_t i = 0; i < m; ++i) sum += zr[i] * weight[i];
    coeff[static_cast<std::size_t>(n)] = sum;
    for (std::size_t i = 0; i < m; ++i) {
      const double r = zr[i] * sr[i] - zi[i] * si[i];
      zi[i] = zr[i] * si[i] + zi[i] * sr[i];
      zr[i] = r;
    }
  }
  for (std::size_t b = 0; b < betas.size(); ++b) {
    const int Nb = std::min(N, fourier_terms(betas[b], tolerance));
    std::vector<double> v(static_cast<std::size_t>(Nb) + 1);
    for (int n = 0; n <= Nb; ++n)
      v[static_cast<std::size_t>(n)] = (n ? 2.0 : 1.0) * std::exp(-0.5 * static_cast<double>(n) * n * betas[b] * betas[b]) *
                                       coeff[static_cast<std::size_t>(n)] / kTwoPi;
    for (std::size_t j = 0; j < phis.size(); ++j) {
      // Σ v_n cos(n φ) by the Clenshaw recurrence (stable for any n).
      const double c2 = 2.0 * std::cos(phis[j]);
      double b1 = 0.0, b2 = 0.0;
      for (int n = Nb; n >= 1; --n) {
        const double b0 = v[static_cast<std::size_t>(n)] + c2 * b1 - b2;
        b2 = b1, b1 = b0;
      }
      const double value = v[0] + 0.5 * c2 * b1 - b2;
      out[b * phis.size() + j] = std::max(0.0, value);
    }
  }
}

void bake_dual_scattering_tables(const BakeConfig& c, const BakeOptions& opt, TableSet& set, BakeReport& report) {
  if (!c.dual_scattering && !c.engine) return;
  json groups = json::object();
  if (c.dual_scattering) {
    DsGroup g;
    g.ds_group = "dual_scattering";
    g.me_group = "mean_energy";
    g.axes = c.dual_scattering->axes;
    g.absorption_axis = "sigma_a", g.roughness_axis = "beta", g.theta_axis = "theta_i";
    g.roughness.parameter = RoughnessParameter::beta;
    g.roughness.lobes = c.lobe_count;
    g.roughness.residual = c.residual;
    g.roughness.scale = c.dual_scattering->lobe_scale;
    g.roughness.tilt = c.tilt;
    if (c.residual) g.roughness.tilt.push_back(c.residual_tilt);
    g.absorption.parameter = AbsorptionParameter::sigma_a;
    g.density_factor = c.dual_scattering->density_factor;
    bake_ds_group(c, g, opt, set, report, groups);
  }
  if (c.engine) {
    const EnginePreset& preset = engine_preset(c.engine->preset);
    const std::vector<EngineTexture> textures = engine_preset_textures(*c.engine);
    auto needed = [&](const std::string& group) {
      return std::any_of(textures.begin(), textures.end(), [&](const EngineTexture& t) { return t.group == group; });
    };
    for (const EngineTableSpec& s : preset.tables(c.residual)) {
      if (s.kind == "dual_scattering" || s.kind == "mean_energy") {
        // Dual scattering and mean energy share the grid: bake them together when either is wanted
        // (the mean energy of HDRP's axes has no texture but stays in the generic files).
        if (s.kind == "mean_energy") continue;
        DsGroup g;
        g.ds_group = s.group;
        g.me_group = s.group.substr(0, s.group.find('/')) + "/mean_energy";
        if (!needed(g.ds_group) && !needed(g.me_group)) continue;
        g.axes = s.axes;
        g.absorption_axis = s.absorption_axis, g.roughness_axis = s.roughness_axis, g.theta_axis = s.theta_axis;
        g.roughness = s.roughness;
        g.absorption = s.absorption;
        g.density_factor = c.engine->density_factor;
        bake_ds_group(c, g, opt, set, report, groups);
      } else if (needed(s.group)) {
        preset.bake(c, s, opt, set, report);  // a kind of the preset's own (lib/presets/)
      }
    }
    json tex = json::array();
    for (const EngineTexture& t : textures) tex.push_back(t.describe());
    set.metadata["engine"] = {{"preset", c.engine->preset}, {"textures", tex}, {"documentation", "docs/presets/" + c.engine->preset + ".md"}};
  }
  if (groups.empty()) return;  // HDRP's textures only: their tables carry their own definitions
  set.metadata["dual_scattering"] = {
      {"reference", "Zinke, Yuksel, Weber, Keyser 2008, Dual scattering approximation for fast multiple scattering in hair"},
      {"definitions", ds_definitions()},
      {"normalization",
       "hairlut's S integrates to the directional albedo E(theta_i) = int int S cos(theta_r) dphi dtheta_r. Zinke's eq. 6 carries "
       "1/pi as an average over a half-turn of incident azimuths; for a circular fiber S depends only on phi = phi_r - phi_i, so that "
       "average is the integrand itself: a_f and a_b here are Zinke's with S for f_s, and a_f + a_b = E(theta_i)"},
      {"halves", "backward |phi| <= pi/2, forward pi/2 < |phi| <= pi; the residual lobe is uniform in phi (half each)"},
      {"angles", "alpha and beta are shifts and widths of theta_r (hairlut's tilt, d'Eon's beta_m); Zinke's theta_h convention is half of "
                 "each (a quarter of beta^2)"},
      {"density_factor", "d_b = d_f = 0.7 unless the config says otherwise"},
      {"method",
       "b_p, f_p and e_p at 513 theta_d_j = (pi/2) sin(pi j / 1024) over [0, pi/2] (cubic Lagrange interpolation in j, even about 0): b_p, f_p from "
       "the Fourier coefficients of N_p (int_{|phi|<=pi/2} cos(n phi) dphi = 2 sin(n pi/2)/n) for beta_n needing at most 320 terms "
       "(tolerance 1e-11), below that by adaptive Gauss-Kronrod of A(p, h) times the half-circle mass of the wrapped Gaussian, split "
       "where Phi(p, h) = +-pi/2; e_p by Gauss-Legendre in gamma; the theta_r integrals by adaptive Gauss-Kronrod (relative 1e-9) "
       "split at each lobe's specular cone and tilt fold. No Monte Carlo."},
      {"groups", groups}};
}

}  // namespace hairlut
