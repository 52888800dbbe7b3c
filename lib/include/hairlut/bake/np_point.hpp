// N_p at one point exactly as the baker computes a table entry: the detector's Fourier series or
// direct spreading (azimuthal_fourier.hpp), chosen per point by the baker's cost model, with the
// baker's tolerance. For checking a table value by hand (hairlut-eval np, the Python module).
#pragma once

#include <string>

#include "hairlut/physics/attenuation.hpp"

namespace hairlut {

/// A value of N_p and how it was obtained.
struct PointNp {
  double value = 0.0;
  std::string method;  ///< what computed `value`, in words
  std::string note;    ///< empty, or why the baker's method was not used
};

/// N_p(φ; θd, σa, β, η) of lobe p by the baker's method (bake_np_grid with method fourier) and
/// tolerance (relative to the lobe peak). Exact up to that tolerance and rounding; the value
/// equals a table entry at the same arguments up to rounding. φ is any real (N_p is even and
/// 2π-periodic); φ/π is matched to a fraction with denominator ≤ 10^6 when it is one to 1e-13,
/// so that the evaluation grid is the baker's kind of periodic grid. Where the baker's quadrature
/// would need more Gauss–Legendre nodes than the library's rules provide (β of order 1e-4 rad and
/// below), the baker cannot bake that β: the adaptive reference is returned instead and `note`
/// says so. Throws DomainError for arguments outside the model's domain.
PointNp baker_np(double eta, AbsorptionPath path, double theta_d, double sigma_a, int p, double beta, double phi, double tolerance = 1e-12);

}  // namespace hairlut
