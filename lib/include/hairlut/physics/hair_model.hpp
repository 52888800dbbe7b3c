// The parameters of a full d'Eon 2011 hair model: fiber, explicit lobes and the residual lobe.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "hairlut/physics/attenuation.hpp"

namespace hairlut {

/// Roughness and tilt of one lobe. Longitudinal variance v = β_m²; azimuthal detector width β_n.
struct LobeParams {
  double beta_m = 0.1;  ///< longitudinal roughness β (radians), v = β²; > 0
  double beta_n = 0.1;  ///< azimuthal roughness β of the Gaussian detector (radians); > 0
  double alpha = 0.0;   ///< cuticle tilt: shift of the cone in θr (radians), |α| ≤ π/2 (see longitudinal_mp.hpp)
};

/// A fiber with explicit lobes p = 0 … P − 1 and, optionally, the residual of all p ≥ P, whose
/// energy is spread uniformly in φ (conventions.md) and which uses its own longitudinal lobe.
struct HairModel {
  double eta = 1.55;                          ///< index of refraction, > 1
  double sigma_a = 0.0;                       ///< absorption per unit fiber radius, ≥ 0
  AbsorptionPath path = AbsorptionPath::chord;
  std::vector<LobeParams> lobes;              ///< p = 0 (R), 1 (TT), 2 (TRT), ...
  std::optional<LobeParams> residual;         ///< the lobes p ≥ lobes.size(), if included

  /// Throws DomainError naming the first invalid field (e.g. "lobes[2].beta_m must be ...").
  void validate() const;

  /// d'Eon's energy argument: every lobe (and the residual) with the same roughness β, no tilt.
  static HairModel uniform(double eta, double sigma_a, double beta, int lobe_count, bool with_residual);
};

/// Conventional lobe names: R, TT, TRT, TRRT, TRRRT, ... ("T" + "R"×(p−1) + "T" for p ≥ 1).
std::string lobe_name(int p);
/// Inverse of lobe_name; also accepts "p<N>". Throws DomainError naming `what`.
int parse_lobe(const std::string& name, const std::string& what = "lobe");

}  // namespace hairlut
