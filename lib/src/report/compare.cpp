#include "hairlut/report/compare.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "hairlut/physics/azimuthal_np.hpp"
#include "hairlut/bake/bake.hpp"
#include "hairlut/physics/directional_albedo.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/report/report.hpp"
#include "hairlut/report/svg_plot.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;

constexpr const char* kLobes[3] = {"R", "TT", "TRT"};

// JSON has no infinity: non-finite values become null (a gap in the plots).
json finite_array(const std::vector<double>& v) {
  json a = json::array();
  for (double x : v) a.push_back(std::isfinite(x) ? json(x) : json(nullptr));
  return a;
}

std::vector<double> to_vec(const json& j) {
  std::vector<double> v;
  for (const json& x : j) v.push_back(x.is_number() ? x.get<double>() : NAN);
  return v;
}

std::vector<double> degrees_of(const std::vector<double>& v) {
  std::vector<double> d;
  for (double x : v) d.push_back(degrees(x));
  return d;
}

std::string fmt(double v, int digits = 3) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

void check_cancel(const CompareSettings& s) {
  if (s.cancel && s.cancel->load()) throw BakeCancelled();
}

MarschnerParams marschner_params(const CompareSettings& s, MarschnerRoots roots) {
  MarschnerParams p = s.marschner.params;
  p.eta = s.eta;
  p.path = s.path;
  p.roots = roots;
  return p;
}

// d'Eon's model with the same lobes: β_m = β_n = Marschner's widths, tilt 2α_p, residual as TRT.
HairModel deon_model(const CompareSettings& s, const MarschnerLobes& l, bool residual) {
  HairModel m;
  m.eta = s.eta;
  m.sigma_a = s.sigma_a;
  m.path = s.path;
  for (int p = 0; p < 3; ++p) m.lobes.push_back({l.beta[p], l.beta[p], std::clamp(2.0 * l.alpha[p], -kHalfPi, kHalfPi)});
  if (residual) m.residual = m.lobes.back();
  return m;
}

KajiyaKayParams kajiya_kay_of(const CompareSettings& s) {
  KajiyaKayParams k = s.kajiya_kay;
  if (k.exponent <= 0.0) k.exponent = KajiyaKayParams::exponent_for_width(s.beta_r);
  if (k.kd == 0.0 && k.ks == 0.0) {
    k.ks = 1.0;
    k.ks = 1.0 / kajiya_kay_energy(k, 0.0);  // E_KK(0) = 1
  }
  return k;
}

