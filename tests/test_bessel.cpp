// I0e(x) = e^{−x} I0(x) against 50-digit evaluations: Boost's multiprecision Bessel function
// where e^{x} is representable, and the asymptotic series summed in 50 digits beyond.
#include <boost/math/special_functions/bessel.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <cmath>
#include <hairlut/physics/bessel.hpp>

#include "catch.hpp"

using mp = boost::multiprecision::cpp_bin_float_50;

namespace {
mp i0e_reference(double x) {
  const mp X(x);
  if (x < 2e4) return exp(-X) * boost::math::cyl_bessel_i(0, X);
  // Σ a_k x^−k / √(2πx) with a_k = a_{k−1}(2k − 1)²/(8k), summed until 1e−40.
  mp term = 1, sum = 1;
  for (int k = 1; k < 200 && term > mp("1e-40") * sum; ++k) {
    term *= mp((2 * k - 1) * (2 * k - 1)) / (8 * k * X);
    sum += term;
  }
  return sum / sqrt(2 * boost::math::constants::pi<mp>() * X);
}
}  // namespace

TEST_CASE("I0e matches a 50-digit reference", "[bessel]") {
  std::vector<double> xs = {0.0, 1e-300, 1e-10, 1e-3, 0.5, 1.0, 3.75, 10.0, 20.0, 50.0, 63.999, 64.0, 64.001,
                            100.0, 500.0, 700.0, 713.0, 800.0, 1e4, 1e5, 1e6, 1e10, 1e100, 1e300};
  for (double x = 1e-6; x < 1e7; x *= 1.7) xs.push_back(x);
  for (double x : xs) {
    INFO("x=" << x);
    const double ref = i0e_reference(x).convert_to<double>();
    CHECK(hairlut::bessel_i0e(x) == Approx(ref).epsilon(2e-15));
    CHECK(hairlut::bessel_i0e(-x) == hairlut::bessel_i0e(x));
  }
  CHECK(hairlut::bessel_i0e(INFINITY) == 0.0);
}

TEST_CASE("I0e(c/v)/v keeps full precision where c/v or 1/v overflow", "[bessel]") {
  const double cs[] = {1.0, 0.5, 1e-3, 3.7e-33};
  const double vs[] = {100.0, 1.0, 1e-3, 1e-6, 1e-12, 1e-100, 1e-300, 2.3e-308};
  for (double c : cs)
    for (double v : vs) {
      INFO("c=" << c << " v=" << v);
      const double got = hairlut::bessel_i0e_over_v(c, v);
      REQUIRE(std::isfinite(got));
      // Reference in 50 digits: I0e(c/v)/v with the asymptotic form for huge arguments.
      const mp x = mp(c) / mp(v);
      mp ref;
      if (x < 2e4) {
        ref = i0e_reference(static_cast<double>(x)) / mp(v);
        if (!(x > 0)) ref = 1 / mp(v);
      } else {
        mp term = 1, sum = 1;
        for (int k = 1; k < 200 && term > mp("1e-40") * sum; ++k) {
          term *= mp((2 * k - 1) * (2 * k - 1)) / (8 * k * x);
          sum += term;
        }
        ref = sum / sqrt(2 * boost::math::constants::pi<mp>() * mp(c) * mp(v));
      }
      CHECK(got == Approx(ref.convert_to<double>()).epsilon(1e-14));
    }
}
