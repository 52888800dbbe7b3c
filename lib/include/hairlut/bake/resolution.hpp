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

#include "hairlut/bake/config.hpp"
#include "hairlut/bake/sampled_error.hpp"
#include "hairlut/physics/attenuation.hpp"
#include "hairlut/tables/grid.hpp"
#include "hairlut/util/quadrature.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

struct ResolutionPlan {
  std::vector<GridAxis> axes;                        ///< beta, sigma_a, theta_d, phi with the chosen counts
  std::map<std::string, double> axis_error;          ///< predicted interpolation error per axis (at the chosen count)
  std::map<std::string, double> slope;               ///< local error ∝ count^−slope per axis, where interpolated
  double predicted_error = 0.0;                      ///< sum of the per-axis errors
  std::size_t entries = 0;                           ///< entries per lobe
};

/// The interpolation error of one N_p axis at a given node count, as a renderer sees it: at
/// probe points drawn uniformly over the domain (log-uniform on log axes), the axis's own
/// interpolation (linear, cubic or geometric in its mapped coordinate) from the exact values at
/// its nodes with the other coordinates exact, against direct evaluation (the Fourier method at
/// 1e−12), relative to the peak over φ of the true slice at the same (β, σa, θd), floored at 1e−3
/// of the white fiber's peak (docs/conventions.md). With normalize_energy the table holds
/// N_p / E_p: the nodes' shapes are interpolated and multiplied by the exact energy at the point.
/// Lobes R, TT, TRT and TRRT (as many as `lobes`).
class AxisErrorProbe {
 public:
  /// What the nodes hold besides N_p: N_p itself; its shape N_p / E_p (times the exact E_p at the
  /// point); or N_p / F with F the lobe's least absorption (least_absorption, attenuation.hpp; times
  /// F at the point): the Fourier representation's coefficients, whose interpolation along one axis
  /// is that of N_p / F (the series is linear in them, with weights that depend on β and φ only).
  enum class Nodes { n_p, shape, over_least_absorption };
  /// axes: beta, sigma_a, theta_d, phi (ranges, spacing, placement, interpolation used; counts
  /// ignored); probes: (σa, θd) slabs, each with 4 β and 16 φ.
  AxisErrorProbe(std::vector<GridAxis> axes, double eta, AbsorptionPath path, int lobes, int probes = 24, bool normalize_energy = false);
  AxisErrorProbe(std::vector<GridAxis> axes, double eta, AbsorptionPath path, int lobes, int probes, Nodes nodes);
  /// Largest error relative to the local peak of axis k (0 … 3) with `count` nodes.
  double error(std::size_t k, int count) const;

 private:
  static constexpr std::size_t kBetas = 4, kPhis = 16;
  struct Slab {
    double sigma = 0.0, theta = 0.0;
    std::array<double, kBetas> betas{};
    std::array<double, kPhis> phis{};
    std::array<std::array<std::array<double, kPhis>, kBetas>, 4> truth{};
    std::array<std::array<double, kBetas>, 4> scale{};
    std::vector<double> energy;  ///< E_p or F_p at (σa, θd) (the nodes' divisor at the probe)
  };
  std::vector<double> exact_lists(const std::vector<double>& betas, const std::vector<double>& sigmas, const std::vector<double>& thetas,
                                  const std::vector<double>& phis) const;
  std::vector<double> divisors(double sigma, double theta) const;  ///< E_p or F_p per lobe at (σa, θd)

  std::vector<GridAxis> axes_;
  double eta_;
  AbsorptionPath path_;
  int lobes_;
  Nodes nodes_;
  std::vector<Slab> slabs_;
  std::shared_ptr<GaussLegendreCache> rules_;
  std::shared_ptr<const GaussLegendreRule> energy_rule_;
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
                                  std::size_t max_entries = std::size_t{1} << 31, bool normalize_energy = false);

/// The Fourier representation's counts for a target (tables.np.representation fourier).
struct FourierResolutionPlan {
  FourierNpConfig config;                     ///< the coefficients' axes with the chosen counts, β range, tolerance
  std::map<std::string, double> axis_error;   ///< predicted interpolation error along theta_d and sigma_a
  double predicted_error = 0.0;               ///< their sum plus the truncation bound (the tolerance)
  int terms = 0;                              ///< stored coefficients per node
  std::size_t entries = 0;                    ///< entries per lobe: terms × θd × σa
};

/// Chooses the θd and σa counts of Fourier tables (given counts are lower bounds; ranges, spacing
/// and interpolation as given) so that the predicted off-node error is at most `target`: the
/// truncation tolerance is a tenth of the target, and θd and σa share the rest equally, each count
/// found as plan_np_resolution finds one, by AxisErrorProbe with Nodes::over_least_absorption.
/// Throws DomainError when the table would exceed max_entries per lobe.
FourierResolutionPlan plan_fourier_resolution(const FourierNpConfig& bounds, double eta, AbsorptionPath path, int lobes, double target,
                                              std::size_t max_entries = std::size_t{1} << 31);

/// The error a baked table achieves where a renderer samples (sampled_error.hpp).
struct AchievedError {
  double worst = 0.0;          ///< largest over the N_p tables
  double p99 = 0.0;            ///< largest 99th percentile over the N_p tables
  std::string worst_table;     ///< where the worst occurs
  std::size_t points = 0;      ///< points measured (random and search), all tables together
  std::map<std::string, std::pair<double, double>> per_table;  ///< path → (worst, p99)
  std::string denominator;     ///< the denominator of the lobes' errors, in words
};

/// The error of every lobe's N_p table of group "np" (R, TT, TRT, TRRT, ...; not the residual,
/// which the validator judges with the energies), or of group "np_fourier" read through
/// sampler::FourierNp in double (over its domain, fourier_domain), relative to the peak over φ of
/// the same (β, σa, θd) slice floored at 1e−3 × the white fiber's (as validate-hair-luts's
/// accuracy_max_rel): the worst found by `samples` random points per table and the worst-point
/// search (SampledErrorOptions::search), on points the resolution plan did not probe (a seed of
/// their own per table, fixed so that a bake is reproducible). `worst` is the worst found, `p99`
/// that of the random points. Deterministic for any thread count.
AchievedError measure_np_error(const TableSet& set, double eta, AbsorptionPath path, std::size_t samples = kSampledErrorPoints, int threads = 0);

}  // namespace hairlut