// ---- N_p(φ) per lobe at each θd.
json polar_section(const CompareSettings& s) {
  json out = json::array();
  const int n = std::max(3, s.phi_samples);
  std::vector<double> phis(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) phis[static_cast<std::size_t>(j)] = kPi * j / (n - 1);
  const MarschnerLobes lobes = s.marschner.lobes(s.beta_r);
  const GaussLegendreRule rule(2048);
  const GaussLegendreRule energy_rule(256);
  for (std::size_t it = 0; it < s.theta_d.size(); ++it) {
    check_cancel(s);
    if (s.progress) s.progress("N_p per lobe", it, s.theta_d.size());
    const double td = s.theta_d[it];
    const AttenuationSlice slice(s.eta, td, s.sigma_a, s.path);
    const MarschnerAzimuthal exact(marschner_params(s, MarschnerRoots::exact), td, s.phi_h);
    const MarschnerAzimuthal cubic(marschner_params(s, MarschnerRoots::cubic), td, s.phi_h);
    const auto deon_e = lobe_energies(slice, {3, false}, energy_rule);
    json entry = {{"theta_d_deg", degrees(td)}, {"phi_deg", degrees_of(phis)}, {"lobes", json::object()}};
    std::vector<double> tot_smooth(phis.size(), 0.0), tot_rough(phis.size(), 0.0), tot_exact(phis.size(), 0.0), tot_cubic(phis.size(), 0.0);
    json energies = json::object();
    for (int p = 0; p < 3; ++p) {
      const NpQuadratureSlab slab(slice, p, rule);
      std::vector<double> smooth, rough, ex, cu;
      for (std::size_t j = 0; j < phis.size(); ++j) {
        smooth.push_back(azimuthal_np_smooth(slice, p, phis[j]));
        // Order 2048 resolves detectors down to 0.25°; narrower ones take the adaptive reference.
        rough.push_back(lobes.beta[p] >= radians(0.25) ? slab(lobes.beta[p], phis[j])
                                                       : azimuthal_np_reference(slice, p, lobes.beta[p], phis[j], 1e-10).value[0]);
        ex.push_back(exact.np(p, s.sigma_a, phis[j]));
        cu.push_back(cubic.np(p, s.sigma_a, phis[j]));
        tot_smooth[j] += smooth.back(), tot_rough[j] += rough.back(), tot_exact[j] += ex.back(), tot_cubic[j] += cu.back();
      }
      const double sig = s.sigma_a;
      double e_exact = 0.0, e_cubic = 0.0;
      exact.energy(p, std::span<const double>(&sig, 1), std::span<double>(&e_exact, 1));
      cubic.energy(p, std::span<const double>(&sig, 1), std::span<double>(&e_cubic, 1));
      entry["lobes"][kLobes[p]] = {{"deon_smooth", finite_array(smooth)}, {"deon_rough", finite_array(rough)},
                                   {"marschner_exact", finite_array(ex)}, {"marschner_cubic", finite_array(cu)},
                                   {"beta_n_deg", degrees(lobes.beta[p])}};
      energies[kLobes[p]] = {{"deon", deon_e[static_cast<std::size_t>(p)]}, {"marschner_exact", e_exact}, {"marschner_cubic", e_cubic}};
    }
    const double e_total = deon_e[0] + deon_e[1] + deon_e[2];
    entry["lobes"]["total"] = {{"deon_smooth", finite_array(tot_smooth)}, {"deon_rough", finite_array(tot_rough)},
                               {"marschner_exact", finite_array(tot_exact)}, {"marschner_cubic", finite_array(tot_cubic)},
                               {"kajiya_kay", std::vector<double>(phis.size(), e_total / kTwoPi)}};
    entry["energies"] = energies;
    entry["eta_prime"] = 1.0 / exact.geometry(0).inv_eta_prime;
    entry["trt_caustic"] = {{"folds", exact.caustic().folds}, {"t", exact.caustic().t}, {"phi_c_deg", degrees(exact.caustic().phi_c)},
                            {"phi_c_cubic_deg", degrees(cubic.caustic().phi_c)}};
    out.push_back(entry);
  }
  return out;
}

// ---- Energy per θi.
json energy_section(const CompareSettings& s) {
  std::vector<double> thetas = s.theta_i;
  if (thetas.empty())
    for (int d = -85; d <= 85; d += 10) thetas.push_back(radians(d));
  const MarschnerLobes lobes = s.marschner.lobes(s.beta_r);
  const HairModel deon = deon_model(s, lobes, true);
  const KajiyaKayParams kk = kajiya_kay_of(s);
  std::vector<double> d3, dres, mex, mcu, kkv;
  std::vector<std::vector<double>> mex_lobes(3);
  for (std::size_t i = 0; i < thetas.size(); ++i) {
    check_cancel(s);
    if (s.progress) s.progress("energy per theta_i", i, thetas.size());
    const double ti = thetas[i];
    const AlbedoResult a = directional_albedo(deon, ti, 1e-8);
    d3.push_back(a.per_lobe[0] + a.per_lobe[1] + a.per_lobe[2]);
    dres.push_back(a.total);
    const MarschnerAlbedo e = marschner_directional_albedo(marschner_params(s, MarschnerRoots::exact), lobes, s.marschner.argument, s.sigma_a, ti, s.phi_h);
    mex.push_back(e.total);
    for (int p = 0; p < 3; ++p) mex_lobes[static_cast<std::size_t>(p)].push_back(e.per_lobe[static_cast<std::size_t>(p)]);
    mcu.push_back(marschner_directional_albedo(marschner_params(s, MarschnerRoots::cubic), lobes, s.marschner.argument, s.sigma_a, ti, s.phi_h).total);
    kkv.push_back(kajiya_kay_energy(kk, ti));
  }
  json out = {{"theta_i_deg", degrees_of(thetas)},
              {"deon_R+TT+TRT", d3},
              {"deon_with_residual", dres},
              {"marschner_exact", mex},
              {"marschner_cubic", mcu},
              {"kajiya_kay", kkv},
              {"marschner_exact_per_lobe", {{"R", mex_lobes[0]}, {"TT", mex_lobes[1]}, {"TRT", mex_lobes[2]}}},
              {"kajiya_kay_params", {{"kd", kk.kd}, {"ks", kk.ks}, {"exponent", kk.exponent}}},
              {"measure", "d'Eon: int S cos(theta_r) dtheta_r dphi (hairlut conventions); Marschner and Kajiya-Kay: int S cos^2(theta_r) dtheta_r dphi "
                          "(d'Eon 2011 eq. 5)"}};
  return out;
}

