// Absorption of hair from its melanin concentrations: d'Eon 2011's RGB cross-sections, and the
// spectral model of Donner & Jensen 2006 seen through the CIE 1931 observer under D65.
#pragma once

#include <vector>

namespace hairlut {

/// A linear sRGB triple.
struct Rgb {
  double r = 0.0, g = 0.0, b = 0.0;
};

/// d'Eon 2011 §6.1 (also pbrt): σa = c_e (0.419, 0.697, 1.37) + c_p (0.187, 0.4, 1.05), per unit
/// fiber radius. Domain: concentrations finite and ≥ 0 (throws DomainError).
Rgb melanin_sigma_a_rgb(double eumelanin, double pheomelanin);

/// Linear sRGB from CIE XYZ with the IEC 61966-2-1 matrix (no white balance, no gamma):
/// R = 3.2406X − 1.5372Y − 0.4986Z, G = −0.9689X + 1.8758Y + 0.0415Z, B = 0.0557X − 0.2040Y + 1.0570Z.
/// Any finite input (out-of-gamut colours give negative components).
Rgb srgb_linear_from_xyz(double X, double Y, double Z);

/// Donner & Jensen 2006 eumelanin absorption, σ_e(λ) = 6.6×10¹⁰ λ^−3.33 mm⁻¹, λ in nm (finite, > 0).
double eumelanin_absorption_mm(double lambda_nm);
/// Donner & Jensen 2006 pheomelanin absorption, σ_p(λ) = 2.9×10¹⁴ λ^−4.75 mm⁻¹, λ in nm (finite, > 0).
double pheomelanin_absorption_mm(double lambda_nm);

/// The spectral melanin model over the CIE 1931 2° observer and D65 (380–780 nm in 5 nm steps,
/// tables embedded in the library, see data/README.md). Immutable after construction; copies are
/// independent and every member is const, so one instance may be shared between threads.
///
/// Absorption per unit fiber radius: σa(λ) = s · (c_e σ_e(λ) + c_p σ_p(λ)), s = spectral_scale.
/// A sample's colour is the linear sRGB of D65 light transmitted through a path of `length` radii,
///   T_c = RGB_c(Σ_λ D65 e^{−σa(λ) length} (x̄, ȳ, z̄)) / RGB_c(Σ_λ D65 (x̄, ȳ, z̄)),
/// i.e. white-balanced per channel (von Kries in linear sRGB) so that a non-absorbing sample is
/// exactly (1, 1, 1); the balance factors are white_rgb(), within 1e-3 of 1 because the matrix's
/// white point is D65. T_c is clamped to [1e−30, 1]: deep red spectra (dark hair) leave the sRGB
/// gamut in blue (and, darker still, in green), where the unclamped T_c would be ≤ 0.
/// The RGB-equivalent absorption over the reference path L = path_length is σa_c = −ln(T_c)/L.
class SpectralMelanin {
 public:
  struct Options {
    /// L in fiber radii (finite, > 0): 2 = one diameter, the TT path at h = 0.
    double path_length = 2.0;
    /// s in mm per fiber radius per unit concentration (finite, ≥ 0). 0 (the default) calibrates
    /// it: s is chosen so that the default fit (FitRange{}) gives eumelanin G = d'Eon's 0.697, which
    /// makes the concentrations d'Eon's/pbrt's units (s ≈ 0.01346 for L = 2).
    double spectral_scale = 0.0;
  };
  /// Concentrations of the fit: `count` (≥ 2) log-spaced values in [min, max], 0 < min < max finite.
  struct FitRange {
    double min_concentration = 0.05;
    double max_concentration = 8.0;  ///< pbrt's black hair
    int count = 40;
  };
  /// RGB cross-sections fitted to the spectral model (see fit_rgb_cross_sections).
  struct Fit {
    Rgb eumelanin, pheomelanin;       ///< k per unit concentration, per unit radius
    double spectral_scale = 0.0;      ///< the s used
    double rms_relative_error = 0.0;  ///< rms of c k_c / σa_c − 1 over the fitted samples
    double max_relative_error = 0.0;  ///< largest |c k_c / σa_c − 1| over the fitted samples
    int samples = 0;                  ///< (pigment, concentration, channel) samples fitted
    int clamped = 0;                  ///< samples left out because T_c was clamped to [1e−30, 1]
  };

