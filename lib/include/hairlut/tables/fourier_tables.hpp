// N_p in its Fourier representation as tables (docs/table-format.md, "N_p as a Fourier series"):
// per lobe, the coefficients c_n = C_n / F of the detector's cosine series over (θd, σa, n), with
// the attributes that make a file self-describing, their reader, the domain (β, σa, θd, φ) over
// which such a table defines N_p, and the library's own evaluation of it.
//
//   N_p(φ; β, σa, θd) = F(σa, θd) / 2π · [c_0 + 2 Σ_{n=1}^{N(β)} e^{−n²β²/2} c_n cos nφ]
//
// The evaluation here is the plain form of that sum (each axis's taps by sampler.hpp's reference
// taps(), every cos nφ and e^{−n²β²/2} by the standard library, N(β) by the tail bound), written
// independently of sampler::FourierNp (fourier_np.hpp), which renderers use and which the tests
// hold against it.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hairlut/sampler/fourier_np.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

inline constexpr const char* kFourierGroup = "np_fourier";               ///< np_fourier/<lobe>, np_fourier/residual
inline constexpr const char* kFourierQuantity = "fourier_coefficient";  ///< c_n = C_n / F (dimensionless)

/// Whether t is a table of the Fourier representation (group np_fourier).
bool is_fourier_table(const Table& t);
/// Whether the set holds N_p in the Fourier representation.
bool has_fourier_np(const TableSet& set);

/// The n axis of a table storing `terms` coefficients: explicit nodes 0 … terms − 1, not interpolated.
GridAxis fourier_n_axis(int terms);

/// What a Fourier table's attributes record: the series, its truncation and the factor F.
struct FourierTableInfo {
  sampler::FourierNpParams params;
  double beta_max = 0.0;  ///< upper end of the β range the table was baked and validated for [rad]
  std::string lobe;       ///< "R", "TT", ..., or "residual"
  int p = 0;              ///< the lobe's p (the residual: its first lobe P)
};
/// The attributes of a Fourier table (every formula it needs, in words, and the constants).
nlohmann::ordered_json fourier_attributes(const FourierTableInfo& info, const std::string& absorption_path);
/// The info recorded in t's attributes and axes. Throws DomainError naming the table and the
/// attribute when one is missing or out of its domain, or the axes are not (theta_d, sigma_a, n).
FourierTableInfo fourier_table_info(const Table& t);

/// The axes (beta, sigma_a, theta_d, phi) over which t defines N_p: β log-spaced over
/// [beta_min, beta_max] (8 nodes), σa and θd as stored, φ even over [0, π] (13 nodes). β and φ are
/// exact: their nodes only delimit the cells a report bins errors in. The residual: (sigma_a, theta_d).
std::vector<GridAxis> fourier_domain(const Table& t);
/// A table standing for what t defines, without values: t's path, quantity N_p, t's lobe
/// attributes (lobe, p or p_from), axes fourier_domain(t). The sampled-error measure draws its
/// points over it and finds the reference by it (table_truth), as for a tensor table.
Table fourier_domain_table(const Table& t);
/// N_p of t at a point x of fourier_domain(t) as a renderer reads it: sampler::FourierNp in double
/// arithmetic over t's stored values (t must outlive the function). Safe to call from many threads.
std::function<double(const std::vector<double>&)> fourier_point_function(const Table& t);

/// N_p of a Fourier table evaluated by the library (double, plain sums). Points into t's values
/// (float32 or float64): t must outlive it.
class FourierNpReference {
 public:
  explicit FourierNpReference(const Table& t);
  /// N_p [1/rad] at (β, σa, θd, φ), clamped at 0; NaN for a NaN argument. Domain and edges as
  /// sampler::FourierNp: θd → |θd|, θd and σa clamped to their axes, β below beta_min reads beta_min.
  double operator()(double beta, double sigma_a, double theta_d, double phi) const;
  /// E = ∫N_p dφ = c_0 F at (σa, θd) (the residual's energy for the residual table).
  double energy(double sigma_a, double theta_d) const;
  /// N(β): the last n summed (the tail bound, at most terms − 1).
  int series_terms(double beta) const;
  const FourierTableInfo& info() const { return info_; }

 private:
  // Σ over the taps of c_n at (σa, θd), n = 0 … count − 1, and F there.
  void coefficients(double sigma_a, double theta_d, int count, std::vector<double>& c, double& F) const;
  const Table* table_;
  FourierTableInfo info_;
  sampler::PreparedAxis theta_, sigma_;
};

}  // namespace hairlut