// ---- Where the cubic approximation departs from the exact roots.
double max_snell_error(double eta_prime) {
  const double a = 1.0 / eta_prime, c = cubic_edge_angle(a);
  double worst = 0.0;
  for (int k = 0; k <= 4000; ++k) {
    const double g = kHalfPi * k / 4000.0;
    worst = std::max(worst, std::abs(cubic_gamma_t(g, c) - std::asin(std::sin(g) * a)));
  }
  return worst;
}

json cubic_section(const CompareSettings& s) {
  json out;
  std::vector<double> eps, err;
  for (int k = 0; k <= 120; ++k) {
    const double ep = 1.01 * std::pow(3.0 / 1.01, k / 120.0);
    eps.push_back(ep);
    err.push_back(degrees(max_snell_error(ep)));
  }
  double above = 0.0;
  for (double ep = 1.5; ep <= 100.0; ep *= 1.005) above = std::max(above, degrees(max_snell_error(ep)));
  const double water = s.eta / 1.333;
  out["snell"] = {{"eta_prime", eps}, {"max_error_deg", err}, {"claim_deg", 0.75}, {"max_error_eta_prime_ge_1_5_deg", above},
                  {"max_error_at_1_2_deg", degrees(max_snell_error(1.2))},
                  {"in_water", {{"eta_prime", water}, {"max_error_deg", water > 1.0 ? degrees(max_snell_error(water)) : NAN}}},
                  {"fiber_theta_d_0", {{"eta_prime", s.eta}, {"max_error_deg", degrees(max_snell_error(s.eta))}}}};
  // Root and N_p errors per φ for a few Bravais indices (the map depends on η' only).
  json cases = json::array();
  const int n = 181;
  struct Case {
    double eta_prime;
    std::string label;
  };
  std::vector<Case> list = {{1.2, "eta' = 1.2"}, {s.eta, "this fiber at theta_d = 0"}};
  if (water > 1.01) list.insert(list.begin() + 1, {water, "this fiber in water (eta/1.333)"});
  for (const Case& c : list) {
    check_cancel(s);
    const FiberGeometry g = FiberGeometry::make(c.eta_prime, 0.0);
    MarschnerParams pe = marschner_params(s, MarschnerRoots::exact), pc = marschner_params(s, MarschnerRoots::cubic);
    pe.eta = pc.eta = c.eta_prime;
    pe.eccentricity = pc.eccentricity = 1.0;
    const MarschnerAzimuthal me(pe, 0.0), mc(pc, 0.0);
    json cj = {{"eta_prime", c.eta_prime}, {"label", c.label}, {"phi_deg", json::array()}};
    for (int p = 1; p <= 2; ++p) {
      std::vector<double> root_err, np_err, ne, nc;
      double peak = 0.0;
      for (int j = 0; j < n; ++j) {
        const double phi = kPi * j / (n - 1);
        const auto re = azimuthal_roots(g, p, phi);
        const auto rc = cubic_azimuthal_roots(g.inv_eta_prime, p, phi);
        double e = NAN;
        if (re.size() == rc.size() && !re.empty()) {
          e = 0.0;
          for (std::size_t k = 0; k < re.size(); ++k) e = std::max(e, std::abs(re[k] - rc[k]));
          e = degrees(e);
        }
        root_err.push_back(e);
        ne.push_back(me.np(p, s.sigma_a, phi));
        nc.push_back(mc.np(p, s.sigma_a, phi));
        peak = std::max(peak, ne.back());
        if (p == 1) cj["phi_deg"].push_back(degrees(phi));
      }
      for (int j = 0; j < n; ++j) np_err.push_back(peak > 0 ? std::abs(nc[static_cast<std::size_t>(j)] - ne[static_cast<std::size_t>(j)]) / peak : 0.0);
      double max_root = 0.0, max_np = 0.0;
      for (double v : root_err)
        if (std::isfinite(v)) max_root = std::max(max_root, v);
      for (double v : np_err) max_np = std::max(max_np, v);
      cj[kLobes[p]] = {{"root_error_deg", finite_array(root_err)}, {"np_error_rel_peak", np_err}, {"max_root_error_deg", max_root},
                       {"max_np_error_rel_peak", max_np}};
    }
    cases.push_back(cj);
  }
  out["cases"] = cases;
  return out;
}

