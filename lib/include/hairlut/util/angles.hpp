// Angle constants, conversions and the checked inclination domain [-pi/2, pi/2].
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string_view>

#include "hairlut/util/error.hpp"

namespace hairlut {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kHalfPi = std::numbers::pi / 2.0;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

constexpr double radians(double degrees) { return degrees * (kPi / 180.0); }
constexpr double degrees(double radians) { return radians * (180.0 / kPi); }

/// Checks that an inclination θ lies in [-π/2, π/2] and returns it clamped there. The double
/// nearest π/2 lies below π/2, so values up to 4 ulp beyond the rounded end point (as produced by
/// radians(90.0) or M_PI/2 arithmetic) are accepted and clamped.
inline double checked_inclination(std::string_view name, double theta) {
  constexpr double kSlack = kHalfPi * (1.0 + 8.0 * 1.1102230246251565e-16);
  if (!(std::abs(theta) <= kSlack)) throw_domain_error(name, "must lie in [-pi/2, pi/2] radians", theta);
  return std::clamp(theta, -kHalfPi, kHalfPi);
}

/// φ wrapped to [-π, π] (exact: std::remainder introduces no rounding error).
inline double wrap_azimuth(double phi) { return std::remainder(phi, kTwoPi); }

}  // namespace hairlut
