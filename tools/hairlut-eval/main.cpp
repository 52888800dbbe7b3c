// hairlut-eval: print M_p, N_p, lobe energies and white-furnace energies for given parameters, so
// that a value can be checked by hand. Thin: all physics lives in the hairlut library.
#include "common/cli.hpp"
#include <cstdio>
#include <hairlut/hairlut.hpp>
#include <hairlut/bake/np_point.hpp>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace {

using hairlut::radians;
using nlohmann::ordered_json;

constexpr const char* kExamples = R"(Angles on the command line are in degrees; the library works in radians.

Examples:
  hairlut-eval mp --beta-deg 5 --theta-i-deg 30 --theta-r-deg -30
  hairlut-eval mp --beta-deg 5 --theta-i-deg 30 --theta-r-deg -34 --alpha-deg -4 --form gaussian-2h
  hairlut-eval np --lobe TRT --eta 1.55 --sigma-a 0.5 --theta-d-deg 20 --phi-deg 30 --beta-deg 5
  hairlut-eval np --lobe TT --beta-deg 0.72 --phi-deg 180 --sigma-a 0.5 --reference
  hairlut-eval np --lobe TT --beta-deg 1 --phi-deg 170 --order 35 --variable h --reference --smooth
  hairlut-eval energy --eta 1.55 --sigma-a 0 --theta-d-deg 80 --lobes 4 --residual
  hairlut-eval furnace --beta-deg 10 --lobes 3 --residual --theta-i-deg 0,45,80,89
  hairlut-eval furnace --beta-deg 5,2.5,10 --alpha-deg -4,2,6 --lobes 3 --residual --json
  hairlut-eval marschner --lobe TRT --sigma-a 0.2 --theta-d-deg 10 --phi-deg 15 --roots cubic
  hairlut-eval marschner --lobe TRT --eccentricity 0.9 --phi-h-deg 30 --phi-deg 25 --k-g 1 --w-c-deg 10
  hairlut-eval dual --beta-deg 14,7,28,28 --alpha-deg -4,2,8,8 --lobes 3 --residual --sigma-a 0.4 --theta-i-deg 0,30,60

np prints by default the value a table stores: the baker's quadrature (the detector's Fourier
series or direct spreading, chosen by cost) with --tolerance; --method gauss-legendre and
--method adaptive give the fixed-order rule and the adaptive reference instead, and every value
comes with the method that made it.

Exit status: 0 done, 1 an evaluation failed, 2 bad argument or command line (one line
"hairlut-eval: error: ..." on stderr).
)";

// Expands a per-lobe list given once for all lobes or once per lobe (plus one for the residual).
std::vector<double> per_lobe(const std::vector<double>& values, std::size_t count, const std::string& option) {
  if (values.size() == 1) return std::vector<double>(count, values[0]);
  if (values.size() == count) return values;
  throw hairlut::DomainError(option + " must give one value or one per lobe (" + std::to_string(count) +
                             " including the residual), got " + std::to_string(values.size()));
}