// ---- The TRT caustic against θd (and φh).
json caustic_section(const CompareSettings& s) {
  std::vector<double> tds, pe, pc, ts;
  double merge = NAN;
  for (int k = 0; k <= 178; ++k) {
    const double td = radians(0.5 * k);
    const MarschnerAzimuthal e(marschner_params(s, MarschnerRoots::exact), td, s.phi_h);
    const MarschnerAzimuthal c(marschner_params(s, MarschnerRoots::cubic), td, s.phi_h);
    tds.push_back(0.5 * k);
    pe.push_back(e.caustic().t > 0 ? degrees(e.caustic().phi_c) : NAN);
    pc.push_back(c.caustic().t > 0 ? degrees(c.caustic().phi_c) : NAN);
    ts.push_back(e.caustic().t);
    if (std::isnan(merge) && !e.caustic().folds) merge = 0.5 * k;
  }
  json out = {{"theta_d_deg", tds}, {"phi_c_exact_deg", finite_array(pe)}, {"phi_c_cubic_deg", finite_array(pc)}, {"t", ts},
              {"merge_theta_d_deg", std::isfinite(merge) ? json(merge) : json(nullptr)}};
  if (s.marschner.params.eccentricity != 1.0) {
    std::vector<double> phs, pcs, etas;
    for (int k = 0; k <= 90; k += 3) {
      const MarschnerAzimuthal e(marschner_params(s, MarschnerRoots::exact), 0.0, radians(k));
      phs.push_back(k);
      pcs.push_back(e.caustic().t > 0 ? degrees(e.caustic().phi_c) : NAN);
      etas.push_back(e.geometry(2).eta);
    }
    out["eccentric"] = {{"phi_h_deg", phs}, {"phi_c_deg", finite_array(pcs)}, {"eta_star", etas}};
  }
  return out;
}

}  // namespace

void CompareSettings::validate() const {
  require_greater("eta", eta, 1.0, "must be a finite number > 1");
  require_non_negative("sigma_a", sigma_a);
  require_positive("beta_R", beta_r);
  MarschnerParams p = marschner.params;
  p.eta = eta;
  p.validate();
  if (theta_d.empty()) throw DomainError("theta_d must list at least one angle");
  for (double t : theta_d) checked_inclination("theta_d", t);
  for (double t : theta_i)
    if (!(std::abs(t) < kHalfPi)) throw_domain_error("theta_i", "must lie in (-pi/2, pi/2)", t);
  if (phi_samples < 3 || phi_samples > 100000) throw_domain_error("phi_samples", "must lie in [3, 100000]", static_cast<long long>(phi_samples));
}

