// Periodic φ layouts (both ends present, −π … π, cell centres) and the per-material N_p path
// (material_np.hpp) against the adaptive reference (a different algorithm: adaptive Gauss–Kronrod
// over h with breakpoints, 1e−12), on Tungsten's layout and hairlut's, for β from 2° to 30°.
#include <cmath>
#include <hairlut/physics/azimuthal_fourier.hpp>
#include <hairlut/hairlut.hpp>
#include <hairlut/physics/material_np.hpp>
#include <hairlut/physics/melanin.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/outputs.hpp>
#include <hairlut/io/table_io.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "catch.hpp"

using namespace hairlut;

namespace {

std::vector<double> uniform(double lo, double step, int n) {
  std::vector<double> v;
  for (int j = 0; j < n; ++j) v.push_back(lo + step * j);
  return v;
}

}  // namespace

TEST_CASE("Periodic grids with both ends present are recognised", "[fourier][material]") {
  const PeriodicGrid a = PeriodicGrid::of(uniform(0.0, kTwoPi / 63, 64));  // [0, 2π], Tungsten's
  CHECK(a.period == 63);
  CHECK(a.points == 64);
  const PeriodicGrid b = PeriodicGrid::of(uniform(-kPi, kTwoPi / 63, 64));  // [−π, π]
  CHECK(b.period == 63);
  CHECK(PeriodicGrid::of(uniform(0.0, kPi / 63, 64)).period == 126);           // [0, π] edges
  CHECK(PeriodicGrid::of(uniform(kPi / 128, kPi / 64, 64)).period == 128);     // (0, π) centres
  CHECK(PeriodicGrid::of(uniform(-kPi + kPi / 64, kTwoPi / 64, 64)).period == 64);  // (−π, π) centres
  CHECK(PeriodicGrid::why_not(uniform(0.0, kTwoPi / 63, 64)).empty());
  // Not periodic, with the reason named.
  CHECK(PeriodicGrid::of(uniform(0.0, kTwoPi / 63, 65)).period == 0);  // more than one period
  CHECK(PeriodicGrid::why_not(uniform(0.0, kTwoPi / 63, 65)).find("more than one period") != std::string::npos);
  CHECK(PeriodicGrid::of(uniform(0.1, kPi / 64, 64)).period == 0);  // not symmetric about 0
  CHECK(PeriodicGrid::why_not(uniform(0.1, kPi / 64, 64)).find("symmetric") != std::string::npos);
  CHECK(PeriodicGrid::of(uniform(0.0, 0.1, 20)).period == 0);  // step does not divide 2π
  CHECK(PeriodicGrid::of(std::vector<double>{0.5}).period == 0);
  CHECK(!PeriodicGrid::why_not(std::vector<double>{0.5}).empty());
}

TEST_CASE("Spreading on a grid with both ends present repeats the first point at the last", "[fourier][material]") {
  const auto phis = uniform(-kPi, kTwoPi / 40, 41);
  const double beta = radians(3.0), tol = 1e-12;
  const FiberGeometry g = FiberGeometry::make(1.55, radians(20.0));
  const GaussLegendreRule rule(spread_nodes(beta, 2, g, tol));
  const std::vector<SpreadLobe> lobes = {{0, beta}, {1, beta}, {2, beta}};
  const double sigma[1] = {0.4};
  std::vector<std::vector<double>> out;
  spread_np(FiberNodes::make(g, AbsorptionPath::chord, rule), g, lobes, sigma, PeriodicGrid::of(phis), tol, out);
  const AttenuationSlice slice(1.55, radians(20.0), 0.4);
  for (std::size_t l = 0; l < lobes.size(); ++l) {
    CHECK(out[l][40] == out[l][0]);
    for (std::size_t j : {0u, 7u, 20u, 33u, 40u}) {
      const double ref = azimuthal_np_reference(slice, lobes[l].p, beta, phis[j], 1e-13).value[0];
      CHECK(out[l][j] == Approx(ref).epsilon(1e-10).margin(1e-13));
    }
  }
}

