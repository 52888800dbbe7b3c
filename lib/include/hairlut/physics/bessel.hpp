// The exponentially scaled modified Bessel function I0e(x) = e^{−x} I0(x) that d'Eon's M_p needs.
#pragma once

namespace hairlut {

/// I0e(x) = e^{−x} I0(x) for x ≥ 0 (even in x: I0e(−x) is not e^{x}I0(x), so callers pass |x|).
/// Accurate to a few ulp for every finite x ≥ 0 and +∞ (returns 0 there); never overflows.
/// Boost.Math provides I0 but no scaled variant, and I0 itself overflows past x ≈ 713, so the large
/// arguments use the asymptotic series written out here.
double bessel_i0e(double x);

/// I0e(c/v)/v for c ≥ 0 and v > 0 (normal), computed without forming c/v when that would overflow:
/// for large c/v it equals Σ_k a_k (v/c)^k / √(2π c v). This is the Bessel factor of d'Eon's M_p.
double bessel_i0e_over_v(double c, double v);

}  // namespace hairlut
