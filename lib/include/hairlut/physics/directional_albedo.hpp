// Energy of the full model: the directional albedo (white-furnace energy)
//   E(θi) = ∫_{−π/2}^{π/2} ∫_{−π}^{π} Σ_p M_p(θi, θr) N_p(φ; θd) cos θr dφ dθr
//         = Σ_p ∫ M_p(v_p, θi, θr − α_p) e_p(θd) cos θr dθr,   θd = (θr − θi)/2,
// which is 1 for σa = 0 with every lobe included, the same roughness everywhere and no tilt
// (d'Eon 2011 §4); and the energy of the longitudinal functions alone.
#pragma once

#include <vector>

#include "hairlut/physics/hair_model.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "hairlut/util/quadrature.hpp"

namespace hairlut {

/// E(θi) in total and per lobe (explicit lobes, then the residual if the model has one).
/// Absolute tolerance of directional_albedo per lobe. Albedos are fractions of unit incident
/// energy (their sum is at most 1 by energy conservation); 1e-14 is about 50 ulp of 1, where the
/// integrand's own rounding (Fresnel factors, cosines, exponentials) sets the floor.
inline constexpr double kAlbedoAbsTol = 1e-14;

struct AlbedoResult {
  double theta_i = 0.0;
  double total = 0.0;
  std::vector<double> per_lobe;
  double error = 0.0;      ///< estimated absolute quadrature error of total
  bool converged = false;  ///< the θr integral met its tolerance
};

/// E(θi) for θi in [−π/2, π/2]: adaptive Gauss–Kronrod over θr (split at each lobe's specular cone
/// and tilt fold) of M_p · e_p(θd) · cos θr, the lobe energies e_p by Gauss–Legendre of
/// energy_order nodes in γ. Each lobe meets rel_tol relative to its own value or an absolute
/// kAlbedoAbsTol, whichever is looser, so that a lobe carrying almost no energy (R as η → 1, or
/// every lobe but R in a strongly absorbing fiber) does not drive the integral into rounding noise:
/// the cost stays bounded for every legal η, β and θi. Throws DomainError for an invalid model or θi.
AlbedoResult directional_albedo(const HairModel& model, double theta_i, double rel_tol = 1e-11,
                                int energy_order = 128);

/// Breakpoints for integrating a tilted lobe M(β², θi, fold(θr − α)) over θr in [−π/2, π/2]: every
/// θr where the lobe peaks (θr − α ≡ −θi across the poles) with a ladder at ±β·4^k around it, so that
/// no adaptive panel next to a narrow peak is more than four times wider than the peak (otherwise
/// Gauss–Kronrod nodes can all miss a peak of width β ≲ 1e−3 at a panel's end), and the two fold
/// points α ± π/2. Appends to bp (values outside [−π/2, π/2] included: filter them).
void add_longitudinal_breakpoints(std::vector<double>& bp, double beta, double alpha, double theta_i);

/// ∫_{−π/2}^{π/2} M(v, θi, θr − α) cos θr dθr for d'Eon's M_p (1 without tilt; tilted lobes lose or
/// gain energy near grazing). Adaptive to rel_tol; converged in the result.
AdaptiveResult longitudinal_energy_deon(double v, double alpha, double theta_i, double rel_tol = 1e-12);

/// ∫_{−π/2}^{π/2} M_G(β; θi, θr) cos²θr dθr for Marschner's Gaussian with 1/cos²θd (the
/// reciprocal-problem energy of d'Eon 2011 eq. 5 with N_R integrating to 1): near 2 for small β
/// with the θh argument, near 1 with 2θh; not 1 in general.
AdaptiveResult longitudinal_energy_gaussian(double beta, double alpha, double theta_i, GaussianArgument argument,
                                            double rel_tol = 1e-12);

}  // namespace hairlut
