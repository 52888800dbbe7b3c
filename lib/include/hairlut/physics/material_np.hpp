// Per-material N_p: the explicit lobes of one material (one detector width β per lobe) for a few
// absorptions (the RGB σa) over θd nodes × a φ grid, the shape renderers precompute per material.
//
// N_p(φ) = ½ ∫_{−π/2}^{π/2} A(p, sin γ) cos γ D_β(φ − Φ(p, γ)) dγ by one symmetric quadrature rule
// per θd shared by every lobe and σa (Φ, Fresnel and the path length computed once per node; only
// T^p depends on σa; R's amplitude f does not, so R is summed once for all channels). The rule is
// Gauss–Legendre of order 2m transplanted by the Kosloff–Tal-Ezer map γ = (π/2) asin(αs)/asin(α)
// (Hale & Trefethen 2008): its nodes are nearly uniform in γ, so it resolves a Gaussian of width
// β/|dΦ/dγ| with about 2/π of the nodes plain Gauss–Legendre needs (material_np_nodes). Each lobe is
// then evaluated by spreading each node's Gaussian onto the periodic φ grid (narrow β) or from the
// Fourier coefficients C_n = Σ W A cos nΦ (wide β), whichever the work estimate says is cheaper.
// The lobe energies ∫N_p dφ = ½∫A dh are the same sums with D replaced by its integral 1.
// Materials of the same β per lobe (and η, path and grids) differ only in T^p, so one MaterialNp
// bakes all their channels at once (MaterialNpRequest::channels keeps each material's values
// those of a bake of its own, bit for bit).
//
// Exact and approximate: the quadrature is the only approximation besides the detector's window
// (cut where the Gaussian is below tolerance/2 of its peak) and the Fourier truncation
// (fourier_terms); the node count comes from a trapezoid-type bound for the Gaussian plus a floor
// for the Fresnel factor near grazing (η close to 1 needs more), calibrated against the adaptive
// reference and checked there in tests/test_material_np.cpp (≤ tolerance × the lobe peak).
#pragma once

#include <cstdint>
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

/// The nodes γ_i ∈ (0, π/2) of a transplanted rule (material_np_nodes) and their θd-independent
/// factors: weight = w_i cos γ_i with w_i the weight of ∫_0^{π/2} (the 2m-point rule on
/// [−π/2, π/2] folded onto its positive half).
struct TransplantedRule {
  std::vector<double> gamma, cos_gamma, sin_gamma, weight, cos_2gamma, sin_2gamma;
};
/// The rule of m nodes for the tolerance (Gauss–Legendre of order 2m by newton_gauss_legendre,
/// mapped by γ = (π/2) asin(αs)/asin(α), α from the tolerance).
TransplantedRule transplanted_rule(int m, double tolerance);

/// Rules shared by the MaterialNp of one bake, each (m, tolerance) built once (the materials of a
/// show share their θd axis and so their rules). Not thread-safe: build the MaterialNp on one thread.
class MaterialNpRules {
 public:
  const TransplantedRule& get(int m, double tolerance);

 private:
  std::map<std::pair<int, double>, TransplantedRule> rules_;
};

/// The fixed inputs of a per-material N_p bake.
struct MaterialNpRequest {
  double eta = 1.55;
  AbsorptionPath path = AbsorptionPath::chord;
  std::vector<double> betas;   ///< one detector width per explicit lobe p = 0 … size − 1
  std::vector<double> sigmas;  ///< σa per channel
  std::vector<double> thetas;  ///< θd nodes
  std::vector<double> phis;    ///< φ nodes (any; periodic grids take the spreading path)
  double tolerance = 1e-12;
  MaterialNpRules* rules = nullptr;  ///< optional: rules shared with other bakes (else built here)
  /// σa per material when `sigmas` holds several materials' channels one material after another
  /// (materials that share η, the path, β per lobe and the grids share every factor but T^p: one
  /// MaterialNp for all of them). Each (θd, lobe) chooses between spreading and the Fourier form
  /// for this many channels, so a material's values do not depend on which materials it is baked
  /// with (bit for bit: each channel's sums are the same operations either way). 0: sigmas.size().
  std::size_t channels = 0;
};

/// Nodes m (a multiple of 8) of the transplanted rule (2m points on [−π/2, π/2], m of them in
/// (0, π/2)) for N_p of lobe p with detector width β at the geometry's θd to the tolerance (relative
/// to the lobe's peak): the widest spacing π²α/(4m asin α) must resolve a Gaussian of width
/// σ = β / max|dΦ/dγ| (spacing ≤ π σ √(2 / ln(10/ε)), the trapezoid bound), plus 4; and at least
/// max(32, 12 + 12/√(η − 1)) × max(1, ln(1/ε)/ln(1e10)) for the Fresnel factor's rise near grazing.
int material_np_nodes(double beta, int p, const FiberGeometry& geometry, double tolerance);

