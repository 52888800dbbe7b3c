// The renderer runtime on a set whose N_p is stored as a Fourier series (HairScattering over
// np_fourier/<lobe> and mp/<lobe>), tested as pbrt-v4 and Mitsuba 3 test their hair BSDFs, with their
// counts and tolerances (peer_hair_tests.hpp names the files and commits and maps their roughness).
//
// The set: the generic domain of tables/configs/generic-1e-3.json (β 2°–45°, σa 0–10, θd 0–89°,
// truncation tolerance 1e-3) on fewer (θd, σa) nodes, with M_p tables on the shipped default's
// axes beside it, untilted. Its eval
// is held against M_p read by TableView times N_p summed by the library's own plain evaluation of the
// series (FourierNpReference), an implementation independent of the runtime's.
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/tables/fourier_tables.hpp>
#include <hairlut/tables/hair_views.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "catch.hpp"
#include "peer_hair_tests.hpp"

using namespace hairlut;
using Runtime = sampler::HairScattering<float>;
using peer::average;
using peer::Rng;
using peer::uniform_sphere;

namespace {

constexpr double kPiF = peer::kPi;
constexpr double kBetaLo = 2.0 * kPiF / 180.0, kBetaHi = 45.0 * kPiF / 180.0;

const TableSet& fourier_tables() {
  static const TableSet set = [] {
    const nlohmann::json j = nlohmann::json::parse(R"({
      "name": "fourier-runtime", "model": "deon2011",
      "lobes": { "explicit": ["R", "TT", "TRT", "TRRT"], "residual": true },
      "tables": {
        "np": { "representation": "fourier",
          "axes": { "beta": { "range_deg": [2, 45] },
            "sigma_a": { "count": 24, "range": [0, 10], "spacing": "sqrt", "interpolation": "linear" },
            "theta_d": { "count": 128, "range_deg": [0, 89], "spacing": "cos", "interpolation": "cubic" } },
          "fourier": { "tolerance": 1e-3 } },
        "mp": { "axes": {
          "theta_i": { "count": 109, "range_deg": [-90, 90], "interpolation": "cubic" },
          "theta_r": { "count": 161, "range_deg": [-90, 90], "interpolation": "cubic" },
          "beta": { "count": 12, "range_deg": [2, 45], "spacing": "log", "interpolation": "cubic" } } } },
      "output": { "basename": "fourier-runtime", "formats": ["hdf5"], "directory": "." } })");
    BakeOptions options;
    options.threads = 2;
    return bake(parse_config(j, "fourier-runtime.json", "."), options);
  }();
  return set;
}
const Runtime& runtime() {
  static const Runtime r = hair_scattering<float>(fourier_tables());
  return r;
}
// A grey fiber with pbrt-style roughness, clamped to the set's β ranges.
sampler::Fiber fiber(double pbrt_m, double pbrt_n, double sigma_a) { return peer::grey_fiber(pbrt_m, pbrt_n, sigma_a, kBetaLo, kBetaHi); }

}  // namespace

