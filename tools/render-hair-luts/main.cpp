// render-hair-luts: renders a small patch of parallel hair fibers lit by a directional light and a
// uniform environment, once from baked tables as a renderer reads them (generic tables through the
// renderer runtime hair_scattering.hpp: eval for the light, importance sampling for the
// environment) and once from direct
// evaluation of the physics (d'Eon's M_p, N_p by the baker's quadrature, exact lobe energies for
// the residual), and writes both beside their difference as PNG. Thin: the physics and the table
// reading live in the library.
//
// The picture (patch.hpp, shared with the GLSL runtime's renderer): fibers run down the image,
// each shaded by its far-field scattering function, L = L_sun · S(wo = view, wi = light) +
// L_env · ∫ S(wo = view, wi) dωi, the environment's radiance scattered towards the viewer (the
// runtime holds wo, the tables' θr).
// The tables' image estimates that integral from samples drawn by the tables' sampler; the direct
// image uses the same directions with the physics' S, so sampling noise cancels in the difference
// and what remains is interpolation error.
//
// Bound: per pixel, |L_table − L_direct| ≤ L_sun B(θl, θv, φ) + L_env Σ_k B(θv, θk, φk)/pdf_k / K,
// with B = Σ_p ε (peak M̃_p/(1 − ε) · Ñ_p + (M̃_p + ε peak M̃_p/(1 − ε)) · d_p), where ε is the
// accuracy the validator enforces on these tables (validate.thresholds.accuracy_max_rel of their
// config, twice for N_p stored as shape × energy: shape and energy each carry it) and d_p the
// validator's denominator for N_p (peak over φ of the slice, floored at 1e-3 of the white fiber's),
// both estimated from the tables (their peak divided by 1 − ε bounds the exact peak).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <hairlut/physics/attenuation.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/util/error.hpp>
#include <hairlut/io/hdf5_io.hpp>
#include <hairlut/physics/lobe_energy.hpp>
#include <hairlut/physics/longitudinal_mp.hpp>
#include <hairlut/physics/melanin.hpp>
#include <hairlut/bake/np_point.hpp>
#include <hairlut/io/table_io.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/report/validate.hpp>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "bound_tables.hpp"
#include "patch.hpp"
#include "common/cli.hpp"