  /// Builds the model from the embedded CIE and D65 tables. Throws DomainError for a path length
  /// that is not finite and > 0, or a spectral scale that is not finite and ≥ 0.
  static SpectralMelanin builtin(Options options);
  static SpectralMelanin builtin();  ///< with the default Options (calibrated scale, L = 2)

  /// The options in use; spectral_scale is the calibrated value when 0 was asked for.
  const Options& options() const { return options_; }

  /// T_c for concentrations c_e, c_p (finite, ≥ 0) over `length` radii (finite, > 0), clamped to
  /// [1e−30, 1]; adds the number of clamped channels (0–3) to *clamped when it is not null.
  Rgb transmittance_rgb(double eumelanin, double pheomelanin, double length, int* clamped = nullptr) const;
  /// T_c as transmittance_rgb but without the clamp: white-balanced linear sRGB, smooth in the
  /// concentrations, ≤ 0 where the transmitted colour lies outside the sRGB gamut (dark hair's
  /// blue). What the spectral melanin table stores; σa_c = −ln(max(T_c, 1e−30))/L.
  Rgb transmittance_unclamped(double eumelanin, double pheomelanin, double length) const;
  /// σa_c = −ln(T_c)/L with L = options().path_length: finite, in [0, ln(1e30)/L]. Same domain and
  /// clamp count as transmittance_rgb.
  Rgb sigma_a_rgb(double eumelanin, double pheomelanin, int* clamped = nullptr) const;

  /// Per-channel slopes k_c with σa_c(c) ≈ c k_c for pure eumelanin and for pure pheomelanin:
  /// k_c = argmin Σ_i (c_i k / σa_c(c_i) − 1)², i.e. relative least squares in σa (the same as in
  /// log-transmittance, ln T = −σa L), so that light and dark samples count alike; absolute least
  /// squares would be ruled by the darkest samples, whose blue is distorted by the gamut boundary.
  /// Samples whose T_c was clamped carry no information (their σa is the clamp's ln(1e30)/L) and
  /// are left out and counted. Throws DomainError for a bad range, or one that leaves a channel no
  /// unclamped sample.
  Fit fit_rgb_cross_sections(FitRange range) const;
  Fit fit_rgb_cross_sections() const;  ///< over the default FitRange (0.05 … 8, 40 samples)

  /// The linear sRGB of unattenuated D65 normalized to Y = 1, before white balance (the divisors).
  const Rgb& white_rgb() const { return white_; }
  /// The embedded tables: wavelengths (nm), CIE 1931 2° x̄, ȳ, z̄, D65 relative power.
  const std::vector<double>& wavelengths_nm() const { return lambda_; }
  const std::vector<double>& xbar() const { return xbar_; }
  const std::vector<double>& ybar() const { return ybar_; }
  const std::vector<double>& zbar() const { return zbar_; }
  const std::vector<double>& d65() const { return d65_; }

 private:
  SpectralMelanin() = default;
  Rgb unbalanced_rgb(double eumelanin, double pheomelanin, double length) const;
  Rgb transmittance_unchecked(double eumelanin, double pheomelanin, double length, bool* clamped3) const;  // flags per channel
  Fit fit_with_scale(double scale, const FitRange& range, bool eumelanin_green_only) const;

  Options options_;
  std::vector<double> lambda_, xbar_, ybar_, zbar_, d65_;
  std::vector<double> sigma_e_, sigma_p_;  // σ_e(λ), σ_p(λ) in mm⁻¹ at the table's wavelengths
  Rgb white_;                              // RGB of unattenuated D65 with Y = 1 (per-channel white balance)
};

}  // namespace hairlut