TEST_CASE("Fourier HairScattering: eval is M_p from its tables times the series, as the Fourier views and the library's own sum give it", "[scattering][fourier]") {
  // Against the per-lobe views (fourier_np(), held against the library's sum in
  // test_fourier_representation) to rounding; against the library's plain sum of N(β) terms within
  // the truncation bound, tolerance × c_0 F / 2π per lobe (the views sum whole groups of four terms).
  const TableSet& set = fourier_tables();
  const Runtime& rt = runtime();
  REQUIRE(rt.valid());
  REQUIRE(!rt.material());
  std::vector<std::string> lobes;
  for (const auto& l : set.metadata.at("lobes")) lobes.push_back(l.get<std::string>());
  lobes.push_back("residual");
  std::vector<sampler::TableView<float>> mp;
  std::vector<sampler::FourierNp<float, double>> view;
  std::vector<FourierNpReference> ref;
  std::vector<std::vector<sampler::Axis>> axes(lobes.size());
  for (std::size_t p = 0; p < lobes.size(); ++p) {
    const Table* m = set.find("mp/" + lobes[p]);
    const Table* n = set.find(std::string(kFourierGroup) + "/" + lobes[p]);
    REQUIRE(m);
    REQUIRE(n);
    for (const auto& a : m->axes) axes[p].push_back(a.view());
    mp.emplace_back(m->f32.data(), axes[p].data(), 3);
    view.push_back(fourier_np<float, double>(set, lobes[p]));
    ref.emplace_back(*n);
  }
  const double tolerance = ref[0].info().params.tolerance;
  Rng rng(3);
  double worst_view = 0.0, worst_ref = 0.0;
  for (int i = 0; i < 3000; ++i) {
    sampler::Fiber f = fiber(0.1 + 0.8 * rng(), 0.1 + 0.8 * rng(), 0.0);
    for (double& s : f.sigma_a) s = 6.0 * rng() * rng();
    const double to = (2.0 * rng() - 1.0) * 0.5 * kPiF, ti = (2.0 * rng() - 1.0) * 0.5 * kPiF, phi = (2.0 * rng() - 1.0) * kPiF;
    const double td = 0.5 * (to - ti);
    double got[3], by_view[3] = {0.0, 0.0, 0.0}, by_ref[3] = {0.0, 0.0, 0.0}, bound[3] = {0.0, 0.0, 0.0};
    rt.eval(f, to, ti, phi, got);
    for (std::size_t p = 0; p < lobes.size(); ++p) {
      const double x[3] = {f.beta_m, ti, to};
      const double m = std::max(0.0, mp[p](x));
      for (int c = 0; c < 3; ++c) {
        by_view[c] += m * view[p](f.beta_n, f.sigma_a[c], td, phi);
        by_ref[c] += m * ref[p](f.beta_n, f.sigma_a[c], td, phi);
        bound[c] += m * tolerance * std::fabs(ref[p].energy(f.sigma_a[c], td)) / (2.0 * kPiF);
      }
    }
    for (int c = 0; c < 3; ++c) {
      worst_view = std::max(worst_view, std::fabs(got[c] - by_view[c]) / std::max(1e-300, std::fabs(by_view[c])));
      if (bound[c] > 0.0) worst_ref = std::max(worst_ref, std::fabs(got[c] - by_ref[c]) / bound[c]);
      else CHECK(got[c] == by_ref[c]);
    }
  }
  INFO("worst relative difference from the views " << worst_view << ", worst difference from the plain sum over its bound " << worst_ref);
  CHECK(worst_view < 1e-12);
  CHECK(worst_ref <= 1.0);
}

TEST_CASE("Fourier HairScattering: pbrt-v4 Hair.WhiteFurnace and Hair.WhiteFurnaceSampled", "[scattering][fourier]") {
  const Runtime& rt = runtime();
  Rng rng(7);
  double wo[3];
  uniform_sphere(rng(), rng(), wo);
  for (double bm = 0.1; bm < 1.0; bm += 0.2)
    for (double bn = 0.1; bn < 1.0; bn += 0.2) {
      const sampler::Fiber f = fiber(bm, bn, 0.0);
      const auto [uniform, sampled] = peer::white_furnaces(rt, f, wo, rng, (bm < 0.5 || bn < 0.5) ? 100000 : 20000);
      INFO("beta_m " << f.beta_m << " beta_n " << f.beta_n << ": uniform " << uniform << ", sampled " << sampled);
      CHECK(uniform >= 0.95);
      CHECK(uniform <= 1.05);
      CHECK(sampled >= 0.99);
      CHECK(sampled <= 1.01);
    }
}

TEST_CASE("Fourier HairScattering: pbrt-v4 Hair.SamplingWeights, every sample's weight of a white fiber", "[scattering][fourier]") {
  const Runtime& rt = runtime();
  Rng rng(13);
  peer::WeightSpread r;
  for (double bm = 0.1; bm < 1.0; bm += 0.2)
    for (double bn = 0.4; bn < 1.0; bn += 0.2) peer::sampling_weights(rt, fiber(bm, bn, 0.0), rng, 10000, false, r);
  INFO(r.total << " samples, weights in [" << r.lo << ", " << r.hi << "]");
  CHECK(r.total == 150000);
  CHECK(r.outside == 0);
}