TEST_CASE("Per-material N_p matches the adaptive reference within 1e-10 of the lobe peak", "[fourier][material]") {
  struct Layout {
    const char* name;
    std::vector<double> thetas, phis;
  };
  std::vector<Layout> layouts(4);
  layouts[0].name = "tungsten [0, 2 pi]";
  layouts[1].name = "hairlut (0, pi) centres";
  layouts[2].name = "[-pi, pi] edges";
  layouts[3].name = "uneven (Fourier only)";
  for (int y = 0; y < 64; y += 9) {
    layouts[0].thetas.push_back(std::acos(std::max(y, 1) / 63.0));
    layouts[1].thetas.push_back(std::acos((y + 0.5) / 64.0));
  }
  layouts[2].thetas = layouts[0].thetas;
  layouts[3].thetas = {radians(10.0), radians(70.0)};
  layouts[0].phis = uniform(0.0, kTwoPi / 63, 64);
  layouts[1].phis = uniform(kPi / 128, kPi / 64, 64);
  layouts[2].phis = uniform(-kPi, kTwoPi / 63, 64);
  layouts[3].phis = {0.0, 0.3, 1.1, 2.0, 3.0};
  const double sigma[3] = {0.37, 0.64, 1.3};
  const double tol = 1e-10;
  for (const Layout& l : layouts)
    for (double bd : {2.0, 5.0, 10.0, 30.0}) {
      if (l.name[0] == 'u' && bd < 5.0) continue;  // the direct Fourier sum at 2° is slow; covered by the others
      const double beta = radians(bd);
      const MaterialNp np({1.55, AbsorptionPath::chord, {beta, beta, beta}, {sigma, sigma + 3}, l.thetas, l.phis, tol});
      CHECK(np.note().empty() == (l.name[0] != 'u'));
      const std::size_t nphi = l.phis.size();
      std::vector<double> v;
      for (int p = 0; p < 3; ++p) {
        double peak = 0.0, err = 0.0;
        for (std::size_t t = 0; t < l.thetas.size(); ++t) {
          np.evaluate(t, v);
          for (std::size_t j = 0; j < nphi; j += 3)
            for (std::size_t k = 0; k < 3; ++k) {
              const double ref = azimuthal_np_reference(AttenuationSlice(1.55, l.thetas[t], sigma[k]), p, beta, l.phis[j], 1e-12).value[0];
              peak = std::max(peak, ref);
              err = std::max(err, std::abs(v[(static_cast<std::size_t>(p) * 3 + k) * nphi + j] - ref));
            }
        }
        INFO(l.name << ", beta " << bd << " deg, p " << p << ": error / peak " << err / peak);
        CHECK(err <= 1e-10 * peak);
      }
    }
}

TEST_CASE("Newton Gauss-Legendre rules agree with the library's rules", "[material]") {
  for (int m : {1, 2, 7, 16, 140, 192, 513}) {
    std::vector<double> x, w;
    newton_gauss_legendre(m, x, w);
    const GaussLegendreRule ref(m);
    double wsum = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      CHECK(std::abs(x[i] - ref.nodes()[i]) <= 1e-15);
      // A node known to ε moves the weight 2/((1 − x²) P'²) by about ε/(1 − x²) relative.
      const double x2 = (1.0 - ref.nodes()[i]) * (1.0 + ref.nodes()[i]);
      CHECK(std::abs(w[i] - ref.weights()[i]) <= (4.0 * 2.2e-16 / x2 + 2.0 * m * 2.2e-16) * ref.weights()[i]);  // and m rounded steps of the recurrence
      wsum += w[i];
    }
    CHECK(wsum == Approx(2.0).epsilon(1e-14));
  }
}

TEST_CASE("Lobe energies of all channels at once equal lobe_energies", "[material]") {
  const GaussLegendreRule rule(128);
  const double sigmas[3] = {0.0, 0.8, 12.0};
  for (bool residual : {false, true})
    for (double td : {0.0, 40.0, 89.0}) {
      std::vector<double> e;
      const LobeSet lobes{3, residual};
      material_energies(1.55, radians(td), AbsorptionPath::chord, sigmas, lobes, rule, e);
      for (std::size_t k = 0; k < 3; ++k) {
        const auto ref = lobe_energies(AttenuationSlice(1.55, radians(td), sigmas[k]), lobes, rule);
        for (std::size_t p = 0; p < ref.size(); ++p) CHECK(e[k * ref.size() + p] == Approx(ref[p]).epsilon(1e-13).margin(1e-300));
      }
    }
}

