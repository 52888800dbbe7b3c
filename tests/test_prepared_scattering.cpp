// The renderer runtime prepared for one roughness (HairScattering(source, roughness);
// prepared_scattering.hpp): its S against the runtime it was prepared from, its pdf against its
// samples and the sphere, and pbrt-v4's and Mitsuba 3's hair tests with their counts and
// tolerances (peer_hair_tests.hpp names the files and commits and maps the peers' roughness), each
// (β_m, β_n) of a peer's loop prepared on its own, as a renderer prepares a material.
//
// The sources: the shipped (tilted) default tables, and the same config baked without tilts
// (HAIRLUT_TEST_UNTILTED under ctest) where the peers test energy.
#include <hairlut/tables/hair_views.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "catch.hpp"
#include "default_tables.hpp"
#include "peer_hair_tests.hpp"

using namespace hairlut;
using Runtime = sampler::HairScattering<float>;
using peer::average;
using peer::Rng;
using peer::uniform_sphere;

namespace {

constexpr double kPiP = peer::kPi;

const Runtime& source(bool tilted) {
  if (tilted) {
    static const Runtime t = hair_scattering<float>(test_tables::tilted_default());
    return t;
  }
  static const Runtime u = hair_scattering<float>(test_tables::untilted_default());
  return u;
}

// A grey fiber with the peers' roughness, clamped to the default tables' β range [4°, 45°].
sampler::Fiber fiber(double pbrt_m, double pbrt_n, double sigma_a) {
  return peer::grey_fiber(pbrt_m, pbrt_n, sigma_a, 4.0 * kPiP / 180.0, 45.0 * kPiP / 180.0);
}

}  // namespace

TEST_CASE("PreparedScattering: S is the source's at the directions it draws, within the tables' 1e-2 of the peak at wo", "[scattering][prepared]") {
  // The default tables' own accuracy thresholds are 1e-2 of the local peak (tables/configs/default.json):
  // what a renderer relies on. Roughness at the β axis's ends and between; white and coloured
  // fibers, σa beyond the tables' range (read as its end, as the tables read it) and 0.
  const Runtime& src = source(true);
  Rng rng(5);
  // The last roughness adds a fiber tilt of 2° (pbrt's scale angle) to the tables' own tilts.
  for (const auto& [bm, bn, tilt] : std::vector<std::array<double, 3>>{{4.0, 4.0, 0.0}, {10.0, 12.0, 0.0}, {16.7, 12.2, 0.0}, {45.0, 45.0, 0.0},
                                                                      {6.0, 30.0, 0.0}, {10.0, 12.0, 2.0}}) {
    sampler::Fiber rough;
    rough.beta_m = bm * kPiP / 180.0, rough.beta_n = bn * kPiP / 180.0, rough.tilt = tilt * kPiP / 180.0;
    const Runtime prep(src, rough);
    REQUIRE(prep.valid());
    REQUIRE(prep.prepared());
    for (const std::array<double, 3>& sa : {std::array<double, 3>{0.0, 0.0, 0.0}, std::array<double, 3>{0.42, 0.67, 1.4},
                                            std::array<double, 3>{0.05, 3.0, 9.0}, std::array<double, 3>{16.0, 20.0, 1e3}}) {
      sampler::Fiber f = rough;
      for (int c = 0; c < 3; ++c) f.sigma_a[c] = sa[static_cast<std::size_t>(c)];
      const double worst = peer::prepared_error_over_peak(src, prep, f, rng, 300, 16);
      INFO("beta_m " << bm << " beta_n " << bn << " tilt " << tilt << " sigma_a " << sa[0] << ", " << sa[1] << ", " << sa[2] << ": worst " << worst);
      CHECK(worst >= 0.0);
      CHECK(worst <= 1e-2);
    }
  }
}

