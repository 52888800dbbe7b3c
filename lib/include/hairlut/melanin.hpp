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
Rgb srgb_linear_from_xyz(double X, double Y, double Z);

/// Donner & Jensen 2006 absorption spectra in mm⁻¹ at wavelength λ in nm:
/// eumelanin 6.6×10¹⁰ λ^−3.33, pheomelanin 2.9×10¹⁴ λ^−4.75.
double eumelanin_absorption_mm(double lambda_nm);
double pheomelanin_absorption_mm(double lambda_nm);

/// The spectral melanin model over the CIE 1931 2° observer and D65 (380–780 nm in 5 nm steps,
/// tables embedded in the library). Immutable after construction.
///
/// Absorption per unit fiber radius: σa(λ) = s · (c_e σ_e(λ) + c_p σ_p(λ)), s = spectral_scale.
/// A sample's colour is the linear sRGB of D65 light transmitted through a path of L radii,
/// T_c = RGB_c(∫ D65 e^{−σa(λ) L} x̄ȳz̄ dλ) / RGB_c(∫ D65 x̄ȳz̄ dλ): white-balanced per channel so
/// that a clear sample is exactly (1, 1, 1). Its RGB-equivalent absorption is σa_c = −ln(T_c)/L.
class SpectralMelanin {
 public:
  struct Options {
    double path_length = 2.0;     ///< L in fiber radii (2 = one diameter, the TT path at h = 0)
    double spectral_scale = 0.0;  ///< s (mm per radius); ≤ 0 calibrates it: fitted eumelanin G = d'Eon's 0.697
  };
  /// RGB cross-sections fitted to the spectral model (see fit_rgb_cross_sections).
  struct Fit {
    Rgb eumelanin, pheomelanin;      ///< per unit concentration, per unit radius
    double spectral_scale = 0.0;     ///< the s used
    double rms_relative_error = 0.0; ///< of the linear fit over the fitted concentrations
    int clamped = 0;                 ///< transmittances clamped to [1e−30, 1] (out of gamut or underflow)
  };

  /// Builds the model from the embedded CIE and D65 tables. Throws DomainError for L ≤ 0.
  static SpectralMelanin builtin(Options options);
  static SpectralMelanin builtin();  ///< with the default Options

  const Options& options() const { return options_; }
  /// T_c for concentrations (c_e, c_p) ≥ 0 over `length` radii (> 0).
  Rgb transmittance_rgb(double eumelanin, double pheomelanin, double length) const;
  /// σa_c = −ln(T_c)/L with L = options().path_length; finite and ≥ 0.
  Rgb sigma_a_rgb(double eumelanin, double pheomelanin) const;
  /// Linear RGB cross-sections k_c that best give σa_c(c) ≈ c k_c for pure eumelanin and pure
  /// pheomelanin over 40 log-spaced concentrations in [0.05, 8], in the relative least-squares
  /// sense (relative error counts equally for light and dark hair).
  Fit fit_rgb_cross_sections() const;

  const std::vector<double>& wavelengths_nm() const { return lambda_; }

 private:
  SpectralMelanin() = default;
  Rgb unbalanced_rgb(double eumelanin, double pheomelanin, double length) const;
  Rgb transmittance_raw(double eumelanin, double pheomelanin, double length, int* clamped) const;
  Fit fit_with_scale(double scale) const;

  Options options_;
  std::vector<double> lambda_, xbar_, ybar_, zbar_, d65_;
  Rgb white_;  // RGB of unattenuated D65 (per-channel white balance)
};

}  // namespace hairlut