TEST_CASE("Fourier HairScattering: pbrt-v4 Hair.SamplingConsistency, importance and uniform estimates agree", "[scattering][fourier]") {
  const Runtime& rt = runtime();
  Rng rng(17);
  for (double bm = 0.2; bm < 1.0; bm += 0.2)
    for (double bn = 0.4; bn < 1.0; bn += 0.2) {
      const sampler::Fiber f = fiber(bm, bn, 0.25);
      double wo[3];
      uniform_sphere(rng(), rng(), wo);
      const auto [importance, uniform] = peer::sampling_consistency(rt, f, wo, rng, 64 * 1024);
      INFO("beta_m " << f.beta_m << " beta_n " << f.beta_n << ": importance " << importance << " uniform " << uniform);
      CHECK(std::fabs(importance - uniform) / uniform < 0.05);
    }
}

TEST_CASE("Fourier HairScattering: pbrt-v4 Hair.HOnTheEdge and the frame's edges give finite values", "[scattering][fourier]") {
  const peer::EdgeChecks r = peer::h_on_the_edge(runtime(), fiber(0.1, 0.1, 0.0));
  INFO(r.failures << " failed, the first: " << r.first);
  CHECK(r.failures == 0);
}

TEST_CASE("Fourier HairScattering: Mitsuba 3 test04_sample_numeric, every lane's luminance weight within 1e-3", "[scattering][fourier]") {
  const Runtime& rt = runtime();
  Rng rng(0);
  peer::LaneWeights w;
  for (int a = 0; a < 5; ++a)
    for (int b = 0; b < 5; ++b) peer::sample_numeric(rt, fiber(0.1 + 0.89 * a / 4.0, 0.1 + 0.89 * b / 4.0, 0.0), rng, 100000, w);
  INFO(w.lanes << " lanes, worst |w - 1| " << w.worst);
  CHECK(w.bad == 0);
}

TEST_CASE("Fourier HairScattering: pdf() is sample()'s density and integrates to one", "[scattering][fourier]") {
  const Runtime& rt = runtime();
  Rng rng(23);
  for (int i = 0; i < 2000; ++i) {
    const sampler::Fiber f = fiber(0.1 + 0.8 * rng(), 0.1 + 0.8 * rng(), 4.0 * rng());
    double wo[3];
    uniform_sphere(rng(), rng(), wo);
    double u[3] = {rng(), rng(), rng()};
    if (i % 7 == 0) u[i % 3] = 0.0;
    const sampler::ScatteringSample s = rt.sample(f, wo, u);
    REQUIRE(s.pdf > 0.0);
    // pdf() reads wi back as angles (asin, atan2); 1e-7 leaves room for that round trip.
    CHECK(rt.pdf(f, wo, s.wi) == Approx(s.pdf).epsilon(1e-7));
    double rgb[3];
    rt.eval(f, wo, s.wi, rgb);
    for (int c = 0; c < 3; ++c) CHECK(s.weight[c] == Approx(rgb[c] / s.pdf).epsilon(1e-6));
  }
  // ∫ pdf dω by the midpoint rule in (θi, φi) on cells of 1/8° × 1/2°.
  for (const auto& [bm, to] : {std::pair{0.1, 1.5}, std::pair{0.5, -1.2}, std::pair{0.3, 0.2}}) {
    const sampler::Fiber f = fiber(bm, 0.15, 0.5);
    const double wo[3] = {std::sin(to), std::cos(to), 0.0};
    const Runtime::ShadingPoint sp = rt.at(f, wo);
    const int nt = 1440, np = 720;
    double s = 0.0;
    for (int a = 0; a < nt; ++a)
      for (int b = 0; b < np; ++b) {
        const double ti = -0.5 * kPiF + (a + 0.5) * kPiF / nt, ph = -kPiF + 2.0 * kPiF * (b + 0.5) / np;
        s += sp.pdf(ti, ph) * std::cos(ti);
      }
    s *= (kPiF / nt) * (2.0 * kPiF / np);
    INFO("beta_m " << f.beta_m << " beta_n " << f.beta_n << " theta_o " << to << ": integral " << s);
    CHECK(s == Approx(1.0).epsilon(2e-3));
  }
}