TEST_CASE("PreparedScattering: pdf() is sample()'s density and the weights are S over it, u = 0 and 1 included", "[scattering][prepared]") {
  const Runtime& src = source(true);
  sampler::Fiber f;
  f.beta_m = 8.0 * kPiP / 180.0, f.beta_n = 10.0 * kPiP / 180.0, f.sigma_a[0] = 0.3, f.sigma_a[1] = 0.9, f.sigma_a[2] = 2.5;
  const Runtime prep(src, f);
  const sampler::PreparedFiber pf = prep.fiber(f);
  Rng rng(11);
  for (int i = 0; i < 20000; ++i) {
    double wo[3];
    uniform_sphere(rng(), rng(), wo);
    double u[3] = {rng(), rng(), rng()};
    if (i % 7 == 0) u[i % 3] = 0.0;
    if (i % 11 == 0) u[(i + 1) % 3] = 1.0;
    const Runtime::ShadingPoint sp = prep.at(pf, wo);
    const sampler::ScatteringSample s = sp.sample(u);
    REQUIRE(s.pdf > 0.0);
    // pdf() reads wi back as angles (asin, atan2), and the shapes are summed in float: a change of
    // 1e-16 in φ may move those sums by a float rounding (6e-8) each; 1e-6 leaves room for a few.
    // A density that differs from sample()'s is off by percents.
    CHECK(sp.pdf(s.wi) == Approx(s.pdf).epsilon(1e-6));
    double rgb[3];
    sp.eval(s.wi, rgb);
    for (int c = 0; c < 3; ++c) CHECK(s.weight[c] == Approx(rgb[c] / s.pdf).epsilon(1e-6));
  }
}

TEST_CASE("PreparedScattering: pdf integrates to one and albedo() is the integral of S", "[scattering][prepared]") {
  // Midpoint rule in (θi, φ) on 1/16° × 1/8° cells; a white and a coloured fiber, θo up to 0.05°
  // from the poles. A coloured fiber's albedo() is its fitted row groups' normalisation: held to
  // the same 2e-3, which the √σa-linear group weights it replaced missed by 20%.
  const Runtime& src = source(true);
  sampler::Fiber rough;
  rough.beta_m = 10.0 * kPiP / 180.0, rough.beta_n = 12.0 * kPiP / 180.0;
  const Runtime prep(src, rough);
  for (const double grey : {0.0, 0.8}) {
    sampler::Fiber f = rough;
    f.sigma_a[0] = grey, f.sigma_a[1] = 2.0 * grey, f.sigma_a[2] = 4.0 * grey;
    const sampler::PreparedFiber pf = prep.fiber(f);
    for (double deg : {-89.95, -40.0, 0.0, 63.0, 89.95}) {
      const double to = deg * kPiP / 180.0, wo[3] = {std::sin(to), std::cos(to), 0.0};
      const Runtime::ShadingPoint sp = prep.at(pf, wo);
      REQUIRE(sp.valid());
      const int nt = 2880, np = 1440;
      double p = 0.0, s = 0.0;
      for (int a = 0; a < nt; ++a)
        for (int b = 0; b < np; ++b) {
          const double ti = -0.5 * kPiP + (a + 0.5) * kPiP / nt, ph = -kPiP + 2.0 * kPiP * (b + 0.5) / np;
          const double wi[3] = {std::sin(ti), std::cos(ti) * std::cos(ph), std::cos(ti) * std::sin(ph)};
          double rgb[3];
          sp.eval(wi, rgb);
          p += sp.pdf(wi) * std::cos(ti);
          s += average(rgb) * std::cos(ti);
        }
      p *= (kPiP / nt) * (2.0 * kPiP / np), s *= (kPiP / nt) * (2.0 * kPiP / np);
      INFO("sigma_a " << grey << " theta_o " << deg << ": integral of pdf " << p << ", of S " << s << ", albedo() " << sp.albedo());
      CHECK(p == Approx(1.0).epsilon(1e-3));
      CHECK(sp.albedo() == Approx(s).epsilon(2e-3));
    }
  }
}

