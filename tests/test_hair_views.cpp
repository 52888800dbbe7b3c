// Typed views of the shipped default tables (hair_views.hpp, sampler_fiber.hpp): the same values
// as TableSet::sample_value, folding of signed θd and φ, NaN, the float path, and S of a fiber from
// the renderer runtime (HairScattering, which reads the views) against direct evaluation of the
// physics within the tables' own accuracy threshold (the one the file was baked and validated with).
#include <cmath>
#include <hairlut/util/angles.hpp>
#include <hairlut/physics/attenuation.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/util/error.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/physics/lobe_energy.hpp>
#include <hairlut/physics/longitudinal_mp.hpp>
#include <hairlut/io/table_io.hpp>
#include <random>
#include <string>
#include <vector>

#include "catch.hpp"

using namespace hairlut;

namespace {

const TableSet& default_set() {
  static const TableSet set = load_tables(std::string(HAIRLUT_SOURCE_DIR) + "/tables/default/hairlut-default.h5");
  return set;
}

double draw(std::mt19937_64& rng, double lo, double hi) { return lo + (hi - lo) * std::uniform_real_distribution<double>(0.0, 1.0)(rng); }

}  // namespace

TEST_CASE("Typed views give TableSet::sample_value's values at physical arguments, in double and float", "[sampler][views]") {
  const TableSet& set = default_set();
  const auto h = hair_tables<float, double>(set);
  const auto hf = hair_tables<float, float>(set);
  REQUIRE(h.lobes == 4);
  REQUIRE(h.has_residual);
  CHECK(h.eta == 1.55);
  const auto& lobes = set.metadata.at("lobes");
  std::mt19937_64 rng(7);
  for (int p = 0; p < h.lobes; ++p) {
    const std::string lobe = lobes[static_cast<std::size_t>(p)].get<std::string>();
    const Table& n = *set.find("np/" + lobe);
    const Table& m = *set.find("mp/" + lobe);
    double worst = 0.0, worst_float = 0.0;
    for (int i = 0; i < 300; ++i) {
      const double beta = std::exp(draw(rng, std::log(n.axes[0].lo), std::log(n.axes[0].hi))), sigma = draw(rng, 0.0, 16.0),
                   theta = draw(rng, 0.0, radians(89.0)), phi = draw(rng, 0.0, kPi);
      const double ref = set.sample_value(n, {beta, sigma, theta, phi});
      // The local peak as docs/conventions.md defines it: the largest value over φ of this
      // slice, floored at 1e-3 of the white fiber's (σa = 0). Float rounding of the mapped
      // coordinates moves the cell position by ~count × 2^-24 of a cell, and float underflows
      // below 1e-38 (absorbed lobes), which the floor ignores.
      double scale = 0.0, white = 0.0;
      for (int j = 0; j <= 32; ++j) {
        scale = std::max(scale, h.np[p](beta, sigma, theta, kPi * j / 32.0));
        white = std::max(white, h.np[p](beta, 0.0, theta, kPi * j / 32.0));
      }
      scale = std::max(scale, 1e-3 * white);
      worst = std::max(worst, std::abs(h.np[p](beta, sigma, theta, phi) - ref) / scale);
      worst_float = std::max(worst_float, std::abs(hf.np[p](static_cast<float>(beta), static_cast<float>(sigma), static_cast<float>(theta),
                                                             static_cast<float>(phi)) - ref) / scale);
      const double ti = draw(rng, -kHalfPi, kHalfPi), tr = draw(rng, -kHalfPi, kHalfPi);
      const double mref = m.sample({beta, ti, tr});
      CHECK(h.mp[p](beta, ti, tr) == Approx(mref).epsilon(1e-12).margin(1e-12));
      CHECK(hf.mp[p](static_cast<float>(beta), static_cast<float>(ti), static_cast<float>(tr)) == Approx(mref).epsilon(1e-3).margin(1e-4));
    }
    CHECK(worst < 1e-12);
    CHECK(worst_float < 1e-4);
  }
  const Table& r = *set.find("np/residual");
  for (int i = 0; i < 100; ++i) {
    const double sigma = draw(rng, 0.0, 16.0), theta = draw(rng, 0.0, radians(89.0));
    CHECK(h.np_residual(sigma, theta) == Approx(set.sample_value(r, {sigma, theta})).epsilon(1e-12));
  }
}