namespace {

namespace fs = std::filesystem;
using hairlut::sampler::AxisRow;
using hairlut::sampler::AxisSampler;
using render::Coordinate;
using render::FiberCoordinates;
constexpr double kPi = 3.14159265358979323846;

// One look: the lobes of a table group and, per channel, the fiber coordinates and physics.
struct Look {
  std::string name;
  std::string group;  // "" generic, "materials/<name>"
  FiberCoordinates fiber[3];
  double sigma_a[3];
  std::vector<double> beta_n, beta_m, alpha;  // per lobe, for the direct evaluation
};

// The physics' S of all lobes (explicit lobes by the baker's N_p quadrature, the residual as its
// exact energy spread uniformly in φ).
double direct_s(const Look& look, int channel, double eta, hairlut::AbsorptionPath path, double ti, double tr, double phi) {
  const double td = 0.5 * (tr - ti);
  const int lobes = static_cast<int>(look.alpha.size());
  double s = 0.0;
  for (int p = 0; p < lobes; ++p) {
    const double bm = look.beta_m[static_cast<std::size_t>(p)];
    const double m = hairlut::longitudinal_deon_tilted(bm * bm, look.alpha[static_cast<std::size_t>(p)], ti, tr);
    if (!(m > 1e-300)) continue;
    double n;
    if (p == lobes - 1) {
      const hairlut::AttenuationSlice slice(eta, std::fabs(td), look.sigma_a[channel], path);
      n = hairlut::lobe_energies_reference(slice, {lobes - 1, true}, 1e-10).value.back() / (2.0 * kPi);
    } else {
      n = hairlut::baker_np(eta, path, std::fabs(td), look.sigma_a[channel], p, look.beta_n[static_cast<std::size_t>(p)], phi, 1e-10).value;
    }
    s += m * n;
  }
  return s;
}

// The bound B on |S_table − S_direct| at one direction (see the top of this file).
struct Bounder {
  const render::BoundTables* h;
  std::vector<AxisSampler<float>> mp, np;
  double eps_m = 0.0, eps_n = 0.0, eps_e = 0.0;
  double operator()(const FiberCoordinates& f, double ti, double tr, double phi, AxisRow& row) const {
    double b = 0.0;
    for (std::size_t p = 0; p < h->lobes.size(); ++p) {
      const auto& l = h->lobes[p];
      double x[8];
      auto fill = [&](const render::TableRef& t, double sigma) {
        for (int d = 0; d < t.dims; ++d) {
          switch (t.coords[d]) {
            case Coordinate::beta: x[d] = f.beta; break;
            case Coordinate::sigma_a: x[d] = sigma; break;
            case Coordinate::channel: x[d] = f.channel; break;
            case Coordinate::theta_d: x[d] = 0.5 * (tr - ti); break;
            case Coordinate::theta_i: x[d] = ti; break;
            case Coordinate::theta_r: x[d] = tr; break;
            case Coordinate::phi: x[d] = phi; break;
            default: x[d] = 0.0;
          }
        }
      };
      auto peak = [&](const AxisSampler<float>& a, int cells, double lo, double hi) {
        double m = 0.0;
        for (int k = 0; k <= 4 * cells; ++k) m = std::max(m, a.value(row, lo + (hi - lo) * k / (4.0 * cells)));
        return m;
      };
      fill(l.mp, f.sigma_a);
      const hairlut::sampler::TableView<float> mv(l.mp.data, l.mp.axes, l.mp.dims);
      const double m = std::max(0.0, mv(x));
      mp[p].blend(x, row);
      const double peak_m = peak(mp[p], l.mp.axes[l.mp.dims - 1].count, -0.5 * kPi, 0.5 * kPi) / (1.0 - eps_m);
      const hairlut::sampler::TableView<float> nv(l.np.data, l.np.axes, l.np.dims);
      double factor = 1.0, white_factor = 1.0;
      if (l.factor.data) {
        const hairlut::sampler::TableView<float> fv(l.factor.data, l.factor.axes, l.factor.dims);
        fill(l.factor, f.sigma_a);
        const double td = 0.5 * (tr - ti);
        factor = std::max(0.0, fv(x)) * l.factor.grazing(f.sigma_a, td);
        fill(l.factor, 0.0);
        white_factor = std::max(0.0, fv(x)) * l.factor.grazing(0.0, td);
      }
      fill(l.np, f.sigma_a);
      // A material's N_p where its θd axis reaches 90°: stored over its grazing factor (none for
      // the generic shapes, whose energy carries it).
      const double gn = l.np.grazing(f.sigma_a, 0.5 * (tr - ti));
      const double n = std::max(0.0, nv(x)) * gn * factor;
      double d;  // the validator's denominator for this N_p, bounded from the tables
      const bool has_phi = l.np.coords[l.np.dims - 1] == Coordinate::phi;
      const double eps = l.factor.data ? eps_n + eps_e * (1.0 + eps_n) : eps_n;
      if (!has_phi) {
        d = n / (1.0 - eps_e);  // residual: relative error of the value itself
        b += eps_m * peak_m * n + (m + eps_m * peak_m) * eps_e * d;
        continue;
      }
      np[p].blend(x, row);
      const double peak_n = peak(np[p], l.np.axes[l.np.dims - 1].count, 0.0, kPi) * gn * factor;
      fill(l.np, 0.0);
      if (l.np.coords[0] == Coordinate::channel) x[0] = f.channel;  // per-material: white is not in the table
      np[p].blend(x, row);
      const double peak_white = peak(np[p], l.np.axes[l.np.dims - 1].count, 0.0, kPi) * gn * white_factor;
      d = std::max(peak_n, 1e-3 * peak_white) / (1.0 - eps);
      b += eps_m * peak_m * n + (m + eps_m * peak_m) * eps * d;
    }
    return b;
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"render-hair-luts: a patch of hair fibers from baked tables (through the sampler) beside direct evaluation"};
  std::string tables, config, out_dir = ".";
  int width = 96, height = 96, fibers = 12, env_samples = 16;
  double gain = 10.0;
  bool check = false;
  app.add_option("--tables", tables, "a table file (HDF5 or EXR) written by bake-hair-luts");
  app.add_option("--config", config, "a config to bake in memory instead (e.g. a per-material scene config)");
  app.add_option("--output-dir", out_dir, "where the PNGs and render.json go")->capture_default_str();
  app.add_option("--size", width, "panel width and height in pixels")->check(CLI::Range(8, 1024))->capture_default_str();
  app.add_option("--fibers", fibers, "fibers across the patch")->check(CLI::Range(1, 256))->capture_default_str();
  app.add_option("--env-samples", env_samples, "environment samples per shading point")->check(CLI::Range(1, 4096))->capture_default_str();
  app.add_option("--diff-gain", gain, "the difference panel shows |tables - direct| times this")->capture_default_str();
  app.add_flag("--check", check, "exit 1 when a pixel's difference exceeds its bound from the validator's accuracy");
  app.footer("Example: render-hair-luts --tables tables/default/hairlut-default.h5 --output-dir docs/images\n\n"
             "Exit status: 0 done, 1 error or (with --check) a difference above its bound, 2 bad command line or bad input\n"
             "(a missing, unreadable or malformed --tables or --config).");
  if (const auto rc = hairlut::tools::parse_command_line(app, "render-hair-luts", argc, argv)) return *rc;
  height = width;
  if (tables.empty() == config.empty()) {
    hairlut::tools::print_error("render-hair-luts", "give exactly one of --tables and --config (see --help)");
    return 2;
  }
  // A table file or config that cannot be read is bad input (exit 2, as in the other tools).
  hairlut::TableSet set;
  hairlut::BakeConfig bake_config;
  try {
    if (!tables.empty()) set = hairlut::load_tables(tables);
    else bake_config = hairlut::load_config(config);
  } catch (const std::exception& e) {
    hairlut::tools::print_error("render-hair-luts", e.what());
    return 2;
  }
  try {
    if (tables.empty()) {
      hairlut::BakeOptions opt;
      set = hairlut::bake(bake_config, opt);
    }
    const double eta = set.metadata.at("eta").get<double>();
    const hairlut::AbsorptionPath path = hairlut::parse_absorption_path(set.metadata.at("absorption_path").get<std::string>());
    hairlut::ValidationThresholds thresholds;
    const auto& cfg = set.metadata.contains("config") ? set.metadata["config"] : nlohmann::ordered_json::object();
    if (cfg.contains("validate") && cfg["validate"].contains("thresholds")) {
      const auto& t = cfg["validate"]["thresholds"];
      thresholds.accuracy_max_rel = t.value("accuracy_max_rel", thresholds.accuracy_max_rel);
      thresholds.mp_table_energy = t.value("mp_table_energy", thresholds.mp_table_energy);
    }
    const double eps = thresholds.accuracy_max_rel;

    // The looks: generic tables at three melanin settings, or every material of the set.
    std::vector<Look> looks;
    const std::vector<std::string> groups = hairlut::material_groups(set);
    if (groups.empty()) {
      const hairlut::Table* mel = set.find("melanin/sigma_a_deon");
      struct Setting {
        const char* name;
        double eu, pheo, beta_deg;
      };
      for (const Setting& st : {Setting{"blonde", 0.3, 0.15, 6.0}, Setting{"auburn", 0.9, 0.6, 8.0}, Setting{"brown", 1.6, 0.1, 10.0}}) {
        Look l{st.name, "", {}, {}, {}, {}, {}};
        for (int c = 0; c < 3; ++c) {
          // σa through the melanin table as an engine reads it (the direct image uses d'Eon's
          // linear formula, which the cubic table reproduces exactly).
          const double s = mel ? set.sample_value(*mel, {st.eu, st.pheo, static_cast<double>(c)}) : 0.0;
          const hairlut::Rgb d = hairlut::melanin_sigma_a_rgb(st.eu, st.pheo);
          l.sigma_a[c] = c == 0 ? d.r : c == 1 ? d.g : d.b;
          l.fiber[c] = FiberCoordinates{st.beta_deg * kPi / 180.0, s, 0.0};
        }
        looks.push_back(l);
      }
    } else {
      for (const std::string& g : groups) {
        Look l{g.substr(10), g, {}, {}, {}, {}, {}};
        const hairlut::Table* np0 = set.find(g + "/np_R");
        if (!np0) throw hairlut::DomainError(g + "/np_R: missing");
        const auto sig = np0->attributes.at("sigma_a").get<std::vector<double>>();
        // The material's σa rides along for its residual's grazing factor (its tables have no σa axis).
        for (int c = 0; c < 3; ++c)
          l.sigma_a[c] = sig.at(static_cast<std::size_t>(c)), l.fiber[c] = FiberCoordinates{0.0, l.sigma_a[c], static_cast<double>(c)};
        looks.push_back(l);
      }
    }

    fs::create_directories(out_dir);
    nlohmann::ordered_json summary = {{"tables", tables.empty() ? config : tables}, {"size", width}, {"fibers", fibers},
                                      {"env_samples", env_samples}, {"accuracy_max_rel", eps}, {"images", nlohmann::ordered_json::array()}};
    const render::Lighting lit;
    const double l_sun = lit.l_sun, l_env = lit.l_env;
    bool within = true;
    for (Look& look : looks) {
      const render::BoundTables h = render::bound_tables(set, look.group);
      // Per-lobe physics parameters from the tables' attributes.
      for (std::size_t p = 0; p < h.lobes.size(); ++p) {
        const std::string& lobe = h.lobe_names[p];
        const hairlut::Table* mp = set.find(look.group.empty() ? "mp/" + lobe : look.group + "/mp_" + lobe);
        const hairlut::Table* np = set.find(look.group.empty() ? "np/" + lobe : look.group + "/np_" + lobe);
        look.alpha.push_back(mp->attributes.value("alpha", 0.0));
        look.beta_m.push_back(mp->attributes.contains("beta") ? mp->attributes["beta"].get<double>() : look.fiber[0].beta);
        look.beta_n.push_back(np->attributes.contains("beta") ? np->attributes["beta"].get<double>() : look.fiber[0].beta);
      }
      Bounder bound{&h, {}, {}, eps, eps, eps};
      for (const auto& l : h.lobes) {
        bound.mp.emplace_back(l.mp.data, l.mp.axes, l.mp.dims, hairlut::sampler::Measure::plain);
        bound.np.emplace_back(l.np.data, l.np.axes, l.np.dims, hairlut::sampler::Measure::plain);
      }
      // Shade every (fiber, row): the tangent is the same across a fiber's width.
      std::vector<double> table_px(static_cast<std::size_t>(fibers * height * 3)), direct_px(table_px.size()), bound_px(table_px.size());
      // Every look through the renderer runtime (one fiber, RGB at once; the view direction held,
      // as a path tracer holds wo). A material's runtime ignores the Fiber: its σa and β are baked.
      const hairlut::sampler::HairScattering<float> runtime =
          look.group.empty() ? hairlut::hair_scattering<float>(set) : hairlut::hair_scattering<float>(set, look.group);
      if (!runtime.valid()) throw hairlut::DomainError((look.group.empty() ? std::string("tables") : look.group) + ": the runtime cannot read them");
      hairlut::sampler::Fiber rt_fiber;
      for (int c = 0; c < 3; ++c) rt_fiber.sigma_a[c] = look.sigma_a[c];
      rt_fiber.beta_m = rt_fiber.beta_n = look.fiber[0].beta;
      for (int c = 0; c < 3; ++c) {
        AxisRow row;
        std::mt19937_64 rng(12345u + static_cast<unsigned>(c));
        std::uniform_real_distribution<double> u(0.0, 1.0);
        for (int i = 0; i < fibers; ++i)
          for (int y = 0; y < height; ++y) {
            const render::PatchAngles pa = render::patch_angles(lit, i, y, height);
            const double tl = pa.theta_light, tv = pa.theta_view, phi = pa.phi;
            const FiberCoordinates& f = look.fiber[c];
            double lt = 0.0, ld = l_sun * direct_s(look, c, eta, path, tl, tv, phi);
            double lb = l_sun * bound(f, tl, tv, phi, row);
            double et = 0.0, ed = 0.0, eb = 0.0;
            // S(wo = view, wi = light), then the environment through samples of wi at wo.
            double rgb_s[3];
            runtime.eval(rt_fiber, tv, tl, phi, rgb_s);
            lt = l_sun * rgb_s[c];
            const double wo[3] = {std::sin(tv), std::cos(tv), 0.0};
            const auto point = runtime.at(rt_fiber, wo);
            for (int k = 0; k < env_samples; ++k) {
              const double uu[3] = {u(rng), u(rng), u(rng)};
              const auto s = point.sample(uu);
              if (!(s.pdf > 0.0)) continue;
              et += s.weight[c];
              ed += direct_s(look, c, eta, path, s.theta_i, tv, s.phi) / s.pdf;
              eb += bound(f, s.theta_i, tv, s.phi, row) / s.pdf;
            }
            lt += l_env * et / env_samples, ld += l_env * ed / env_samples, lb += l_env * eb / env_samples;
            const std::size_t at = static_cast<std::size_t>((i * height + y) * 3 + c);
            table_px[at] = lt, direct_px[at] = ld, bound_px[at] = lb;
          }
      }
      // Compose: tables | direct | |difference| × gain.
      double max_diff = 0.0, max_ratio = 0.0, max_value = 0.0, sum2 = 0.0;
      int count = 0;
      for (int i = 0; i < fibers; ++i)
        for (int y = 0; y < height; ++y)
          for (int c = 0; c < 3; ++c) {
            const std::size_t at = static_cast<std::size_t>((i * height + y) * 3 + c);
            const double d = std::fabs(table_px[at] - direct_px[at]);
            max_diff = std::max(max_diff, d);
            max_value = std::max(max_value, direct_px[at]);
            if (bound_px[at] > 0.0) max_ratio = std::max(max_ratio, d / bound_px[at]);
            else if (d > 0.0) max_ratio = std::max(max_ratio, 1e300);
            sum2 += d * d, ++count;
          }
      const std::string file = "render-" + look.name + ".png";
      render::write_png(fs::path(out_dir) / file, 3 * width, height, render::compose_panels(width, height, fibers, table_px, direct_px, gain));
      const double rms = std::sqrt(sum2 / std::max(1, count));
      std::printf("%s: max |tables - direct| %.3g (%.3g of the brightest pixel), rms %.3g, max difference / bound %.3g -> %s\n",
                  look.name.c_str(), max_diff, max_diff / std::max(max_value, 1e-300), rms, max_ratio, file.c_str());
      summary["images"].push_back({{"look", look.name}, {"file", file}, {"max_abs_difference", max_diff},
                                   {"max_relative_to_brightest", max_diff / std::max(max_value, 1e-300)}, {"rms_difference", rms},
                                   {"max_difference_over_bound", max_ratio}, {"brightest", max_value}});
      if (max_ratio > 1.0) within = false;
    }
    std::FILE* js = std::fopen((fs::path(out_dir) / "render.json").c_str(), "w");
    if (!js) throw hairlut::IoError(out_dir + "/render.json: cannot write");
    std::fputs((summary.dump(2) + "\n").c_str(), js);
    std::fclose(js);
    if (check && !within) {
      hairlut::tools::print_error("render-hair-luts", "a pixel differs from direct evaluation by more than its bound");
      return 1;
    }
  } catch (const hairlut::DomainError& e) {
    // Tables that lack what a look needs, or hold values out of their domain: bad input.
    hairlut::tools::print_error("render-hair-luts", e.what());
    return 2;
  } catch (const std::exception& e) {
    hairlut::tools::print_error("render-hair-luts", e.what());
    return 1;
  }
  return 0;
}