TEST_CASE("PreparedScattering: pbrt-v4 Hair.WhiteFurnace and Hair.WhiteFurnaceSampled", "[scattering][prepared]") {
  const Runtime& src = source(false);
  Rng rng(7);
  double wo[3];
  uniform_sphere(rng(), rng(), wo);
  for (double bm = 0.1; bm < 1.0; bm += 0.2)
    for (double bn = 0.1; bn < 1.0; bn += 0.2) {
      const sampler::Fiber f = fiber(bm, bn, 0.0);
      const Runtime prep(src, f);
      const auto [uniform, sampled] = peer::white_furnaces(prep, prep.fiber(f), wo, rng, (bm < 0.5 || bn < 0.5) ? 100000 : 20000);
      INFO("pbrt beta_m " << bm << " beta_n " << bn << ": uniform " << uniform << ", sampled " << sampled);
      CHECK(uniform >= 0.95);
      CHECK(uniform <= 1.05);
      CHECK(sampled >= 0.99);
      CHECK(sampled <= 1.01);
    }
}

TEST_CASE("PreparedScattering: pbrt-v4 Hair.SamplingWeights, every sample's weight of a white fiber", "[scattering][prepared]") {
  const Runtime& src = source(false);
  Rng rng(13);
  peer::WeightSpread r;
  for (double bm = 0.1; bm < 1.0; bm += 0.2)
    for (double bn = 0.4; bn < 1.0; bn += 0.2) {
      const sampler::Fiber f = fiber(bm, bn, 0.0);
      const Runtime prep(src, f);
      peer::sampling_weights(prep, prep.fiber(f), rng, 10000, false, r);
    }
  INFO(r.total << " samples, weights in [" << r.lo << ", " << r.hi << "]");
  CHECK(r.total == 150000);
  CHECK(r.outside == 0);
}

TEST_CASE("PreparedScattering: pbrt-v4 Hair.SamplingConsistency and Hair.HOnTheEdge", "[scattering][prepared]") {
  const Runtime& src = source(false);
  Rng rng(17);
  for (double bm = 0.2; bm < 1.0; bm += 0.2)
    for (double bn = 0.4; bn < 1.0; bn += 0.2) {
      const sampler::Fiber f = fiber(bm, bn, 0.25);
      const Runtime prep(src, f);
      double wo[3];
      uniform_sphere(rng(), rng(), wo);
      const auto [importance, uniform] = peer::sampling_consistency(prep, prep.fiber(f), wo, rng, 64 * 1024);
      INFO("pbrt beta_m " << bm << " beta_n " << bn << ": importance " << importance << " uniform " << uniform);
      CHECK(std::fabs(importance - uniform) / uniform < 0.05);
    }
  const sampler::Fiber f = fiber(0.1, 0.1, 0.0);
  const Runtime prep(src, f);
  const peer::EdgeChecks r = peer::h_on_the_edge(prep, prep.fiber(f));
  INFO(r.failures << " failed, the first: " << r.first);
  CHECK(r.failures == 0);
}

TEST_CASE("PreparedScattering: Mitsuba 3 test04_sample_numeric, every lane's luminance weight within 1e-3", "[scattering][prepared]") {
  const Runtime& src = source(false);
  Rng rng(0);
  peer::LaneWeights w;
  for (int a = 0; a < 5; ++a)
    for (int b = 0; b < 5; ++b) {
      const sampler::Fiber f = fiber(0.1 + 0.89 * a / 4.0, 0.1 + 0.89 * b / 4.0, 0.0);
      const Runtime prep(src, f);
      peer::sample_numeric(prep, prep.fiber(f), rng, 100000, w);
    }
  INFO(w.lanes << " lanes, worst |w - 1| " << w.worst);
  CHECK(w.lanes == 2500000);
  CHECK(w.bad == 0);
}