TEST_CASE("Typed views fold a signed theta_d and phi, and give NaN for NaN", "[sampler][views]") {
  const auto h = hair_tables<float, double>(default_set());
  const auto hf = hair_tables<float, float>(default_set());
  // β 5°, σa 0.5, φ ±30°, θd ±20°: N_p depends on cos θd and is even in φ.
  for (int p = 0; p < h.lobes; ++p) {
    const double b = radians(5.0), v = h.np[p](b, 0.5, radians(20.0), radians(30.0));
    CHECK(v >= 0.0);  // 0 where cubic interpolation undershoots next to a narrow lobe
    CHECK(h.np[p](b, 0.5, radians(-20.0), radians(30.0)) == v);
    CHECK(h.np[p](b, 0.5, radians(-20.0), radians(-30.0)) == v);
    CHECK(h.np[p](b, 0.5, radians(20.0), radians(30.0) - kTwoPi) == Approx(v).epsilon(1e-12));
    CHECK(h.np[p](b, 0.5, radians(20.0), radians(30.0) + 3.0 * kTwoPi) == Approx(v).epsilon(1e-12));
    CHECK(h.np[p].energy(0.5, radians(-20.0)) == h.np[p].energy(0.5, radians(20.0)));
    const double nan = std::nan("");
    CHECK(std::isnan(h.np[p](nan, 0.5, 0.3, 0.2)));
    CHECK(std::isnan(h.np[p](b, nan, 0.3, 0.2)));
    CHECK(std::isnan(h.np[p](b, 0.5, nan, 0.2)));
    CHECK(std::isnan(h.np[p](b, 0.5, 0.3, nan)));
    CHECK(std::isnan(h.mp[p](nan, 0.3, 0.2)));
    CHECK(std::isnan(h.mp[p](b, nan, 0.2)));
    CHECK(std::isnan(h.mp[p](b, 0.3, nan)));
    CHECK(std::isnan(hf.np[p](0.1f, 0.5f, std::nanf(""), 0.2f)));
    CHECK(std::isnan(hf.mp[p](0.1f, std::nanf(""), 0.2f)));
  }
  double sum = 0.0, sum_negative = 0.0;
  for (int p = 0; p < h.lobes; ++p) {
    sum += h.np[p](radians(5.0), 0.5, radians(20.0), radians(30.0));
    sum_negative += h.np[p](radians(5.0), 0.5, radians(-20.0), radians(-30.0));
  }
  CHECK(sum > 0.0);
  CHECK(sum_negative == sum);
  CHECK(std::isnan(h.np_residual(std::nan(""), 0.2)));
  CHECK(h.np_residual(0.5, -0.4) == h.np_residual(0.5, 0.4));
  const sampler::HairScattering<float> s(h);
  const sampler::Fiber f = fiber_from_melanin(0.8, 0.2, radians(10.0), radians(12.0));
  double rgb[3];
  s.eval(f, 0.1, std::nan(""), 0.2, rgb);
  CHECK((std::isnan(rgb[0]) && std::isnan(rgb[1]) && std::isnan(rgb[2])));
  s.eval(f, 0.2, 0.1, std::nan(""), rgb);
  CHECK(std::isnan(rgb[1]));
}

TEST_CASE("hair_tables refuses what it cannot read", "[sampler][views]") {
  TableSet set = default_set();
  CHECK_THROWS_AS((hair_tables<double, double>(set)), DomainError);  // float32 tables
  set.metadata["model"] = "marschner2003";
  CHECK_THROWS_AS((hair_tables<float, double>(set)), DomainError);
  set.metadata["model"] = "deon2011";
  set.tables.erase(set.tables.begin());  // np/R
  CHECK_THROWS_AS((hair_tables<float, double>(set)), DomainError);
  CHECK_THROWS_AS(fiber_from_melanin(-1.0, 0.0, 0.1, 0.1), DomainError);
}

