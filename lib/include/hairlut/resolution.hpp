// Table resolution from a target error: how many nodes each axis of a generic N_p table needs so
// that multilinear interpolation stays within a given error relative to the lobe peak, with the
// smallest table, and the error the baked table then achieves.
#pragma once

#include <cstddef>
#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "hairlut/attenuation.hpp"
#include "hairlut/grid.hpp"
#include "hairlut/quadrature.hpp"
#include "hairlut/tables.hpp"

namespace hairlut {

struct ResolutionPlan {
  std::vector<GridAxis> axes;                        ///< beta, sigma_a, theta_d, phi with the chosen counts
  std::map<std::string, double> axis_error;          ///< predicted interpolation error per axis (at the chosen count)
  std::map<std::string, double> slope;               ///< local error ∝ count^−slope per axis, where interpolated
  double predicted_error = 0.0;                      ///< sum of the per-axis errors
  std::size_t entries = 0;                           ///< entries per lobe
};

/// The interpolation error of one N_p axis at a given node count: linear interpolation in the
/// axis's mapped coordinate at the cell midpoints, the other axes at a fixed set of probes, lobes
/// R, TT, TRT, relative to each lobe's peak over the domain of the axes (exact N_p by the Fourier
/// method at 1e−12).
class AxisErrorProbe {
 public:
  /// axes: beta, sigma_a, theta_d, phi (ranges, spacing, placement used; counts ignored).
  AxisErrorProbe(std::vector<GridAxis> axes, double eta, AbsorptionPath path, int lobes, int probes = 6);
  /// Largest error relative to the lobe peak of axis k (0 … 3) with `count` nodes.
  double error(std::size_t k, int count) const;

 private:
  std::vector<GridAxis> axes_;
  double eta_;
  AbsorptionPath path_;
  int lobes_;
  std::vector<std::array<double, 4>> probes_;
  std::vector<double> peak_;
  std::shared_ptr<GaussLegendreCache> rules_;
};

/// Chooses node counts for the N_p axes (beta, sigma_a, theta_d, phi: ranges, spacing and placement
/// as given; given counts are lower bounds) so that the predicted off-node error relative to the
/// lobe peak is at most `target`. The errors of the axes add; with second-order interpolation on
/// every axis the smallest table (minimum of Σ ln n under Σ e_k = target, Lagrange) gives each
/// axis the same share. An axis's error is measured (midpoints of the mapped coordinate, exact
/// N_p, a fixed set of probes over the other axes, lobes R, TT, TRT) at 16, 32, 64, ... nodes until
/// it is within its share, and the count is interpolated in log–log between the last two.
/// Throws DomainError when the table would exceed max_entries per lobe.
ResolutionPlan plan_np_resolution(const std::vector<GridAxis>& axes, double eta, AbsorptionPath path, int lobes, double target,
                                  std::size_t max_entries = std::size_t{1} << 31);

/// The error a baked table achieves where a renderer samples (sampled_error.hpp).
struct AchievedError {
  double worst = 0.0;          ///< largest over the N_p tables
  double p99 = 0.0;            ///< largest 99th percentile over the N_p tables
  std::string worst_table;     ///< where the worst occurs
  std::size_t points = 0;      ///< points measured, all tables together
  std::map<std::string, std::pair<double, double>> per_table;  ///< path → (worst, p99)
  std::string denominator;     ///< the denominator of the lobes' errors, in words
};

/// The error of every lobe's N_p table of group "np" (R, TT, TRT, TRRT, ...; not the residual,
/// which the validator judges with the energies) at `samples` random points per table over its
/// declared domain, relative to the peak over φ of the same (β, σa, θd) slice floored at 1e−3 × the
/// white fibre's: measure_sampled_error with table_truth, as validate-hair-luts's
/// accuracy_max_rel / accuracy_p99_rel. Deterministic for any thread count.
AchievedError measure_np_error(const TableSet& set, double eta, AbsorptionPath path, std::size_t samples = 4096, int threads = 0);

}  // namespace hairlut