TEST_CASE("PreparedScattering: Mitsuba 3 test06_chi2, samples distributed as pdf() says", "[scattering][prepared]") {
  // Mitsuba's χ² (peer_hair_tests.hpp): 301 × 150 bins, 10⁶ samples, wo at Mitsuba's θ 0 and
  // 0.99 π/4 (φ π/2), tilted tables, a white and a coloured fiber at two roughness; significance
  // 0.01 with the Šidák correction over the 8 configurations.
  const Runtime& src = source(true);
  const double alpha = 1.0 - std::pow(1.0 - 0.01, 1.0 / 8.0);
  int k = 0;
  for (const auto& [bm, bn] : std::vector<std::pair<double, double>>{{0.2, 0.3}, {0.6, 0.7}})
    for (const double sa : {0.0, 1.2}) {
      const sampler::Fiber f = fiber(bm, bn, sa);
      const Runtime prep(src, f);
      const sampler::PreparedFiber pf = prep.fiber(f);
      for (double th : {0.0, 0.99 * kPiP / 4.0}) {
        const double wo[3] = {std::sin(th) * std::cos(kPiP / 2.0), std::sin(th) * std::sin(kPiP / 2.0), std::cos(th)};
        const peer::Chi2 r = peer::chi2_sphere<float>(prep.at(pf, wo), 60 + k++, 301, 150, 1000000);
        INFO("pbrt beta_m " << bm << " beta_n " << bn << " sigma_a " << sa << " theta " << th << ": chi2 " << r.chi2 << " with " << r.dof - 1 << " dof, p " << r.p);
        REQUIRE(r.valid);
        CHECK(r.p > alpha);
      }
    }
}

TEST_CASE("PreparedScattering: hostile fibers, grids and sources", "[scattering][prepared][hostile]") {
  const Runtime& src = source(true);
  sampler::Fiber rough;
  rough.beta_m = 10.0 * kPiP / 180.0, rough.beta_n = 12.0 * kPiP / 180.0;
  SECTION("NaN, infinite and negative σa give finite, nonnegative values and a sample") {
    const Runtime prep(src, rough);
    Rng rng(23);
    for (const double bad : {std::nan(""), HUGE_VAL, -HUGE_VAL, -1.0, 1e300}) {
      sampler::Fiber f = rough;
      f.sigma_a[1] = bad;
      const sampler::PreparedFiber pf = prep.fiber(f);
      for (int i = 0; i < 500; ++i) {
        double wo[3], wi[3], rgb[3];
        uniform_sphere(rng(), rng(), wo);
        uniform_sphere(rng(), rng(), wi);
        prep.eval(pf, wo, wi, rgb);
        for (double v : rgb) CHECK((std::isfinite(v) && v >= 0.0));
        const double u[3] = {rng(), rng(), rng()};
        const sampler::ScatteringSample s = prep.sample(pf, wo, u);
        CHECK(s.pdf > 0.0);
        for (double w : s.weight) CHECK((std::isfinite(w) && w >= 0.0));
      }
    }
  }
  SECTION("a grid it cannot use, a source it cannot read and a state it did not build give an invalid runtime or zeros") {
    for (int which = 0; which < 6; ++which) {
      sampler::PreparedGrid g;
      if (which == 0) g.error = 0.0;
      if (which == 1) g.error = std::nan("");
      if (which == 2) g.max_nodes = 1;
      if (which == 3) g.theta_d = 1;
      if (which == 4) g.row_groups = 7;
      if (which == 5) g.shape_sigma_a = 1;
      CHECK(!Runtime(src, rough, g).valid());
    }
    sampler::Fiber zero = rough;
    zero.beta_m = 0.0;
    CHECK(!Runtime(src, zero).valid());
    const Runtime prep(src, rough);
    CHECK(!Runtime(prep, rough).valid());  // a prepared runtime is not a source
    const sampler::PreparedFiber none;
    const double wo[3] = {0.0, 1.0, 0.0}, wi[3] = {0.0, 0.0, 1.0}, u[3] = {0.5, 0.5, 0.5};
    double rgb[3] = {1.0, 1.0, 1.0};
    prep.eval(none, wo, wi, rgb);
    CHECK((rgb[0] == 0.0 && rgb[1] == 0.0 && rgb[2] == 0.0));
    CHECK(!prep.at(none, wo).valid());
    CHECK(prep.sample(none, wo, u).pdf == 0.0);
    CHECK(!src.at(prep.fiber(rough), wo).valid());  // a state for a runtime that is not prepared
  }
}
