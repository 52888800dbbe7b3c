// Internal: every solution of f(x) ≡ φ (mod 2π) on a function that is monotone between given
// edges, by bracketed TOMS 748 per piece and per multiple of 2π. Shared by the exact and the
// cubic azimuthal root finders (azimuthal_np.cpp, marschner.cpp).
#pragma once

#include <algorithm>
#include <boost/math/tools/roots.hpp>
#include <boost/math/tools/toms748_solve.hpp>
#include <cmath>
#include <span>
#include <vector>

#include "hairlut/util/angles.hpp"

namespace hairlut::detail {

/// Roots x of f(x) = φ + 2πk for every integer k, on the pieces [edges[i], edges[i+1]] on which
/// f is monotone; φ is wrapped to [−π, π] first. Ascending, duplicates (at shared edges) removed.
template <class F>
std::vector<double> monotone_piece_roots(F&& f, std::span<const double> edges, double phi) {
  phi = wrap_azimuth(phi);
  std::vector<double> roots;
  for (std::size_t e = 0; e + 1 < edges.size(); ++e) {
    const double lo = edges[e], hi = edges[e + 1];
    const double f_lo = f(lo), f_hi = f(hi);
    const double mn = std::min(f_lo, f_hi), mx = std::max(f_lo, f_hi);
    const auto k_min = static_cast<long>(std::ceil((mn - phi) / kTwoPi));
    const auto k_max = static_cast<long>(std::floor((mx - phi) / kTwoPi));
    for (long k = k_min; k <= k_max; ++k) {
      const double target = phi + kTwoPi * static_cast<double>(k);
      auto g = [&](double x) { return f(x) - target; };
      const double a_val = f_lo - target, b_val = f_hi - target;
      if (a_val == 0.0) { roots.push_back(lo); continue; }
      if (b_val == 0.0) { roots.push_back(hi); continue; }
      if ((a_val < 0.0) == (b_val < 0.0)) continue;  // target only touches the piece at rounding level
      std::uintmax_t iterations = 200;
      const auto bracket = boost::math::tools::toms748_solve(g, lo, hi, a_val, b_val,
                                                             boost::math::tools::eps_tolerance<double>(52), iterations);
      roots.push_back(0.5 * (bracket.first + bracket.second));
    }
  }
  std::sort(roots.begin(), roots.end());
  roots.erase(std::unique(roots.begin(), roots.end(), [](double a, double b) { return std::abs(a - b) < 1e-13; }), roots.end());
  return roots;
}

}  // namespace hairlut::detail