TEST_CASE("Transplanted rules keep 1e-10 of the lobe peak at the edges of the domain", "[fourier][material]") {
  // Index close to 1 (the Fresnel floor of the node count) and large, grazing and head-on θd,
  // white and black fibers, the narrowest and a wide β, and a tighter tolerance, on hairlut's
  // (0, π) cell centres; every 4th φ against the adaptive reference.
  std::vector<double> phis;
  for (int j = 0; j < 64; ++j) phis.push_back((j + 0.5) * kPi / 64.0);
  const std::vector<double> thetas = {0.0, radians(60.0), radians(89.5)};
  const double sigma[2] = {0.0, 20.0};
  struct Case {
    double eta, beta_deg, tol;
  };
  for (const Case c : {Case{1.05, 2.0, 1e-10}, Case{1.05, 30.0, 1e-10}, Case{2.5, 2.0, 1e-10}, Case{2.5, 30.0, 1e-10}, Case{1.55, 3.0, 1e-12},
                       Case{1.55, 20.0, 1e-12}}) {
    const double beta = radians(c.beta_deg);
    const MaterialNp np({c.eta, AbsorptionPath::chord, {beta, beta, beta, beta}, {sigma, sigma + 2}, thetas, phis, c.tol});
    std::vector<double> v;
    for (std::size_t t = 0; t < thetas.size(); ++t) {
      np.evaluate(t, v);
      for (int p = 0; p < 4; ++p) {
        // Relative to the lobe's peak, floored at 1e-3 of the white fiber's (docs: "Error as a
        // renderer sees it"): a lobe absorbed below that no longer shows.
        double white_peak = 0.0;
        for (int k = 0; k < 2; ++k) {  // white first
          const AttenuationSlice slice(c.eta, thetas[t], sigma[k]);
          double peak = 0.0, err = 0.0;
          for (std::size_t j = 0; j < phis.size(); j += 4) {
            const double ref = azimuthal_np_reference(slice, p, beta, phis[j], 1e-13).value[0];
            peak = std::max(peak, ref);
            err = std::max(err, std::abs(v[(static_cast<std::size_t>(p) * 2 + static_cast<std::size_t>(k)) * phis.size() + j] - ref));
          }
          if (k == 0) white_peak = peak;
          const double denom = std::max(peak, 1e-3 * white_peak);
          INFO("eta " << c.eta << ", beta " << c.beta_deg << " deg, tol " << c.tol << ", theta_d " << thetas[t] << ", sigma_a " << sigma[k]
                      << ", p " << p << ": error / peak " << err / denom << " (" << np.nodes_at(t) << " nodes, spreads " << np.spreads(t, p) << ")");
          CHECK(err <= c.tol * denom);
        }
      }
    }
  }
}

TEST_CASE("Lobe energies from N_p's own nodes agree with lobe_energies", "[material]") {
  // The same integrand ½∫A dh on N_p's transplanted rule (evaluate's energies) against a
  // 256-point Gauss–Legendre rule: within 1e-10 relative (1e-300 absolute) for every lobe, white
  // to black, head-on to grazing, the fewest nodes (β = 30°) and an index close to 1.
  const GaussLegendreRule rule(256);
  const double sigmas[3] = {0.0, 0.8, 12.0};
  const std::vector<double> thetas = {0.0, radians(40.0), radians(89.0)};
  std::vector<double> phis;
  for (int j = 0; j < 32; ++j) phis.push_back((j + 0.5) * kPi / 32.0);
  for (double bd : {2.0, 30.0})
    for (double eta : {1.05, 1.55}) {
      const double beta = radians(bd);
      const MaterialNp np({eta, AbsorptionPath::chord, {beta, beta, beta}, {sigmas, sigmas + 3}, thetas, phis, 1e-10});
      std::vector<double> v, e;
      for (std::size_t t = 0; t < thetas.size(); ++t) {
        np.evaluate(t, v, &e);
        REQUIRE(e.size() == 9);
        for (std::size_t k = 0; k < 3; ++k) {
          const auto ref = lobe_energies(AttenuationSlice(eta, thetas[t], sigmas[k]), LobeSet{3, false}, rule);
          for (std::size_t p = 0; p < ref.size(); ++p) {
            const double got = e[k * 3 + p];
            INFO("beta " << bd << ", eta " << eta << ", theta_d " << thetas[t] << ", sigma_a " << sigmas[k] << ", lobe " << p
                         << ": relative error " << std::abs(got - ref[p]) / ref[p]);
            CHECK(got == Approx(ref[p]).epsilon(1e-10).margin(1e-300));
          }
        }
      }
    }
}

