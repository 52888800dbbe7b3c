// Per-material N_p: the explicit lobes of one material (one detector width β per lobe) for a few
// absorptions (the RGB σa) over θd nodes × a φ grid, the shape renderers precompute per material.
//
// The same quadratures as the generic bake (azimuthal_fourier.hpp): Gauss–Legendre nodes in γ on
// [0, π/2] whose count comes from the error bounds there, evaluated either by spreading each
// node's Gaussian onto the periodic φ grid (narrow β) or from Fourier coefficients (wide β),
// whichever the work estimate says is cheaper per (θd, lobe). What the material shape lets it
// share: one node set for every lobe and σa of a θd (Φ, Fresnel and the path length computed once;
// only T^p depends on σa), the θd-independent node factors (γ, cos γ, sin γ, weights) computed
// once per material, and a spreading loop that runs straight over a padded circle.
//
// Exact and approximate: as spread_np / fourier_coefficients (tolerance relative to the lobe's
// peak); checked against the adaptive reference in tests/test_material_np.cpp.
#pragma once

#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "hairlut/physics/attenuation.hpp"
#include "hairlut/physics/azimuthal_fourier.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/util/quadrature.hpp"

namespace hairlut {

/// The fixed inputs of a per-material N_p bake.
struct MaterialNpRequest {
  double eta = 1.55;
  AbsorptionPath path = AbsorptionPath::chord;
  std::vector<double> betas;   ///< one detector width per explicit lobe p = 0 … size − 1
  std::vector<double> sigmas;  ///< σa per channel
  std::vector<double> thetas;  ///< θd nodes
  std::vector<double> phis;    ///< φ nodes (any; periodic grids take the spreading path)
  double tolerance = 1e-12;
};

class MaterialNp {
 public:
  /// Plans every (θd, lobe) and builds the Gauss–Legendre rules it needs (newton_gauss_legendre).
  explicit MaterialNp(MaterialNpRequest request);

  std::size_t theta_count() const { return r_.thetas.size(); }
  /// N_p of every lobe and σa at θd node t: out[(p · K + k) · n_phi + j], K = sigmas.size().
  void evaluate(std::size_t t, std::vector<double>& out) const;
  /// Why narrow detectors cannot take the spreading path on this φ grid (empty when they can).
  const std::string& note() const { return note_; }

  /// How (θd node t, lobe p) is evaluated: by spreading (true) or by Fourier coefficients.
  bool spreads(std::size_t t, int p) const { return spread_[t * r_.betas.size() + static_cast<std::size_t>(p)] != 0; }
  int spread_nodes_at(std::size_t t) const { return spread_m_[t]; }
  int fourier_nodes_at(std::size_t t) const { return fourier_m_[t]; }
  int fourier_terms_of(int p) const { return terms_[static_cast<std::size_t>(p)]; }

 private:
  // θd-independent factors of a rule's nodes mapped to γ ∈ [0, π/2].
  struct RuleNodes {
    std::vector<double> gamma, cos_gamma, sin_gamma, weight;  // weight: w · π/4 · cos γ
    std::vector<double> cos_2gamma, sin_2gamma;
  };
  void spread_at(std::size_t t, std::vector<double>& out) const;
  void fourier_at(std::size_t t, std::vector<double>& out) const;

  MaterialNpRequest r_;
  PeriodicGrid grid_;
  std::string note_;
  std::vector<char> spread_;         // [t · L + p]
  std::vector<int> spread_m_, fourier_m_, terms_;
  std::map<int, RuleNodes> nodes_;
  std::unique_ptr<CosineSeries> series_;
};

/// Gauss–Legendre nodes (ascending) and weights of order m on [−1, 1] by Newton's method on the
/// three-term recurrence from the asymptotic first guess cos(π(i + 3/4)/(m + 1/2)), in double:
/// O(m²) work, a fraction of GaussLegendreRule's cost; agrees with it to ~1e−15 (tested).
void newton_gauss_legendre(int m, std::vector<double>& nodes, std::vector<double>& weights);

/// lobe_energies (lobe_energy.hpp) for every σa in `sigmas` at once: the node factors that do not
/// depend on σa (Fresnel, path length) are computed once. The same rule and integrand, so the
/// same values to rounding. out[k · lobes.size() + p].
void material_energies(double eta, double theta_d, AbsorptionPath path, std::span<const double> sigmas, LobeSet lobes,
                       const GaussLegendreRule& rule, std::vector<double>& out);

}  // namespace hairlut