TEST_CASE("Fourier HairScattering: Mitsuba 3 test06_chi2, samples distributed as pdf() says", "[scattering][fourier]") {
  // As test_hair_scattering.cpp runs it (301 × 150 bins, 10⁶ samples, σa 0.8, wo at Mitsuba's θ 0
  // and 0.99 π/4, φ π/2), on the longitudinal roughness ends 0.2 and 1 and azimuthal 0.2 and 0.6;
  // significance 0.01 with the Šidák correction over the 8 configurations.
  const Runtime& rt = runtime();
  std::vector<std::array<double, 3>> configs;
  for (double bm : {0.2, 1.0})
    for (double bn : {0.2, 0.6})
      for (double th : {0.0, 0.99 * kPiF / 4.0}) configs.push_back({bm, bn, th});
  const double alpha = 1.0 - std::pow(1.0 - 0.01, 1.0 / static_cast<double>(configs.size()));
  std::vector<peer::Chi2> results(configs.size());
  auto run = [&](std::size_t ci) {
    const auto& c = configs[ci];
    const double wo[3] = {0.0, std::sin(c[2]), std::cos(c[2])};
    results[ci] = peer::chi2_sphere<float>(rt.at(fiber(c[0], c[1], 0.8), wo), 60 + ci, 301, 150, 1000000);
  };
  std::thread second([&] {
    for (std::size_t ci = 1; ci < configs.size(); ci += 2) run(ci);
  });
  for (std::size_t ci = 0; ci < configs.size(); ci += 2) run(ci);
  second.join();
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
    const peer::Chi2& r = results[ci];
    INFO("long " << configs[ci][0] << " azimuthal " << configs[ci][1] << " theta " << configs[ci][2] << ": chi2 " << r.chi2 << " with " << r.dof - 1
                 << " dof, p " << r.p << " (alpha " << alpha << ")");
    REQUIRE(r.valid);
    CHECK(r.p > alpha);
  }
}

TEST_CASE("Fourier HairScattering: a Fourier set without M_p tables is refused, naming the table", "[scattering][fourier][hostile]") {
  TableSet set = fourier_tables();
  set.tables.erase(std::remove_if(set.tables.begin(), set.tables.end(), [](const Table& t) { return t.path() == "mp/TT"; }), set.tables.end());
  CHECK_THROWS_WITH(hair_scattering<float>(set), Catch::Contains("mp/TT"));
}

TEST_CASE("Fourier HairScattering prepared per roughness: S within 1e-2 of the peak at wo, and pbrt-v4 Hair.SamplingWeights", "[scattering][fourier][prepared]") {
  // The set prepared for each roughness of pbrt's SamplingWeights loop (prepared_scattering.hpp):
  // every white fiber's weight within (0.99, 1.01), 10⁴ samples per pair; and its S against the
  // Fourier runtime's at the directions it draws, within 1e-2 of the largest S drawn at the same
  // wo (the tables' accuracy threshold), for a white and a coloured fiber.
  const Runtime& rt = runtime();
  Rng rng(41);
  peer::WeightSpread r;
  double worst = 0.0;
  for (double bm = 0.1; bm < 1.0; bm += 0.2)
    for (double bn = 0.4; bn < 1.0; bn += 0.2) {
      const sampler::Fiber f = fiber(bm, bn, 0.0);
      const Runtime prep(rt, f);
      REQUIRE(prep.valid());
      peer::sampling_weights(prep, prep.fiber(f), rng, 10000, false, r);
      for (const double sa : {0.0, 1.5}) {
        sampler::Fiber g = f;
        g.sigma_a[1] = sa, g.sigma_a[2] = 2.0 * sa;
        const double e = peer::prepared_error_over_peak(rt, prep, g, rng, 100, 8);
        REQUIRE(e >= 0.0);
        worst = std::max(worst, e);
      }
    }
  INFO(r.total << " samples, weights in [" << r.lo << ", " << r.hi << "]; S's worst error over the peak at wo " << worst);
  CHECK(r.total == 150000);
  CHECK(r.outside == 0);
  CHECK(worst <= 1e-2);
}
