// The energy of each azimuthal lobe, e_p(θd) = ½ ∫_{−1}^{1} A(p, h) dh = ∫_{−π/2}^{π/2} ... (the
// integral of N_p over φ, independent of the azimuthal roughness), and of the residual p ≥ P.
#pragma once

#include <vector>

#include "hairlut/physics/attenuation.hpp"
#include "hairlut/util/quadrature.hpp"

namespace hairlut {

/// Which lobes a computation includes: the explicit lobes p = 0 … count − 1 and, optionally, the
/// residual of all lobes p ≥ count (d'Eon's A summed in closed form).
struct LobeSet {
  int count = 3;          ///< number of explicit lobes P ≥ 1 (3: R, TT, TRT)
  bool residual = false;  ///< include the residual p ≥ P as one more entry
  int size() const { return count + (residual ? 1 : 0); }
};

/// e_p = ½ ∫ A(p, h) dh = ∫_0^{π/2} A(p, sin γ) cos γ dγ for p = 0 … P − 1, then (if asked) the
/// residual ½ ∫ A_{≥P} dh, by Gauss–Legendre in γ over [0, π/2] with the given rule (the
/// integrand is analytic there, so the error falls geometrically with the order; 128 nodes reach
/// 1e−13 for η ≥ 1.01, see tests). For σa = 0 with the residual the entries sum to 1.
/// Domain: lobes.count in [1, 1000]. Entries in [0, 1].
std::vector<double> lobe_energies(const AttenuationSlice& slice, LobeSet lobes, const GaussLegendreRule& rule);

/// The same energies by adaptive Gauss–Kronrod to rel_tol relative to max(entry, 1e-3) (a slower
/// reference; bounded cost for every legal η, including η → 1); the result says whether every
/// entry converged.
AdaptiveResult lobe_energies_reference(const AttenuationSlice& slice, LobeSet lobes, double rel_tol = 1e-14);

}  // namespace hairlut
