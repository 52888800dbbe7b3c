// compare-hair-models: d'Eon 2011, Marschner 2003 (exact and cubic paths) and Kajiya–Kay for one
// fiber, side by side: N_p(φ) per lobe as polar plots, total energy per θi, where the cubic
// approximation departs from the exact roots, and the TRT caustic. Writes compare.html,
// compare.json and compare.md. Thin: the figures live in hairlut/report/compare.hpp.
#include <unistd.h>

#include "common/cli.hpp"
#include "common/progress.hpp"
#include <atomic>
#include <csignal>
#include <cstdio>
#include <hairlut/bake/bake.hpp>
#include <hairlut/report/compare.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/model_kind.hpp>
#include <hairlut/util/error.hpp>
#include <hairlut/io/hdf5_io.hpp>
#include <hairlut/physics/melanin.hpp>
#include <string>
#include <vector>

#include "../common/cancel.hpp"

namespace {

std::vector<double> to_radians(const std::vector<double>& deg) {
  std::vector<double> r;
  for (double d : deg) r.push_back(hairlut::radians(d));
  return r;
}
}  // namespace

int main(int argc, char** argv) {
  hairlut_tools::install_cancel_handlers("compare-hair-models");
  CLI::App app{"compare-hair-models: d'Eon 2011, Marschner 2003 and Kajiya-Kay for one fiber, side by side"};
  app.footer(R"(Examples:
  compare-hair-models --out compare/
  compare-hair-models --melanin 0.8,0.1 --channel R --beta-r-deg 7 --out compare-brown/
  compare-hair-models --eta 1.55 --sigma-a 0.2 --eccentricity 0.9 --phi-h-deg 30 --out compare-ecc/
  compare-hair-models --config tables/configs/marschner.json --sigma-a 0.5 --out compare/

Both models see the same fiber (eta, sigma_a per unit radius, absorption path) and the same
longitudinal widths: Marschner's Table 1 lobes from --beta-r-deg and --alpha-r-deg; d'Eon's lobes
use those widths as longitudinal and azimuthal roughness and the tilts 2 alpha_p. --config takes
eta, the absorption path and the marschner settings from a marschner2003 config. Writes
compare.html (open it in a browser), compare.json and compare.md into --out. Exit status: 0 done,
1 I/O failure, 2 bad input or command line (one line "compare-hair-models: error: ..."),
130 interrupted.)");
  double eta = 1.55, sigma_a = 0.5, beta_r_deg = 5.0, alpha_r_deg = -5.0, k_g = 0.5, w_c_deg = 15.0, eccentricity = 1.0, phi_h_deg = 0.0;
  double kd = 0.0, ks = 0.0, exponent = 0.0;
  std::vector<double> melanin, theta_d_deg = {0, 20, 40, 60};
  std::string channel = "G", config_path, out_dir = "hairlut-compare", path = "chord", argument = "theta-h";
  bool quiet = false, no_energy = false;
  int phi_samples = 361;
  auto* eta_opt = app.add_option("--eta", eta, "index of refraction")->capture_default_str();
  auto* sigma_opt = app.add_option("--sigma-a", sigma_a, "absorption per unit fiber radius")->capture_default_str();
  app.add_option("--melanin", melanin, "eumelanin[,pheomelanin] concentrations (d'Eon's RGB cross-sections) instead of --sigma-a")->delimiter(',')->excludes(sigma_opt);
  app.add_option("--channel", channel, "colour channel of --melanin: R, G or B")->capture_default_str();
  app.add_option("--beta-r-deg", beta_r_deg, "Marschner's beta_R (TT: beta_R/2, TRT: 2 beta_R)")->capture_default_str();
  app.add_option("--alpha-r-deg", alpha_r_deg, "Marschner's alpha_R, a shift of theta_h")->capture_default_str();
  app.add_option("--argument", argument, "Gaussian M_p argument: theta-h or 2theta-h")->capture_default_str();
  app.add_option("--k-g", k_g, "glint scale factor k_G")->capture_default_str();
  app.add_option("--w-c-deg", w_c_deg, "caustic width w_c in degrees")->capture_default_str();
  app.add_option("--eccentricity", eccentricity, "eccentricity a of the cross-section")->capture_default_str();
  app.add_option("--phi-h-deg", phi_h_deg, "azimuthal half angle for an eccentric fiber")->capture_default_str();
  app.add_option("--absorption-path", path, "chord or papers")->capture_default_str();
  app.add_option("--theta-d-deg", theta_d_deg, "theta_d of the polar plots (comma separated)")->delimiter(',')->capture_default_str();
  app.add_option("--kd", kd, "Kajiya-Kay diffuse K_d (with --ks; default: specular only, E(0) = 1)");
  app.add_option("--ks", ks, "Kajiya-Kay specular k_s");
  app.add_option("--exponent", exponent, "Kajiya-Kay exponent (default 1/(4 beta_R^2))");
  app.add_option("--phi-samples", phi_samples, "phi samples in [0, pi]")->capture_default_str();
  app.add_option("--config", config_path, "take eta, the absorption path and the marschner settings from this marschner2003 config")->excludes(eta_opt);
  app.add_flag("--no-energy", no_energy, "skip the energy-per-theta_i curves (the slow part)");
  app.add_option("--out", out_dir, "output directory")->capture_default_str();
  app.add_flag("--quiet,-q", quiet, "print nothing but errors");
  if (const auto rc = hairlut::tools::parse_command_line(app, "compare-hair-models", argc, argv)) return *rc;

  hairlut::CompareSettings s;
  try {
    if (!config_path.empty()) {
      const hairlut::BakeConfig c = hairlut::load_config(config_path);
      if (c.model != "marschner2003") throw hairlut::DomainError("--config " + config_path + ": model must be marschner2003 (got " + c.model + ")");
      s.eta = c.eta;
      s.path = c.path;
      s.marschner = hairlut::marschner_from_json(c.model_settings->json(), c.eta, c.path);
    } else {
      s.path = hairlut::parse_absorption_path(path, "--absorption-path");
      s.marschner.params.caustic.k_G = k_g;
      s.marschner.params.caustic.w_c = hairlut::radians(w_c_deg);
      s.marschner.params.eccentricity = eccentricity;
      s.marschner.alpha_r = hairlut::radians(alpha_r_deg);
      if (argument != "theta-h" && argument != "2theta-h") throw hairlut::DomainError("--argument must be theta-h or 2theta-h (got \"" + argument + "\")");
      s.marschner.argument = argument == "theta-h" ? hairlut::GaussianArgument::theta_h : hairlut::GaussianArgument::two_theta_h;
      s.eta = eta;
    }
    s.sigma_a = sigma_a;
    if (!melanin.empty()) {
      if (melanin.size() > 2) throw hairlut::DomainError("--melanin takes eumelanin[,pheomelanin] (got " + std::to_string(melanin.size()) + " values)");
      const hairlut::Rgb rgb = hairlut::melanin_sigma_a_rgb(melanin[0], melanin.size() > 1 ? melanin[1] : 0.0);
      if (channel != "R" && channel != "G" && channel != "B") throw hairlut::DomainError("--channel must be R, G or B (got \"" + channel + "\")");
      s.sigma_a = channel == "R" ? rgb.r : channel == "G" ? rgb.g : rgb.b;
      char buf[128];
      std::snprintf(buf, sizeof buf, "melanin %g, %g, channel %s", melanin[0], melanin.size() > 1 ? melanin[1] : 0.0, channel.c_str());
      s.fiber = buf;
    }
    s.beta_r = hairlut::radians(beta_r_deg);
    s.phi_h = hairlut::radians(phi_h_deg);
    s.theta_d = to_radians(theta_d_deg);
    s.kajiya_kay = {kd, ks, exponent};
    s.phi_samples = phi_samples;
    s.energies = !no_energy;
    s.cancel = hairlut_tools::cancel_pointer();
    hairlut_tools::register_temp_dir(out_dir);
    s.validate();
  } catch (const hairlut::ConfigError& e) {
    std::fprintf(stderr, "compare-hair-models: error: %s\n", e.what());
    return 2;
  } catch (const hairlut::DomainError& e) {
    std::fprintf(stderr, "compare-hair-models: error: %s\n", e.what());
    return 2;
  }
  // Before the work: an output directory that cannot be written would otherwise fail at the end.
  if (const auto why = hairlut::tools::unwritable_directory(out_dir)) {
    hairlut::tools::print_error("compare-hair-models", "--out " + *why);
    return 1;
  }
  hairlut::tools::Progress progress(!quiet && ::isatty(STDERR_FILENO));
  s.progress = [&progress](std::string_view stage, std::size_t done, std::size_t total) { progress.update(stage, done, total); };
  try {
    const auto compare = hairlut::compare_models(s);
    progress.stage("writing", out_dir + "/compare.html, .json, .md");
    hairlut::write_compare(compare, out_dir);
    progress.finish();
    if (!quiet) {
      std::printf("%s", hairlut::render_compare_markdown(compare).c_str());
      std::printf("\nwrote %s/compare.html, compare.json, compare.md\n", out_dir.c_str());
    }
    return 0;
  } catch (const hairlut::BakeCancelled&) {
    std::fprintf(stderr, "\ncompare-hair-models: interrupted; nothing written\n");
    return hairlut_tools::cancel_exit_code();
  } catch (const hairlut::DomainError& e) {
    std::fprintf(stderr, "compare-hair-models: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "compare-hair-models: error: %s\n", e.what());
    return 1;
  }
}