void print(const ordered_json& j, bool as_json) {
  if (as_json) {
    std::cout << j.dump(2) << "\n";
    return;
  }
  for (const auto& [key, value] : j.items()) {
    if (value.is_array()) {
      std::cout << key << ":\n";
      for (const auto& row : value) {
        std::cout << " ";
        for (const auto& [k, v] : row.items()) std::cout << " " << k << "=" << v.dump();
        std::cout << "\n";
      }
    } else {
      std::cout << key << " = " << value.dump() << "\n";
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"hairlut-eval: evaluate d'Eon 2011 (and Marschner 2003) hair scattering functions at given parameters"};
  app.footer(kExamples);
  app.require_subcommand(1);
  bool as_json = false;
  app.add_flag("--json", as_json, "print JSON instead of key = value lines");

  // Fiber parameters shared by np, energy and furnace.
  double eta = 1.55, sigma_a = 0.0;
  std::string path = "chord";
  auto add_fiber = [&](CLI::App* sub) {
    sub->add_option("--eta", eta, "index of refraction (> 1)")->capture_default_str();
    sub->add_option("--sigma-a", sigma_a, "absorption coefficient per unit fiber radius (>= 0)")->capture_default_str();
    sub->add_option("--absorption-path", path, "internal path length: chord (2 cos gt) or papers (2(1 + cos 2gt))")
        ->capture_default_str();
  };

  // mp
  auto* mp = app.add_subcommand("mp", "longitudinal function M_p(theta_i, theta_r)");
  double mp_beta = 5.0, theta_i = 30.0, theta_r = -30.0, alpha = 0.0;
  std::string form = "deon";
  mp->add_option("--beta-deg", mp_beta, "longitudinal roughness beta in degrees (v = beta^2 in radians^2)")->capture_default_str();
  mp->add_option("--theta-i-deg", theta_i, "incident inclination in degrees, [-90, 90]")->capture_default_str();
  mp->add_option("--theta-r-deg", theta_r, "exit inclination in degrees, [-90, 90]")->capture_default_str();
  mp->add_option("--alpha-deg", alpha, "cuticle tilt: shift of the cone in theta_r, degrees")->capture_default_str();
  mp->add_option("--form", form, "deon (eq. 7), gaussian (Marschner, theta_h) or gaussian-2h")
      ->check(CLI::IsMember({"deon", "gaussian", "gaussian-2h"}))
      ->capture_default_str();

  // np
  auto* np = app.add_subcommand("np", "azimuthal function N_p(phi) of one lobe");
  add_fiber(np);
  std::string lobe = "TRT";
  double theta_d = 20.0, phi = 30.0, np_beta = 5.0;
  int order = 64;
  std::string variable = "gamma", method = "baker";
  double tolerance = 1e-12;
  bool reference = false, smooth = false;
  np->add_option("--lobe", lobe, "R, TT, TRT, TRRT, ... or p<N>")->capture_default_str();
  np->add_option("--theta-d-deg", theta_d, "longitudinal difference angle in degrees, [-90, 90]")->capture_default_str();
  np->add_option("--phi-deg", phi, "relative azimuth in degrees")->capture_default_str();
  np->add_option("--beta-deg", np_beta, "azimuthal roughness (detector width) in degrees")->capture_default_str();
  auto* method_opt = np->add_option("--method", method,
                                     "baker: the baker's Fourier/spreading quadrature with --tolerance, the value a table stores "
                                     "(default); gauss-legendre: a fixed-order rule of --order nodes in --variable, not adaptive, "
                                     "so it misses narrow lobes; adaptive: the adaptive reference integrator with its error estimate")
                        ->check(CLI::IsMember({"baker", "gauss-legendre", "adaptive"}))
                        ->capture_default_str();
  np->add_option("--tolerance", tolerance, "error relative to the lobe peak (baker) or to the value (adaptive); the configs' default")
      ->check(CLI::Range(1e-15, 1e-2))
      ->capture_default_str();
  auto* order_opt = np->add_option("--order", order, "Gauss-Legendre order of --method gauss-legendre (d'Eon uses 35); implies it")
                        ->capture_default_str();
  auto* variable_opt = np->add_option("--variable", variable, "integration variable of --method gauss-legendre: gamma or h (as d'Eon); implies it")
                           ->capture_default_str();
  np->add_flag("--reference", reference, "also print the adaptive reference value and its error estimate");
  np->add_flag("--smooth", smooth, "also print the smooth-fiber (beta -> 0) value by root solving");

  // energy
  auto* energy = app.add_subcommand("energy", "lobe energies 1/2 int A(p, h) dh at one theta_d");
  add_fiber(energy);
  int lobes = 4;
  bool residual = false;
  energy->add_option("--theta-d-deg", theta_d, "longitudinal difference angle in degrees")->capture_default_str();
  energy->add_option("--lobes", lobes, "number of explicit lobes P (R, TT, TRT, ...)")->capture_default_str();
  energy->add_flag("--residual", residual, "add the residual of all lobes p >= P");

  // furnace
  auto* furnace = app.add_subcommand("furnace", "directional albedo E(theta_i) of the full model (white furnace for sigma_a = 0)");
  add_fiber(furnace);
  std::vector<double> betas = {10.0}, alphas = {0.0};
  std::vector<double> thetas = {-89, -60, -30, 0, 30, 60, 80, 89};
  furnace->add_option("--beta-deg", betas, "longitudinal roughness in degrees: one value, or one per lobe (+ residual)")
      ->delimiter(',');
  furnace->add_option("--alpha-deg", alphas, "tilt in degrees: one value, or one per lobe (+ residual)")->delimiter(',');
  furnace->add_option("--lobes", lobes, "number of explicit lobes P")->capture_default_str();
  furnace->add_flag("--residual", residual, "include the residual of all lobes p >= P");
  furnace->add_option("--theta-i-deg", thetas, "incident inclinations in degrees")->delimiter(',');

  // marschner
  auto* marschner = app.add_subcommand("marschner", "Marschner 2003's N_p(phi) of one lobe (R, TT or TRT), with its paths and caustic");
  add_fiber(marschner);
  std::string roots = "exact";
  double k_g = 0.5, w_c = 15.0, eccentricity = 1.0, phi_h = 0.0;
  marschner->add_option("--lobe", lobe, "R, TT or TRT")->capture_default_str();
  marschner->add_option("--theta-d-deg", theta_d, "longitudinal difference angle in degrees")->capture_default_str();
  marschner->add_option("--phi-deg", phi, "relative azimuth in degrees")->capture_default_str();
  marschner->add_option("--roots", roots, "exact or cubic (Marschner's eq. 10)")->capture_default_str();
  marschner->add_option("--k-g", k_g, "glint scale factor k_G")->capture_default_str();
  marschner->add_option("--w-c-deg", w_c, "caustic width w_c in degrees")->capture_default_str();
  marschner->add_option("--eccentricity", eccentricity, "eccentricity a of the cross-section")->capture_default_str();
  marschner->add_option("--phi-h-deg", phi_h, "azimuthal half angle in degrees (eccentric TRT)")->capture_default_str();
  // dual: mean energy and Zinke 2008's dual-scattering quantities at each theta_i.
  auto* dual = app.add_subcommand("dual", "mean energy per lobe and dual scattering (a_f, a_b, alpha, beta^2, A_b, Delta_b, sigma_b)");
  add_fiber(dual);
  double density = 0.7;
  dual->add_option("--beta-deg", betas, "roughness in degrees (beta_m = beta_n): one value, or one per lobe (+ residual)")->delimiter(',');
  dual->add_option("--alpha-deg", alphas, "tilt in degrees: one value, or one per lobe (+ residual)")->delimiter(',');
  dual->add_option("--lobes", lobes, "number of explicit lobes P")->capture_default_str();
  dual->add_flag("--residual", residual, "include the residual of all lobes p >= P");
  dual->add_option("--theta-i-deg", thetas, "incident inclinations in degrees")->delimiter(',');
  dual->add_option("--density-factor", density, "d_b of Zinke eq. 17")->capture_default_str();

  if (const auto rc = hairlut::tools::parse_command_line(app, "hairlut-eval", argc, argv)) return *rc;

  // The full model of the furnace and dual subcommands: per-lobe β (β_m = β_n) and tilts.
  auto model_from_options = [&] {
    hairlut::HairModel model;
    model.eta = eta;
    model.sigma_a = sigma_a;
    model.path = hairlut::parse_absorption_path(path, "--absorption-path");
    const std::size_t n = static_cast<std::size_t>(std::max(lobes, 0)) + (residual ? 1 : 0);
    const auto b = per_lobe(betas, n, "--beta-deg");
    const auto a = per_lobe(alphas, n, "--alpha-deg");
    for (std::size_t p = 0; p < n; ++p) {
      const hairlut::LobeParams lp{radians(b[p]), radians(b[p]), radians(a[p])};
      if (residual && p + 1 == n) model.residual = lp;
      else model.lobes.push_back(lp);
    }
    return model;
  };
  try {
    ordered_json out;
    if (mp->parsed()) {
      hairlut::require_positive("--beta-deg", mp_beta);
      const double b = radians(mp_beta), ti = radians(theta_i), tr = radians(theta_r), a = radians(alpha);
      out["form"] = form;
      out["v"] = b * b;
      if (form == "deon") {
        out["M"] = hairlut::longitudinal_deon_tilted(b * b, a, ti, tr);
        const auto e = hairlut::longitudinal_energy_deon(b * b, a, ti);
        out["energy_int_M_cos_theta_r"] = e.value[0];
      } else {
        const auto arg = form == "gaussian" ? hairlut::GaussianArgument::theta_h : hairlut::GaussianArgument::two_theta_h;
        // Marschner's α shifts θh; hairlut's --alpha-deg shifts θr, hence α/2.
        out["M"] = hairlut::longitudinal_gaussian(b, 0.5 * a, ti, tr, arg);
        out["energy_int_M_cos2_theta_r"] = hairlut::longitudinal_energy_gaussian(b, 0.5 * a, ti, arg).value[0];
      }
    } else if (np->parsed()) {
      const int p = hairlut::parse_lobe(lobe, "--lobe");
      const hairlut::AttenuationSlice slice(eta, radians(theta_d), sigma_a, hairlut::parse_absorption_path(path, "--absorption-path"));
      hairlut::require_positive("--beta-deg", np_beta);
      // --order or --variable alone ask for the fixed-order rule.
      if (method_opt->count() == 0 && (order_opt->count() > 0 || variable_opt->count() > 0)) method = "gauss-legendre";
      out["lobe"] = hairlut::lobe_name(p);
      out["p"] = p;
      if (method == "gauss-legendre") {
        const hairlut::GaussLegendreRule rule(order);
        const auto var = hairlut::parse_integration_variable(variable, "--variable");
        out["N"] = hairlut::azimuthal_np(slice, p, radians(np_beta), radians(phi), rule, var);
        out["method"] = "fixed-order Gauss-Legendre, " + std::to_string(order) + " nodes in " + variable +
                        " (not adaptive: a lobe narrower than the node spacing is missed or aliased)";
        out["order"] = order;
        out["variable"] = variable;
      } else if (method == "adaptive") {
        const auto r = hairlut::azimuthal_np_reference(slice, p, radians(np_beta), radians(phi), tolerance);
        out["N"] = r.value[0];
        out["method"] = "adaptive reference (Gauss-Kronrod between the detector breakpoints)";
        out["tolerance"] = tolerance;
        out["N_error"] = r.error[0];
        out["converged"] = r.converged;
      } else {
        const hairlut::PointNp b = hairlut::baker_np(eta, hairlut::parse_absorption_path(path, "--absorption-path"), radians(theta_d),
                                                    sigma_a, p, radians(np_beta), radians(phi), tolerance);
        out["N"] = b.value;
        out["method"] = b.method;
        out["tolerance"] = tolerance;
        if (!b.note.empty()) out["note"] = b.note;
      }
      if (reference) {
        const auto r = hairlut::azimuthal_np_reference(slice, p, radians(np_beta), radians(phi));
        out["N_reference"] = r.value[0];
        out["N_reference_error"] = r.error[0];
        out["N_reference_converged"] = r.converged;
      }
      if (smooth) out["N_smooth_fiber"] = hairlut::azimuthal_np_smooth(slice, p, radians(phi));
      const hairlut::GaussLegendreRule energy_rule(128);
      out["lobe_energy"] = hairlut::lobe_energies(slice, {p + 1, false}, energy_rule).back();
    } else if (energy->parsed()) {
      const hairlut::AttenuationSlice slice(eta, radians(theta_d), sigma_a, hairlut::parse_absorption_path(path, "--absorption-path"));
      const hairlut::LobeSet set{lobes, residual};
      const auto r = hairlut::lobe_energies_reference(slice, set);
      ordered_json rows = ordered_json::array();
      double total = 0.0;
      for (int p = 0; p < set.size(); ++p) {
        const bool is_res = p == lobes;
        rows.push_back({{"lobe", is_res ? "residual(p>=" + std::to_string(lobes) + ")" : hairlut::lobe_name(p)},
                        {"energy", r.value[static_cast<std::size_t>(p)]}});
        total += r.value[static_cast<std::size_t>(p)];
      }
      out["lobes"] = rows;
      out["total"] = total;
      out["converged"] = r.converged;
    } else if (dual->parsed()) {
      const hairlut::HairModel model = model_from_options();
      hairlut::DualScatteringOptions o;
      o.density_factor = density;
      ordered_json rows = ordered_json::array();
      for (double t : thetas) {
        const auto r = hairlut::dual_scattering(model, radians(t), o);
        ordered_json row{{"theta_i_deg", t}, {"E", r.energy_total}, {"a_f", r.a_f}, {"a_b", r.a_b}};
        for (std::size_t p = 0; p < r.energy.size(); ++p) {
          const std::string l = p < model.lobes.size() ? hairlut::lobe_name(static_cast<int>(p)) : "residual";
          row["E_" + l] = r.energy[p];
          row["a_f_" + l] = r.forward[p];
          row["a_b_" + l] = r.backward[p];
        }
        row["alpha_f_deg"] = hairlut::degrees(r.alpha_f);
        row["alpha_b_deg"] = hairlut::degrees(r.alpha_b);
        row["beta_f_deg"] = hairlut::degrees(std::sqrt(r.beta_f2));
        row["beta_b_deg"] = hairlut::degrees(std::sqrt(r.beta_b2));
        row["A_b"] = r.backscatter.A_b;
        row["delta_b_deg"] = hairlut::degrees(r.backscatter.delta_b);
        row["sigma_b_deg"] = hairlut::degrees(r.backscatter.sigma_b);
        row["sigma_b_mixed_deg"] = hairlut::degrees(r.backscatter.sigma_b_mixed);
        row["converged"] = r.converged;
        rows.push_back(row);
      }
      out["dual_scattering"] = rows;
    } else if (furnace->parsed()) {
      const hairlut::HairModel model = model_from_options();
      ordered_json rows = ordered_json::array();
      for (double t : thetas) {
        const auto r = hairlut::directional_albedo(model, radians(t));
        ordered_json row{{"theta_i_deg", t}, {"E", r.total}};
        for (std::size_t p = 0; p < r.per_lobe.size(); ++p)
          row[p < model.lobes.size() ? hairlut::lobe_name(static_cast<int>(p)) : "residual"] = r.per_lobe[p];
        row["converged"] = r.converged;
        rows.push_back(row);
      }
      out["E_theta_i"] = rows;
    } else if (marschner->parsed()) {
      const int p = hairlut::parse_lobe(lobe, "--lobe");
      hairlut::MarschnerParams mp_params;
      mp_params.eta = eta;
      mp_params.path = hairlut::parse_absorption_path(path, "--absorption-path");
      mp_params.roots = hairlut::parse_marschner_roots(roots, "--roots");
      mp_params.caustic.k_G = k_g;
      mp_params.caustic.w_c = radians(w_c);
      mp_params.eccentricity = eccentricity;
      const hairlut::MarschnerAzimuthal az(mp_params, radians(theta_d), radians(phi_h));
      out["lobe"] = hairlut::lobe_name(p);
      out["roots"] = roots;
      out["N"] = az.np(p, sigma_a, radians(phi));
      out["N_without_caustic_replacement"] = az.np_smooth(p, sigma_a, radians(phi));
      ordered_json paths = ordered_json::array();
      for (const auto& path_r : hairlut::marschner_paths(az.geometry(p), p, radians(phi), mp_params.roots))
        paths.push_back({{"gamma_i_deg", hairlut::degrees(path_r.gamma_i)}, {"h", std::sin(path_r.gamma_i)}, {"density", path_r.density}});
      out["paths"] = paths;
      out["eta_prime"] = 1.0 / az.geometry(p).inv_eta_prime;
      if (p == 2) {
        const auto& k = az.caustic();
        out["caustic_t"] = k.t;
        out["caustic_phi_c_deg"] = hairlut::degrees(k.phi_c);
        out["caustic_delta_h"] = k.delta_h;
        out["eta_star"] = az.geometry(2).eta;
      }
      double e = 0.0;
      az.energy(p, std::span<const double>(&sigma_a, 1), std::span<double>(&e, 1));
      out["lobe_energy"] = e;
    }
    print(out, as_json);
  } catch (const hairlut::DomainError& e) {
    hairlut::tools::print_error("hairlut-eval", e.what());
    return 2;
  } catch (const std::exception& e) {
    hairlut::tools::print_error("hairlut-eval", e.what());
    return 1;
  }
  return 0;
}