// S = Σ_p M_p(θi, θr) N_p(φ; θd) + M_res N_res against the same sum of directly evaluated lobes:
// M_p in closed form (longitudinal_deon_tilted, the table's tilt), N_p by the baker's Fourier
// method at 1e-12, the residual from its reference energy. Each table may be off by the file's
// threshold `accuracy_max_rel` relative to its local peak (N_p: over φ at the same β, σa, θd,
// floored at 1e-3 of the white fiber's; M_p: over θr at the same β, θi), so S may be off by
// Σ_p thr (M_p N̂_p + M̂_p N_p) + thr² M̂_p N̂_p (hats: the peaks).
TEST_CASE("S of a fiber from the tables matches direct evaluation within the tables' accuracy threshold", "[sampler][views]") {
  const TableSet& set = default_set();
  const auto cfg = nlohmann::json::parse(set.metadata.at("config").get<std::string>());
  const double thr = cfg.at("validate").at("thresholds").at("accuracy_max_rel").get<double>();
  const auto h = hair_tables<float, double>(set);
  const sampler::HairScattering<float> s(h);
  const auto& lobes = set.metadata.at("lobes");
  const int L = h.lobes;
  std::vector<double> alpha;
  for (int p = 0; p < L; ++p) alpha.push_back(set.find("mp/" + lobes[static_cast<std::size_t>(p)].get<std::string>())->attributes.value("alpha", 0.0));
  alpha.push_back(set.find("mp/residual")->attributes.value("alpha", 0.0));
  sampler::Fiber given;
  given.sigma_a[0] = 0.1, given.sigma_a[1] = 1.0, given.sigma_a[2] = 5.0, given.beta_m = radians(25.0), given.beta_n = radians(30.0);
  const sampler::Fiber fibers[] = {fiber_from_melanin(0.8, 0.2, radians(10.0), radians(12.0)), given};
  std::mt19937_64 rng(3);
  const auto rules = std::make_shared<GaussLegendreCache>();
  constexpr int kDense = 97;
  for (const sampler::Fiber& f : fibers) {
    double worst = 0.0, worst_views = 0.0;
    for (int i = 0; i < 40; ++i) {
      const double ti = draw(rng, -radians(85.0), radians(85.0)), tr = draw(rng, -radians(85.0), radians(85.0)), phi = draw(rng, -kPi, kPi);
      const double td = 0.5 * (tr - ti);
      double table[3];
      s.eval(f, tr, ti, phi, table);  // held θo = the tables' θr, sampled θi
      // M_p exact and its peak over θr.
      std::vector<double> m(static_cast<std::size_t>(L + 1)), mpeak(static_cast<std::size_t>(L + 1), 0.0);
      for (int p = 0; p <= L; ++p) {
        const double v = f.beta_m * f.beta_m;
        m[static_cast<std::size_t>(p)] = longitudinal_deon_tilted(v, alpha[static_cast<std::size_t>(p)], ti, tr);
        for (int j = 0; j <= 720; ++j)
          mpeak[static_cast<std::size_t>(p)] = std::max(mpeak[static_cast<std::size_t>(p)], longitudinal_deon_tilted(v, alpha[static_cast<std::size_t>(p)], ti, -kHalfPi + kPi * j / 720.0));
      }
      for (int c = 0; c < 3; ++c) {
        NpGridRequest r;
        r.eta = h.eta;
        r.quadrature.method = NpQuadratureConfig::Method::fourier;
        r.quadrature.tolerance = 1e-12;
        r.lobes = L;
        r.sigmas = {f.sigma_a[c], 0.0};
        r.thetas = {std::abs(td)};
        for (int j = 0; j < kDense; ++j) r.phis.push_back(kPi * j / (kDense - 1));
        r.phis.push_back(std::abs(phi));
        r.betas_of = [&](int) { return std::vector<double>{f.beta_n}; };
        r.rules = rules;
        std::vector<double> n(static_cast<std::size_t>(L)), npeak(static_cast<std::size_t>(L), 0.0), white(static_cast<std::size_t>(L), 0.0);
        BakeOptions o;
        o.threads = 1;
        bake_np_grid(r, o, "", [&](int p, std::size_t k, std::size_t, std::size_t, std::size_t j, double value) {
          const auto pp = static_cast<std::size_t>(p);
          if (j == kDense && k == 0) n[pp] = value;
          if (j < kDense) (k == 0 ? npeak[pp] : white[pp]) = std::max(k == 0 ? npeak[pp] : white[pp], value);
        });
        const double nres = lobe_energies_reference(AttenuationSlice(h.eta, std::abs(td), f.sigma_a[c]), {L, true}, 1e-13).value.back() / kTwoPi;
        double exact = m[static_cast<std::size_t>(L)] * nres;
        double tol = thr * (m[static_cast<std::size_t>(L)] + mpeak[static_cast<std::size_t>(L)]) * nres + thr * thr * mpeak[static_cast<std::size_t>(L)] * nres;
        double views = h.mp_residual(f.beta_m, ti, tr) * h.np_residual(f.sigma_a[c], td);
        for (int p = 0; p < L; ++p) {
          const auto pp = static_cast<std::size_t>(p);
          const double peak = std::max(npeak[pp], 1e-3 * white[pp]);
          exact += m[pp] * n[pp];
          tol += thr * (m[pp] * peak + mpeak[pp] * n[pp]) + thr * thr * mpeak[pp] * peak;
          views += h.mp[p](f.beta_m, ti, tr) * h.np[p](f.beta_n, f.sigma_a[c], td, phi);
        }
        worst = std::max(worst, std::abs(table[c] - exact) / tol);
        // Against the typed 3D/4D lookups summed here: the same tables and lookups, up to rounding.
        worst_views = std::max(worst_views, std::abs(table[c] - views) / (1e-12 * views + 1e-300));
      }
    }
    CHECK(worst <= 1.0);
    CHECK(worst_views <= 1.0);
  }
}