nlohmann::ordered_json compare_models(const CompareSettings& s) {
  s.validate();
  const MarschnerLobes lobes = s.marschner.lobes(s.beta_r);
  json out;
  out["tool"] = "hairlut compare";
  out["fiber"] = {{"eta", s.eta}, {"sigma_a", s.sigma_a}, {"description", s.fiber}, {"absorption_path", to_string(s.path)},
                  {"phi_h", s.phi_h}};
  out["marschner"] = marschner_json(s.marschner);
  out["lobes"] = json::array();
  for (int p = 0; p < 3; ++p)
    out["lobes"].push_back({{"lobe", kLobes[p]}, {"beta_deg", degrees(lobes.beta[p])}, {"alpha_theta_h_deg", degrees(lobes.alpha[p])},
                            {"deon_tilt_deg", degrees(2.0 * lobes.alpha[p])}});
  out["polar"] = polar_section(s);
  out["cubic"] = cubic_section(s);
  out["caustic"] = caustic_section(s);
  if (s.energies) out["energy"] = energy_section(s);
  if (s.progress) s.progress("done", 1, 1);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Rendering.

namespace {

const char* kModelColour[] = {"#7f7f7f", "#1f77b4", "#d62728", "#ff7f0e", "#2ca02c"};

std::vector<svg::Series> polar_series(const json& lobe, const std::vector<double>& phis) {
  std::vector<svg::Series> v;
  auto add = [&](const char* key, const char* name, const char* colour, bool dashed) {
    if (!lobe.contains(key)) return;
    std::vector<double> rad;
    for (double d : phis) rad.push_back(radians(d));
    v.push_back({name, rad, to_vec(lobe[key]), colour, dashed, false});
  };
  add("deon_smooth", "d'Eon, beta -> 0", kModelColour[0], true);
  add("deon_rough", "d'Eon, rough", kModelColour[1], false);
  add("marschner_exact", "Marschner, exact", kModelColour[2], false);
  add("marschner_cubic", "Marschner, cubic", kModelColour[3], true);
  add("kajiya_kay", "Kajiya-Kay (same energy)", kModelColour[4], true);
  return v;
}

}  // namespace

std::string render_compare_html_sections(const json& c) {
  using svg::escape;
  std::ostringstream o;
  const json& f = c["fiber"];
  o << "<h2>Models side by side: d'Eon 2011, Marschner 2003, Kajiya&ndash;Kay</h2>\n<p>Fiber: &eta; = " << fmt(f["eta"].get<double>())
    << ", &sigma;<sub>a</sub> = " << fmt(f["sigma_a"].get<double>()) << " per unit radius"
    << (f["description"].get<std::string>().empty() ? "" : " (" + escape(f["description"].get<std::string>()) + ")") << ", absorption path "
    << escape(f["absorption_path"].get<std::string>()) << ". Lobes (Marschner Table 1; d'Eon uses the same widths as &beta;<sub>m</sub> = "
    << "&beta;<sub>n</sub> and tilts 2&alpha;): ";
  for (const json& l : c["lobes"])
    o << escape(l["lobe"].get<std::string>()) << " &beta; = " << fmt(l["beta_deg"].get<double>()) << "&deg;, &alpha; = " << fmt(l["alpha_theta_h_deg"].get<double>())
      << "&deg;; ";
  o << "caustic k<sub>G</sub> = " << fmt(c["marschner"]["caustic"]["k_G"].get<double>()) << ", w<sub>c</sub> = "
    << fmt(degrees(c["marschner"]["caustic"]["w_c"].get<double>())) << "&deg;, eccentricity " << fmt(c["marschner"]["eccentricity"].get<double>()) << ".</p>\n";
  o << "<h3>N<sub>p</sub>(&phi;) per lobe</h3><p>Polar plots of the azimuthal scattering function (radius N<sub>p</sub> in 1/rad, &phi; = 0 "
       "towards the light, mirrored to negative &phi;): d'Eon's smooth-fiber limit &beta; &rarr; 0 (infinite at the caustics: clipped at the rim), "
       "d'Eon at the lobe's roughness, Marschner with exact and with cubic paths (caustic replacement included).</p>\n";
  for (const json& e : c["polar"]) {
    const auto phis = to_vec(e["phi_deg"]);
    o << "<h4>&theta;<sub>d</sub> = " << fmt(e["theta_d_deg"].get<double>()) << "&deg; (&eta;&prime; = " << fmt(e["eta_prime"].get<double>(), 4)
      << (e["trt_caustic"]["folds"].get<bool>() ? ", TRT caustic at &plusmn;" + fmt(e["trt_caustic"]["phi_c_deg"].get<double>()) + "&deg;"
                                                : std::string(", TRT caustics merged"))
      << ")</h4><div class=\"plots\">\n";
    for (const char* lobe : {"R", "TT", "TRT", "total"}) {
      const json& l = e["lobes"][lobe];
      svg::PolarPlot p;
      p.title = std::string(lobe == std::string("total") ? "R + TT + TRT" : lobe);
      p.series = polar_series(l, phis);
      double rmax = 0.0;
      for (const char* k : {"deon_rough", "marschner_exact", "marschner_cubic"})
        for (double v : to_vec(l[k]))
          if (std::isfinite(v)) rmax = std::max(rmax, v);
      p.r_max = rmax > 0 ? 1.15 * rmax : NAN;
      if (e["energies"].contains(lobe)) {
        const json& en = e["energies"][lobe];
        p.note = "energy: d'Eon " + fmt(en["deon"].get<double>()) + ", M. exact " + fmt(en["marschner_exact"].get<double>()) + ", cubic " +
                 fmt(en["marschner_cubic"].get<double>());
      }
      p.size = 300;
      o << svg::polar_plot(p) << "\n";
    }
    o << "</div>\n";
  }
  if (c.contains("energy")) {
    const json& en = c["energy"];
    o << "<h3>Total energy per &theta;<sub>i</sub></h3><p>" << escape(en["measure"].get<std::string>())
      << ". d'Eon's model conserves energy when every lobe is included (the residual); Marschner's does not (its &theta;<sub>h</sub> Gaussian "
         "doubles the energy at low roughness; the caustic replacement adds or removes some); d'Eon's tilted lobes are only approximately normalized "
         "near grazing incidence (about cos(&theta;<sub>i</sub> &minus; &alpha;)/cos &theta;<sub>i</sub>, docs/conventions.md), which shows at "
         "|&theta;<sub>i</sub>| &gt; 75&deg;; Kajiya&ndash;Kay is normalized to E(0) = 1 (k<sub>s</sub> = "
      << fmt(en["kajiya_kay_params"]["ks"].get<double>()) << ", n = " << fmt(en["kajiya_kay_params"]["exponent"].get<double>()) << ").</p><div class=\"plots\">\n";
    svg::LinePlot p;
    p.title = "E(theta_i), sigma_a = " + fmt(f["sigma_a"].get<double>());
    p.xlabel = "theta_i [deg]";
    p.ylabel = "energy";
    p.y_reference = 1.0;
    const auto th = to_vec(en["theta_i_deg"]);
    p.series = {{"d'Eon R+TT+TRT", th, to_vec(en["deon_R+TT+TRT"]), kModelColour[1], true},
                {"d'Eon, all lobes", th, to_vec(en["deon_with_residual"]), kModelColour[1], false},
                {"Marschner, exact", th, to_vec(en["marschner_exact"]), kModelColour[2], false},
                {"Marschner, cubic", th, to_vec(en["marschner_cubic"]), kModelColour[3], true},
                {"Kajiya-Kay", th, to_vec(en["kajiya_kay"]), kModelColour[4], false}};
    o << svg::line_plot(p) << "\n";
    svg::LinePlot q;
    q.title = "Marschner (exact) per lobe";
    q.xlabel = "theta_i [deg]";
    q.ylabel = "energy";
    for (const char* l : {"R", "TT", "TRT"}) q.series.push_back({l, th, to_vec(en["marschner_exact_per_lobe"][l]), "", false});
    o << svg::line_plot(q) << "</div>\n";
  }
  const json& cu = c["cubic"];
  const json& sn = cu["snell"];
  o << "<h3>Marschner's cubic approximation against the exact paths</h3><p>Largest error of the cubic Snell law "
       "&gamma;&#770;<sub>t</sub>(&gamma;<sub>i</sub>) over the fiber: "
    << fmt(sn["max_error_eta_prime_ge_1_5_deg"].get<double>()) << "&deg; for &eta;&prime; &ge; 1.5 (Marschner: &lt; 0.75&deg; for &eta; &gt; 1.5), "
    << fmt(sn["max_error_at_1_2_deg"].get<double>()) << "&deg; at &eta;&prime; = 1.2";
  if (sn["in_water"]["max_error_deg"].is_number())
    o << ", " << fmt(sn["in_water"]["max_error_deg"].get<double>()) << "&deg; for this fiber in water (&eta;&prime; = "
      << fmt(sn["in_water"]["eta_prime"].get<double>(), 4) << ")";
  o << ". The exit azimuth of lobe p moves by 2p times that; near the caustic the number of paths can differ.</p><div class=\"plots\">\n";
  {
    svg::LinePlot p;
    p.title = "max |gamma_t cubic - exact| over the fiber";
    p.xlabel = "eta'";
    p.ylabel = "degrees";
    p.log_y = true;
    p.series = {{"cubic Snell error", to_vec(sn["eta_prime"]), to_vec(sn["max_error_deg"]), kModelColour[3], false},
                {"Marschner's 0.75 deg", {1.5, 3.0}, {0.75, 0.75}, "#999999", true}};
    o << svg::line_plot(p) << "\n";
  }
  for (const char* lobe : {"TT", "TRT"}) {
    svg::LinePlot p, q;
    p.title = std::string(lobe) + ": path error |gamma_i cubic - exact|";
    p.xlabel = "phi [deg]";
    p.ylabel = "degrees";
    p.log_y = true;
    q.title = std::string(lobe) + ": |N cubic - N exact| / peak";
    q.xlabel = "phi [deg]";
    q.ylabel = "relative to the lobe peak";
    q.log_y = true;
    for (const json& k : cu["cases"]) {
      const std::string name = "eta' " + fmt(k["eta_prime"].get<double>(), 4);
      p.series.push_back({name, to_vec(k["phi_deg"]), to_vec(k[lobe]["root_error_deg"]), "", false});
      q.series.push_back({name, to_vec(k["phi_deg"]), to_vec(k[lobe]["np_error_rel_peak"]), "", false});
    }
    o << svg::line_plot(p) << "\n" << svg::line_plot(q) << "\n";
  }
  o << "</div>\n";
  const json& ca = c["caustic"];
  o << "<h3>The TRT caustic</h3><p>Caustic azimuth &phi;<sub>c</sub> against &theta;<sub>d</sub> (Descartes' formula for the exact map, the cubic "
       "map's own fold for the cubic one) and the weight t of the caustic replacement, which fades from 1 to 0 past the merge at &eta;&prime; = 2"
    << (ca["merge_theta_d_deg"].is_number() ? " (&theta;<sub>d</sub> = " + fmt(ca["merge_theta_d_deg"].get<double>()) + "&deg; here)" : std::string())
    << ".</p><div class=\"plots\">\n";
  {
    svg::LinePlot p;
    p.title = "TRT caustic azimuth";
    p.xlabel = "theta_d [deg]";
    p.ylabel = "phi_c [deg]";
    const auto td = to_vec(ca["theta_d_deg"]);
    p.series = {{"exact", td, to_vec(ca["phi_c_exact_deg"]), kModelColour[2], false}, {"cubic", td, to_vec(ca["phi_c_cubic_deg"]), kModelColour[3], true}};
    o << svg::line_plot(p) << "\n";
    svg::LinePlot q;
    q.title = "caustic replacement weight t";
    q.xlabel = "theta_d [deg]";
    q.ylabel = "t";
    q.series = {{"t", td, to_vec(ca["t"]), "", false}};
    o << svg::line_plot(q) << "\n";
    if (ca.contains("eccentric")) {
      svg::LinePlot r;
      r.title = "eccentric fiber: phi_c against phi_h (theta_d = 0)";
      r.xlabel = "phi_h [deg]";
      r.ylabel = "phi_c [deg]";
      r.series = {{"phi_c", to_vec(ca["eccentric"]["phi_h_deg"]), to_vec(ca["eccentric"]["phi_c_deg"]), "", false}};
      o << svg::line_plot(r) << "\n";
    }
  }
  o << "</div>\n";
  return o.str();
}

std::string render_compare_html(const json& c) {
  return html_page("hairlut model comparison", "<h1>hairlut model comparison</h1>\n" + render_compare_html_sections(c));
}

std::string render_compare_markdown(const json& c) {
  std::ostringstream o;
  const json& f = c["fiber"];
  o << "# hairlut model comparison\n\nFiber: eta = " << fmt(f["eta"].get<double>()) << ", sigma_a = " << fmt(f["sigma_a"].get<double>())
    << (f["description"].get<std::string>().empty() ? "" : " (" + f["description"].get<std::string>() + ")") << "\n\n";
  o << "## Lobe energies (int N_p dphi)\n\n| theta_d | lobe | d'Eon | Marschner exact | Marschner cubic |\n|---|---|---|---|---|\n";
  for (const json& e : c["polar"])
    for (const auto& [lobe, en] : e["energies"].items())
      o << "| " << fmt(e["theta_d_deg"].get<double>()) << " | " << lobe << " | " << fmt(en["deon"].get<double>(), 4) << " | "
        << fmt(en["marschner_exact"].get<double>(), 4) << " | " << fmt(en["marschner_cubic"].get<double>(), 4) << " |\n";
  const json& sn = c["cubic"]["snell"];
  o << "\n## Cubic approximation\n\n- max |gamma_t cubic - exact| for eta' >= 1.5: " << fmt(sn["max_error_eta_prime_ge_1_5_deg"].get<double>())
    << " deg (Marschner: < 0.75 deg)\n- at eta' = 1.2: " << fmt(sn["max_error_at_1_2_deg"].get<double>()) << " deg\n";
  if (sn["in_water"]["max_error_deg"].is_number())
    o << "- this fiber in water (eta' = " << fmt(sn["in_water"]["eta_prime"].get<double>(), 4) << "): " << fmt(sn["in_water"]["max_error_deg"].get<double>())
      << " deg\n";
  for (const json& k : c["cubic"]["cases"])
    o << "- eta' = " << fmt(k["eta_prime"].get<double>(), 4) << " (" << k["label"].get<std::string>() << "): largest path error TT "
      << fmt(k["TT"]["max_root_error_deg"].get<double>()) << " deg, TRT " << fmt(k["TRT"]["max_root_error_deg"].get<double>())
      << " deg; largest N error (of the lobe peak) TT " << fmt(k["TT"]["max_np_error_rel_peak"].get<double>()) << ", TRT "
      << fmt(k["TRT"]["max_np_error_rel_peak"].get<double>()) << "\n";
  if (c.contains("energy")) {
    const json& en = c["energy"];
    o << "\n## Total energy per theta_i\n\n| theta_i | d'Eon R+TT+TRT | d'Eon all | Marschner exact | Marschner cubic | Kajiya-Kay |\n|---|---|---|---|---|---|\n";
    for (std::size_t i = 0; i < en["theta_i_deg"].size(); ++i)
      o << "| " << fmt(en["theta_i_deg"][i].get<double>()) << " | " << fmt(en["deon_R+TT+TRT"][i].get<double>(), 4) << " | "
        << fmt(en["deon_with_residual"][i].get<double>(), 4) << " | " << fmt(en["marschner_exact"][i].get<double>(), 4) << " | "
        << fmt(en["marschner_cubic"][i].get<double>(), 4) << " | " << fmt(en["kajiya_kay"][i].get<double>(), 4) << " |\n";
  }
  return o.str();
}

void write_compare(const json& compare, const std::filesystem::path& directory) {
  write_text_files(directory, {{"compare.json", compare.dump(1) + "\n"}, {"compare.md", render_compare_markdown(compare)},
                               {"compare.html", render_compare_html(compare)}});
}

}  // namespace hairlut
