// hairlut sampler, the grazing factor of a table whose θd axis reaches 90°: the analytic factor its
// stored values were divided by, which a lookup multiplies back (docs/table-format.md, "Energies
// at grazing").
//
// Header-only and dependency-free (C++17).
#pragma once

#include <cmath>

namespace hairlut {
namespace sampler {

/// The factor g(σa, θd) by which a table whose θd axis reaches 90° divides its values (the lobe
/// energies, the residual, a Fourier table's coefficients), so that they stay finite and smooth
/// where the energies vanish (docs/table-format.md, "Energies at grazing", format 3.0), with
/// u = cos θd (clamped at 0):
///   g = u^n · u (u² + b x u + e x²) / (u³ + c x u² + d x² u + f x³),  x = x_scale · expm1(τ σa),
/// the second factor present only where x_scale ≠ 0 (the residual, whose energy goes as u for σa = 0
/// and as u² for σa > 0, the change over σa of the order of u; with a = x / u it is
/// (1 + b a + e a²) / (1 + c a + d a² + f a³)). From the table's attributes `cos_theta_d_power` (n, at
/// most kMaxCosPower: loaders refuse more) and `grazing_absorption` {x_scale, tau, b, c, d, e, f}
/// (e and f 0 where absent). g = 0 at u = 0 (n ≥ 1) and where x overflows (σa so large that the
/// energy underflowed).
struct GrazingFactor {
  static constexpr int kMaxCosPower = 2;
  int cos_power = 0;
  double x_scale = 0.0, tau = 0.0, b = 0.0, c = 0.0, d = 0.0, e = 0.0, f = 0.0;
  bool none() const { return cos_power <= 0 && x_scale == 0.0; }
  template <class R>
  R operator()(R sigma_a, R theta_d) const {
    if (none()) return R(1);
    return of_cos(sigma_a, std::cos(theta_d));
  }
  /// The same from u = cos θd, for a caller that has it already.
  template <class R>
  R of_cos(R sigma_a, R cos_theta_d) const {
    if (none()) return R(1);
    return static_cast<R>(of_cos_x(x_of(static_cast<double>(sigma_a)), static_cast<double>(cos_theta_d)));
  }
  /// x = x_scale · expm1(τ σa), the absorption term's argument (0 without one), for a caller that
  /// holds σa fixed (a material) and passes x to of_cos_x.
  double x_of(double sigma_a) const { return x_scale != 0.0 ? x_scale * std::expm1(tau * sigma_a) : 0.0; }
  /// g from x (x_of) and u = cos θd.
  double of_cos_x(double x, double u) const {
    if (!(u > 0.0)) u = 0.0;
    double g = 1.0;
    for (int i = 0; i < cos_power && i < kMaxCosPower; ++i) g *= u;
    if (x_scale != 0.0) {
      const double den = ((u + c * x) * u + d * x * x) * u + f * x * x * x;
      g = den > 0.0 && den < HUGE_VAL ? g * u * ((u + b * x) * u + e * x * x) / den : 0.0;
    }
    return g;
  }
};

}  // namespace sampler
}  // namespace hairlut
