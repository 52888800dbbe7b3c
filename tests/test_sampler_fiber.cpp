// The angles of S from direction vectors in the fiber frame (sampler_fiber.hpp): fiber_angles takes
// its two arcsines on register lanes, which must give fast_acos's values up to rounding.
#include <cmath>
#include <hairlut/tables/hair_views.hpp>
#include <limits>
#include <random>

#include "catch.hpp"

using namespace hairlut;

// fiber_angles takes the two arcsines on register lanes: fast_acos's operations, one lane each.
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
    sampler::fiber_angles(wi, wo, ti, tr, phi);
    worst = std::max(worst, std::abs(static_cast<double>(ti - (half_pi - sampler::fast_acos(wi[0])))));
    worst = std::max(worst, std::abs(static_cast<double>(tr - (half_pi - sampler::fast_acos(wo[0])))));
  }
  return worst / (2.0 * std::numeric_limits<R>::epsilon() * 1.6);  // 2 ulps of π/2
}

TEST_CASE("fiber_angles' arcsines on register lanes equal fast_acos up to rounding", "[sampler][views]") {
  CHECK(compare_angle_lanes<double>(5) <= 1.0);
  CHECK(compare_angle_lanes<float>(6) <= 1.0);
}
