// A table representation of d'Eon's N_p with β and φ exact: the detector's Fourier coefficients
// C_n(θd, σa) of each lobe (azimuthal_fourier.hpp) tabulated at (θd, σa) nodes, interpolated along
// θd and σa, and summed with the exact detector weights and cos nφ:
//   N_p(φ; β, σa, θd) = (1/2π) [C_0 + 2 Σ_{n=1}^{N(β)} e^{−n²β²/2} C_n cos nφ],
// N(β) = fourier_terms(β, tolerance) ≤ the N stored for the narrowest detector β_min.
//
// Exact and approximate: at a node (θd, σa) the value is the library's Fourier series with C_n
// integrated to the quadrature tolerance, truncated after N(β) terms (an error below tolerance × the
// lobe's mean height C_0/2π), and rounded to the table's value type; between nodes the C_n are
// interpolated (Catmull–Rom or linear along θd and along σa), which is where the error is.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include <hairlut/physics/attenuation.hpp>

namespace bench {

struct FourierTableConfig {
  double eta = 1.55;
  hairlut::AbsorptionPath path = hairlut::AbsorptionPath::chord;
  int lobes = 4;            ///< p = 0 … lobes − 1
  double beta_min = 0.0;    ///< narrowest detector (radians); the table stores n = 0 … fourier_terms(beta_min, tolerance)
  double tolerance = 1e-4;  ///< truncation per lookup: 2 Σ_{n>N(β)} e^{−n²β²/2} ≤ tolerance
  double quadrature_tolerance = 1e-12;  ///< the C_n at the nodes (fourier_nodes)
  int theta_count = 64;     ///< θd nodes on [0, theta_max]
  double theta_max = 0.0;   ///< radians, < π/2
  bool theta_cos = true;    ///< nodes uniform in cos θd (else uniform in θd)
  int sigma_count = 32;     ///< σa nodes on [0, sigma_max]
  double sigma_max = 10.0;
  bool sigma_sqrt = true;   ///< nodes uniform in √σa (else uniform in σa)
  /// What the table stores: C_n itself; C_n / F with the lobe's least absorption
  /// F = e^{−p σa' ℓ_min(θd)} (ℓ_min the shortest internal segment, at the fibre's edge) factored
  /// out and multiplied back exactly at lookup; or C_0 / F and the ratios C_n / C_0 (n ≥ 1).
  enum class Store { raw, absorption, ratio } store = Store::absorption;
  bool cubic = true;        ///< Catmull–Rom along θd and σa (else linear)
};

/// Σ_{n=0}^{N(β)} w_n a_n cos nφ / 2π with w_0 = 1, w_n = 2 e^{−n²β²/2}: the weights by a
/// two-term recurrence, the cosines by Clenshaw's recurrence; N(β) = min(a.size() − 1,
/// fourier_terms(β, tolerance)), found by the same tail bound. Not clamped.
double fourier_series(std::span<const double> a, double beta, double phi, double tolerance);
/// N(β) for the same bound: the smallest N with 2 e^{−(N+1)²β²/2} ≤ ½ tolerance (1 − e^{−(2N+3)β²/2}).
int fourier_series_terms(double beta, double tolerance, int max_terms);

/// The tabulated C_n of every lobe, in value type T (float as a renderer stores it; double for checks).
template <class T>
class FourierTable {
 public:
  /// Integrates the C_n at every node. Throws DomainError naming the field for a bad config.
  explicit FourierTable(const FourierTableConfig& config);

  /// N_p of lobe p at (β, σa, θd, φ), clamped at 0 (as the baker's tables). θd is folded to |θd|
  /// and clamped to [0, theta_max], σa to [0, sigma_max].
  double value(int p, double beta, double sigma_a, double theta_d, double phi) const;

  int terms() const { return terms_; }  ///< stored terms per node (N + 1)
  std::size_t entries_per_lobe() const { return static_cast<std::size_t>(terms_) * config_.theta_count * config_.sigma_count; }
  std::size_t bytes() const { return data_.size() * sizeof(T); }
  double theta_node(int i) const;
  double sigma_node(int k) const;
  const FourierTableConfig& config() const { return config_; }

  static constexpr int kMaxTerms = 2048;

 private:
  double absorption(int p, double sigma_a, double cos_theta_d) const;
  FourierTableConfig config_;
  int terms_ = 0;
  std::vector<T> data_;  // [p][θd node][σa node][n]
};

extern template class FourierTable<float>;
extern template class FourierTable<double>;

}  // namespace bench