TEST_CASE("Per-material bakes are bit-identical for any thread count", "[material][bake]") {
  // Two materials of different β per lobe, a residual and both file kinds: every output byte.
  const nlohmann::json j = nlohmann::json::parse(R"({
    "name": "threads", "model": "deon2011",
    "lobes": { "explicit": ["R", "TT", "TRT"], "residual": true },
    "quadrature": { "method": "fourier", "tolerance": 1e-10 },
    "tables": { "np": { "axes": { "theta_d": { "count": 12, "range_deg": [0, 89], "spacing": "cos" }, "phi": { "count": 33, "symmetry": "even" } } } },
    "scene": { "mode": "per-material", "materials": [
      { "name": "a", "melanin": { "eumelanin": 0.4, "pheomelanin": 0.1 }, "beta_deg": { "R": 2, "TT": 3, "TRT": 25 } },
      { "name": "b", "sigma_a": [0.1, 0.5, 2.0], "beta_deg": { "R": 30, "TT": 5, "TRT": 10 } } ] },
    "output": { "basename": "threads", "formats": ["hdf5", "exr"] }
  })");
  std::vector<std::string> bytes;
  for (int threads : {1, 2, 3}) {
    const auto dir = std::filesystem::temp_directory_path() / ("hairlut-test-" + std::to_string(::getpid()) + "-material-threads" + std::to_string(threads));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const BakeConfig c = parse_config(j, "threads.json", dir);
    BakeOptions opt;
    opt.threads = threads;
    BakeReport report;
    write_outputs(bake(c, opt, &report), c, report);
    std::string all;
    for (const auto& p : {output_paths(c).hdf5, output_paths(c).exr, output_paths(c).sidecar}) {
      std::ifstream in(p, std::ios::binary);
      std::ostringstream s;
      s << in.rdbuf();
      all += s.str();
    }
    bytes.push_back(all);
    std::filesystem::remove_all(dir);
  }
  CHECK(bytes[0].size() > 10000);
  CHECK(bytes[0] == bytes[1]);
  CHECK(bytes[0] == bytes[2]);
}