TEST_CASE("fast_acos and fast_atan01 are within 2e-8 of acos and atan, and fiber_angles gives the angles of S from direction vectors", "[sampler][views]") {
  double worst = 0.0, worst_float = 0.0;
  for (int i = -20000; i <= 20000; ++i) {
    const double x = i / 20000.0;
    worst = std::max(worst, std::abs(sampler::fast_acos(x) - std::acos(x)));
    worst_float = std::max(worst_float, std::abs(static_cast<double>(sampler::fast_acos(static_cast<float>(x))) - std::acos(static_cast<double>(static_cast<float>(x)))));
  }
  CHECK(worst < 5e-8);        // A&S 4.4.46: 2e-8, plus the rounding of the coefficients as printed
  CHECK(worst_float < 1e-6);  // plus float rounding: 4 ulps of π (2.4e-7 each)
  double worst_atan = 0.0, worst_atan_float = 0.0;
  for (int i = 0; i <= 20000; ++i) {
    const double x = i / 20000.0;
    worst_atan = std::max(worst_atan, std::abs(sampler::fast_atan01(x) - std::atan(x)));
    worst_atan_float = std::max(worst_atan_float, std::abs(static_cast<double>(sampler::fast_atan01(static_cast<float>(x))) - std::atan(static_cast<double>(static_cast<float>(x)))));
  }
  CHECK(worst_atan < 5e-8);        // A&S 4.4.49: 2e-8, plus the rounding of the coefficients as printed
  CHECK(worst_atan_float < 5e-7);  // plus float rounding: a few ulps of π/4
  std::mt19937_64 rng(5);
  for (int i = 0; i < 1000; ++i) {
    const double ti = draw(rng, -1.5, 1.5), tr = draw(rng, -1.5, 1.5), pi_ = draw(rng, -kPi, kPi), pr = draw(rng, -kPi, kPi);
    const double wi[3] = {std::sin(ti), std::cos(ti) * std::cos(pi_), std::cos(ti) * std::sin(pi_)};
    const double wo[3] = {std::sin(tr), std::cos(tr) * std::cos(pr), std::cos(tr) * std::sin(pr)};
    double a, b, phi;
    sampler::fiber_angles(wi, wo, a, b, phi);
    CHECK(a == Approx(ti).margin(1e-7));
    CHECK(b == Approx(tr).margin(1e-7));
    CHECK(phi == Approx(std::abs(std::remainder(pr - pi_, kTwoPi))).margin(1e-6));  // acos near 0 and π: √ of the rounding
  }
}