class MaterialNp {
 public:
  /// Plans every (θd, lobe) and builds the transplanted rules it needs.
  explicit MaterialNp(MaterialNpRequest request);

  std::size_t theta_count() const { return r_.thetas.size(); }
  /// N_p of every lobe and σa at θd node t: out[(p · K + k) · n_phi + j], K = sigmas.size(); and,
  /// when `energies` is given, ½∫A dh of every lobe from the same nodes (within 1e−10 relative of
  /// lobe_energies with 256 nodes, tested): (*energies)[k · L + p], L = betas.size().
  void evaluate(std::size_t t, std::vector<double>& out, std::vector<double>* energies = nullptr) const;
  /// Why narrow detectors cannot take the spreading path on this φ grid (empty when they can).
  const std::string& note() const { return note_; }

  /// How (θd node t, lobe p) is evaluated: by spreading (true) or by Fourier coefficients.
  bool spreads(std::size_t t, int p) const { return spread_[t * r_.betas.size() + static_cast<std::size_t>(p)] != 0; }
  /// Nodes in (0, π/2) of θd node t's rule (shared by every lobe there).
  int nodes_at(std::size_t t) const { return m_[t]; }
  int fourier_terms_of(int p) const { return terms_[static_cast<std::size_t>(p)]; }
  /// Points of lobe p's spreading window (2R + 1; 0 on a grid that cannot spread).
  int window_of(int p) const { return window_[static_cast<std::size_t>(p)]; }

 private:
  // θd-independent factors of a rule's nodes γ ∈ (0, π/2).
  struct RuleNodes : TransplantedRule {
    // R (p = 0) spreads with Φ = −2γ, which does not depend on θd: its windows are computed once.
    std::vector<long> r_start;   // first padded-circle slot of each node's window
    std::vector<double> r_window;  // [i · run + j]
  };
  // A lobe's detector window on the periodic grid, anchored at the grid point j0 nearest to the
  // node's exit azimuth (d0 = φ_{j0} − Φ): g(d0 + jΔ) = g0 r^j c_j for |j| ≤ R, with
  // g0 = e^{−d0²/2β²}, r = e^{−d0Δ/β²}, c_j = e^{−j²Δ²/2β²} (once per lobe).
  struct Window {
    long R = 0;
    std::size_t run = 0;  // slots per node: 2R + 1, at least 8 (the extra slots add exact zeros)
    double inv2var = 0.0, norm = 0.0;
    bool recurrence = true;  // r^j c_j far from overflow; otherwise each point by its own exp
    std::vector<double> c;
    std::vector<std::uint32_t> fold;  // padded slot q → circle point (q − R) mod P
  };
  struct Row;  // one θd's node factors and scratch (material_np.cpp)
  void node_factors(std::size_t t, Row& row) const;
  void anchor_windows(std::size_t p, const double* centre, std::size_t m, Row& row) const;
  void window_values(std::size_t p, std::size_t i, const Row& row, double* win) const;
  void spread_lobe(std::size_t p, const RuleNodes& n, Row& row, std::vector<double>& out) const;
  void fourier_lobe(std::size_t p, const RuleNodes& n, Row& row, std::vector<double>& out) const;

  MaterialNpRequest r_;
  PeriodicGrid grid_;
  std::string note_;
  std::vector<char> spread_;         // [t · L + p]
  std::vector<int> m_, terms_, window_;
  std::vector<std::vector<double>> series_weight_;  // per lobe: (n ? 2 : 1) e^{−n²β²/2} / 2π
  std::vector<Window> windows_;                     // per lobe (periodic grids)
  std::map<int, RuleNodes> nodes_;
  std::vector<std::uint32_t> here_, mirror_;  // circle points of φ_j and −φ_j (periodic grids)
  int cos_terms_ = 0;
  std::vector<double> cos_table_;             // cos nφ_j as [n][j], n ≤ cos_terms_
  std::unique_ptr<CosineSeries> series_;      // instead of the table when it would be large
};

/// Gauss–Legendre nodes (ascending) and weights of order m on [−1, 1] by Newton's method on the
/// three-term recurrence from Tricomi's first guess, in double:
/// O(m²) work, a fraction of GaussLegendreRule's cost; agrees with it to ~1e−15 (tested).
void newton_gauss_legendre(int m, std::vector<double>& nodes, std::vector<double>& weights);

/// lobe_energies (lobe_energy.hpp) for every σa in `sigmas` at once: the node factors that do not
/// depend on σa (Fresnel, path length) are computed once. The same rule and integrand, so the
/// same values to rounding. out[k · lobes.size() + p].
void material_energies(double eta, double theta_d, AbsorptionPath path, std::span<const double> sigmas, LobeSet lobes,
                       const GaussLegendreRule& rule, std::vector<double>& out);

}  // namespace hairlut
