// S(θi, θr, φ) of a fibre from the default tables (sampler_fibre.hpp): the four axes of N_p and M_p
// located together in register lanes give what each axis's own taps (FixedAxis::taps) give, up to
// rounding, in double and float, at random angles and at the ends of every axis (θd at 0 and
// beyond the last node, φ at 0 and π, θi and θr at ±π/2, nodes exactly).
#include <cmath>
#include <hairlut/io/table_io.hpp>
#include <hairlut/physics/melanin.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/util/angles.hpp>
#include <limits>
#include <random>
#include <string>

#include "catch.hpp"

using namespace hairlut;

namespace {

template <class R>
double compare_lanes_per_axis(const sampler::HairTables<float, R>& h, const sampler::Fibre& f, std::uint64_t seed) {
  const sampler::FibreScattering<float, R> s(h, f);
  const sampler::Axis td = h.np[0].table().axis(2).axis(), ph = h.np[0].table().axis(3).axis();
  const sampler::Axis ti = h.mp[0].table().axis(1).axis(), tr = h.mp[0].table().axis(2).axis();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // A coordinate of axis a: anywhere, in its first or last cell, or on a node.
  auto pick = [&](const sampler::Axis& a) {
    const double r = u(rng);
    if (r < 0.15) return sampler::node(a, static_cast<int>(u(rng) * a.count));
    if (r < 0.3) return sampler::node(a, 0) + u(rng) * (sampler::node(a, 1) - sampler::node(a, 0));
    if (r < 0.45) return sampler::node(a, a.count - 2) + u(rng) * (sampler::node(a, a.count - 1) - sampler::node(a, a.count - 2));
    return a.lo + u(rng) * (a.hi - a.lo);
  };
  const double eps = std::numeric_limits<R>::epsilon();
  double worst = 0.0;
  for (int k = 0; k < 20000; ++k) {
    double a, b, phi;
    if (k % 2 == 0) {
      a = pick(ti), b = pick(tr), phi = (u(rng) < 0.5 ? -1.0 : 1.0) * pick(ph);
    } else {
      // θd chosen on its axis (end cells and nodes included), θi within range around it.
      const double d = (u(rng) < 0.5 ? -1.0 : 1.0) * pick(td);
      a = std::max(ti.lo, std::min(ti.hi - 2.0 * std::abs(d), ti.lo + u(rng) * (ti.hi - ti.lo)));
      b = a + 2.0 * d, phi = pick(ph);
    }
    if (k % 97 == 0) phi += kTwoPi * (u(rng) < 0.5 ? -1.0 : 1.0);
    R lanes[3], per_axis[3];
    s(static_cast<R>(a), static_cast<R>(b), static_cast<R>(phi), lanes);
    s.per_axis(static_cast<R>(a), static_cast<R>(b), static_cast<R>(phi), per_axis);
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(static_cast<double>(lanes[c]) - static_cast<double>(per_axis[c])) /
                                  (8.0 * eps * std::abs(static_cast<double>(per_axis[c])) + 1e-300));
  }
  return worst;
}

}  // namespace

TEST_CASE("S of a fibre with its axes located in register lanes equals S with per-axis taps up to rounding", "[sampler][views]") {
  const TableSet set = load_tables(std::string(HAIRLUT_SOURCE_DIR) + "/tables/default/hairlut-default.h5");
  const auto hd = hair_tables<float, double>(set);
  const auto hf = hair_tables<float, float>(set);
  sampler::Fibre given;
  given.sigma_a[0] = 0.1, given.sigma_a[1] = 1.0, given.sigma_a[2] = 5.0, given.beta_m = radians(25.0), given.beta_n = radians(30.0);
  for (const sampler::Fibre& f : {fibre_from_melanin(0.8, 0.2, radians(10.0), radians(12.0)), given}) {
    CHECK(compare_lanes_per_axis(hd, f, 3) <= 1.0);
    CHECK(compare_lanes_per_axis(hf, f, 4) <= 1.0);
  }
}

// fibre_angles takes the two arcsines on register lanes: fast_acos's operations, one lane each.
template <class R>
double compare_angle_lanes(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  const R half_pi = static_cast<R>(1.57079632679489661923);
  for (int k = 0; k < 20000; ++k) {
    R wi[3], wo[3];
    for (int j = 0; j < 3; ++j) wi[j] = static_cast<R>(u(rng)), wo[j] = static_cast<R>(u(rng));
    if (k % 50 == 0) wi[0] = static_cast<R>(k % 100 == 0 ? 1 : -1), wo[0] = static_cast<R>(u(rng) * 1.5);  // |x| ≥ 1 clamps
    R ti, tr, phi;
    sampler::fibre_angles(wi, wo, ti, tr, phi);
    worst = std::max(worst, std::abs(static_cast<double>(ti - (half_pi - sampler::fast_acos(wi[0])))));
    worst = std::max(worst, std::abs(static_cast<double>(tr - (half_pi - sampler::fast_acos(wo[0])))));
  }
  return worst / (2.0 * std::numeric_limits<R>::epsilon() * 1.6);  // 2 ulps of π/2
}

TEST_CASE("fibre_angles' arcsines on register lanes equal fast_acos up to rounding", "[sampler][views]") {
  CHECK(compare_angle_lanes<double>(5) <= 1.0);
  CHECK(compare_angle_lanes<float>(6) <= 1.0);
}