TEST_CASE("Materials baked together give each material's own values, bit for bit", "[material]") {
  // One MaterialNp over five materials' RGB (channels = 3) against one per material: every N_p
  // value and energy identical, for narrow to wide β (spreading and the Fourier form both taken),
  // on a periodic grid with both ends, a periodic one without, and an even half circle.
  const std::vector<double> thetas = [] {
    std::vector<double> t;
    for (int i = 0; i < 10; ++i) t.push_back(std::acos(1.0 - i / 9.0) * 0.999);
    return t;
  }();
  std::vector<std::vector<double>> sigmas;
  for (int i = 0; i < 5; ++i) {
    const Rgb s = melanin_sigma_a_rgb(0.05 + 1.25 * i, 0.1 + 0.05 * i);
    sigmas.push_back({s.r, s.g, s.b});
  }
  sigmas[4] = {0.0, 0.0, 0.0};  // a white fiber among them
  std::vector<double> all;
  for (const auto& s : sigmas) all.insert(all.end(), s.begin(), s.end());
  const std::vector<std::vector<double>> grids = {uniform(-kPi, kTwoPi / 63.0, 64), uniform(0.0, kTwoPi / 48.0, 48), uniform(0.0, kPi / 64.0, 65)};
  std::size_t spread = 0, fourier = 0, compared = 0, different = 0;
  for (const double beta_deg : {0.7, 2.0, 5.0, 12.0, 30.0})
    for (const auto& phis : grids) {
      const double b = radians(beta_deg);
      const std::vector<double> betas = {b, 0.5 * b, 2.0 * b};
      MaterialNpRequest together{1.55, AbsorptionPath::chord, betas, all, thetas, phis, 1e-10};
      together.channels = 3;
      const MaterialNp g(together);
      for (std::size_t mi = 0; mi < sigmas.size(); ++mi) {
        const MaterialNp own({1.55, AbsorptionPath::chord, betas, sigmas[mi], thetas, phis, 1e-10});
        for (std::size_t t = 0; t < thetas.size(); ++t) {
          for (int p = 0; p < 3; ++p) {
            REQUIRE(own.spreads(t, p) == g.spreads(t, p));
            if (mi == 0) (own.spreads(t, p) ? spread : fourier) += 1;
          }
          std::vector<double> v1, e1, vg, eg;
          own.evaluate(t, v1, &e1);
          g.evaluate(t, vg, &eg);
          for (std::size_t p = 0; p < 3; ++p)
            for (std::size_t k = 0; k < 3; ++k)
              for (std::size_t j = 0; j < phis.size(); ++j, ++compared)
                different += std::memcmp(&v1[(p * 3 + k) * phis.size() + j], &vg[(p * 15 + mi * 3 + k) * phis.size() + j], sizeof(double)) != 0;
          for (std::size_t k = 0; k < 3; ++k)
            for (std::size_t p = 0; p < 3; ++p, ++compared) different += std::memcmp(&e1[k * 3 + p], &eg[(mi * 3 + k) * 3 + p], sizeof(double)) != 0;
        }
      }
    }
  INFO(compared << " values compared; (theta_d, lobe) spreading " << spread << ", Fourier " << fourier);
  CHECK(spread > 0);
  CHECK(fourier > 0);
  CHECK(different == 0);
}

TEST_CASE("A scene's materials of the same beta bake the tables each would bake alone", "[material][bake]") {
  // Three materials, two of the same β per lobe (baked together) and one of its own, against
  // each material in a scene of its own: the same float values in every table.
  auto config = [](const std::string& materials) {
    return nlohmann::json::parse(R"({
      "name": "grouped", "model": "deon2011",
      "lobes": { "explicit": ["R", "TT", "TRT"], "residual": false },
      "quadrature": { "method": "fourier", "tolerance": 1e-10 },
      "tables": { "np": { "axes": { "theta_d": { "count": 9, "range_deg": [0, 89], "spacing": "cos" }, "phi": { "count": 64, "symmetry": "full" } } } },
      "scene": { "mode": "per-material", "materials": [)" + materials + R"(] },
      "output": { "basename": "grouped", "formats": ["hdf5"] }
    })");
  };
  const std::vector<std::string> materials = {
      R"({ "name": "a", "melanin": { "eumelanin": 0.4, "pheomelanin": 0.1 }, "beta_deg": { "R": 2, "TT": 2, "TRT": 2 } })",
      R"({ "name": "b", "sigma_a": [0.1, 0.5, 2.0], "beta_deg": { "R": 6, "TT": 3, "TRT": 12 } })",
      R"({ "name": "c", "melanin": { "eumelanin": 3.0 }, "beta_deg": { "R": 2, "TT": 2, "TRT": 2 } })"};
  BakeOptions opt;
  opt.threads = 2;
  const TableSet scene = bake(parse_config(config(materials[0] + "," + materials[1] + "," + materials[2]), "grouped.json", "."), opt);
  std::size_t compared = 0;
  for (const std::string& m : materials) {
    const TableSet alone = bake(parse_config(config(m), "grouped.json", "."), opt);
    for (const Table& t : alone.tables) {
      const Table* s = nullptr;
      for (const Table& x : scene.tables)
        if (x.path() == t.path()) s = &x;
      REQUIRE(s != nullptr);
      INFO(t.path());
      REQUIRE(s->f32.size() == t.f32.size());
      CHECK(std::memcmp(s->f32.data(), t.f32.data(), t.f32.size() * sizeof(float)) == 0);
      ++compared;
    }
  }
  CHECK(compared == 3 * 6);  // N_p and energy of R, TT, TRT per material
}
