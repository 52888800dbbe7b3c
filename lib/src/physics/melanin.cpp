#include "hairlut/physics/melanin.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "hairlut/util/error.hpp"

namespace hairlut {
namespace detail {
extern const char* const cie1931_2deg_5nm_csv;  // generated from data/cie1931_2deg_5nm.csv
extern const char* const cie_d65_5nm_csv;       // generated from data/cie_d65_5nm.csv
}  // namespace detail

namespace {

constexpr double kMinTransmittance = 1e-30;  // T_c clamp (ln(1e30) ≈ 69.1)
constexpr double kDeonEumelaninGreen = 0.697;

// Rows of numbers from an embedded CSV (comment lines start with '#', one header line).
std::vector<std::vector<double>> parse_csv(const char* text, std::size_t columns) {
  std::vector<std::vector<double>> rows;
  std::istringstream in(text);
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::vector<double> row;
    std::istringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) row.push_back(std::stod(field));
    if (row.size() != columns) throw DomainError("embedded spectral table has a malformed row: " + line);
    rows.push_back(row);
  }
  return rows;
}

void check_concentrations(double ce, double cp) {
  require_non_negative("eumelanin", ce);
  require_non_negative("pheomelanin", cp);
}

// T = value / white clamped to [1e-30, 1]; sets *was_clamped when it clamps.
double balance(double value, double white, bool* was_clamped) {
  const double t = value / white;
  if (t >= kMinTransmittance && t <= 1.0) return t;
  *was_clamped = true;
  return t > 1.0 ? 1.0 : kMinTransmittance;  // t ≤ 0 (out of gamut) or underflow
}

}  // namespace

Rgb melanin_sigma_a_rgb(double eumelanin, double pheomelanin) {
  check_concentrations(eumelanin, pheomelanin);
  return {eumelanin * 0.419 + pheomelanin * 0.187, eumelanin * 0.697 + pheomelanin * 0.4,
          eumelanin * 1.37 + pheomelanin * 1.05};
}

Rgb srgb_linear_from_xyz(double X, double Y, double Z) {
  return {3.2406 * X - 1.5372 * Y - 0.4986 * Z, -0.9689 * X + 1.8758 * Y + 0.0415 * Z, 0.0557 * X - 0.2040 * Y + 1.0570 * Z};
}

double eumelanin_absorption_mm(double lambda_nm) {
  require_positive("lambda_nm", lambda_nm);
  return 6.6e10 * std::pow(lambda_nm, -3.33);
}
double pheomelanin_absorption_mm(double lambda_nm) {
  require_positive("lambda_nm", lambda_nm);
  return 2.9e14 * std::pow(lambda_nm, -4.75);
}

SpectralMelanin SpectralMelanin::builtin() { return builtin(Options{}); }

SpectralMelanin SpectralMelanin::builtin(Options options) {
  require_positive("path_length", options.path_length);
  require_non_negative("spectral_scale", options.spectral_scale);
  SpectralMelanin m;
  const auto cmf = parse_csv(detail::cie1931_2deg_5nm_csv, 4);
  const auto d65 = parse_csv(detail::cie_d65_5nm_csv, 2);
  if (cmf.size() != d65.size() || cmf.size() < 2) throw DomainError("embedded CIE and D65 tables differ in length");
  for (std::size_t i = 0; i < cmf.size(); ++i) {
    if (cmf[i][0] != d65[i][0]) throw DomainError("embedded CIE and D65 tables use different wavelengths");
    // The sums below are Riemann sums on a uniform grid: the step cancels in the normalization.
    if (i > 0 && cmf[i][0] - cmf[i - 1][0] != cmf[1][0] - cmf[0][0])
      throw DomainError("embedded CIE table is not uniformly spaced in wavelength");
    m.lambda_.push_back(cmf[i][0]);
    m.xbar_.push_back(cmf[i][1]);
    m.ybar_.push_back(cmf[i][2]);
    m.zbar_.push_back(cmf[i][3]);
    m.d65_.push_back(d65[i][1]);
    m.sigma_e_.push_back(eumelanin_absorption_mm(cmf[i][0]));
    m.sigma_p_.push_back(pheomelanin_absorption_mm(cmf[i][0]));
  }
  m.options_ = options;
  m.white_ = m.unbalanced_rgb(0.0, 0.0, 1.0);  // linear sRGB of D65 itself (Y = 1)
  if (options.spectral_scale == 0.0) {
    // Calibrate s so that the fitted eumelanin green cross-section is d'Eon's 0.697. σa depends on
    // s c only, so the fitted slope grows with s (a sample dropping out at the gamut boundary can
    // make it jump); bisect on log s.
    double lo = 1e-6, hi = 1.0;
    for (int it = 0; it < 200 && hi / lo > 1.0 + 1e-14; ++it) {
      const double mid = std::sqrt(lo * hi);
      (m.fit_with_scale(mid, FitRange{}, true).eumelanin.g < kDeonEumelaninGreen ? lo : hi) = mid;
    }
    m.options_.spectral_scale = std::sqrt(lo * hi);
  }
  return m;
}

// XYZ of D65 light after e^{−σa(λ) length}, normalized to the Y of D65 itself, then linear sRGB.
// Riemann sum over the 5 nm samples (the CIE tables are defined on them).
Rgb SpectralMelanin::unbalanced_rgb(double ce, double cp, double length) const {
  const double s = options_.spectral_scale;
  double X = 0.0, Y = 0.0, Z = 0.0, Yw = 0.0;
  for (std::size_t i = 0; i < lambda_.size(); ++i) {
    const double t = std::exp(-s * (ce * sigma_e_[i] + cp * sigma_p_[i]) * length) * d65_[i];
    X += t * xbar_[i];
    Y += t * ybar_[i];
    Z += t * zbar_[i];
    Yw += d65_[i] * ybar_[i];
  }
  return srgb_linear_from_xyz(X / Yw, Y / Yw, Z / Yw);
}

Rgb SpectralMelanin::transmittance_unchecked(double ce, double cp, double length, bool* clamped3) const {
  // No shortcut for c = 0: the clear sample goes through the same sums as white_, so the white
  // balance gives exactly 1.
  const Rgb rgb = unbalanced_rgb(ce, cp, length);
  return {balance(rgb.r, white_.r, &clamped3[0]), balance(rgb.g, white_.g, &clamped3[1]),
          balance(rgb.b, white_.b, &clamped3[2])};
}

Rgb SpectralMelanin::transmittance_rgb(double ce, double cp, double length, int* clamped) const {
  check_concentrations(ce, cp);
  require_positive("length", length);
  bool flags[3] = {false, false, false};
  const Rgb t = transmittance_unchecked(ce, cp, length, flags);
  if (clamped) *clamped += int{flags[0]} + int{flags[1]} + int{flags[2]};
  return t;
}

Rgb SpectralMelanin::transmittance_unclamped(double ce, double cp, double length) const {
  check_concentrations(ce, cp);
  require_positive("length", length);
  const Rgb rgb = unbalanced_rgb(ce, cp, length);
  return {rgb.r / white_.r, rgb.g / white_.g, rgb.b / white_.b};
}

Rgb SpectralMelanin::sigma_a_rgb(double ce, double cp, int* clamped) const {
  const double L = options_.path_length;
  const Rgb t = transmittance_rgb(ce, cp, L, clamped);
  // −ln(1) is −0.0; + 0.0 makes it +0.0.
  return {-std::log(t.r) / L + 0.0, -std::log(t.g) / L + 0.0, -std::log(t.b) / L + 0.0};
}

SpectralMelanin::Fit SpectralMelanin::fit_with_scale(double scale, const FitRange& range, bool eumelanin_green_only) const {
  SpectralMelanin m = *this;
  m.options_.spectral_scale = scale;
  const double L = m.options_.path_length;
  Fit fit;
  fit.spectral_scale = scale;
  const char* const pigment_names[2] = {"eumelanin", "pheomelanin"};
  const char* const channel_names[3] = {"R", "G", "B"};
  double sum_sq = 0.0;
  for (int which = 0; which < (eumelanin_green_only ? 1 : 2); ++which) {
    // Unclamped (c, σa_c) samples per channel.
    std::array<std::vector<std::array<double, 2>>, 3> samples;
    for (int i = 0; i < range.count; ++i) {
      const double c = range.min_concentration *
                       std::pow(range.max_concentration / range.min_concentration, i / (range.count - 1.0));
      bool flags[3] = {false, false, false};
      const Rgb t = which == 0 ? m.transmittance_unchecked(c, 0.0, L, flags) : m.transmittance_unchecked(0.0, c, L, flags);
      const double tc[3] = {t.r, t.g, t.b};
      for (std::size_t ch = 0; ch < 3; ++ch) {
        if (flags[ch]) {
          ++fit.clamped;
          continue;
        }
        samples[ch].push_back({c, -std::log(tc[ch]) / L});
      }
    }
    double k[3] = {0.0, 0.0, 0.0};
    for (std::size_t ch = 0; ch < 3; ++ch) {
      if (eumelanin_green_only && ch != 1) continue;
      // Relative least squares through the origin: minimize Σ (c k / σ − 1)² → k = Σ a / Σ a², a = c/σ.
      double num = 0.0, den = 0.0;
      for (const auto& [c, sigma] : samples[ch]) {
        const double a = c / sigma;
        num += a;
        den += a * a;
      }
      if (samples[ch].empty() || !(den > 0.0)) {
        if (eumelanin_green_only) {  // calibration: s too large, everything clamped
          fit.eumelanin.g = std::numeric_limits<double>::infinity();
          return fit;
        }
        throw DomainError(std::string("fit range leaves no unclamped sample for ") + pigment_names[which] + " " +
                          channel_names[ch] + " (lower max_concentration or min_concentration)");
      }
      k[ch] = num / den;
      for (const auto& [c, sigma] : samples[ch]) {
        const double rel = c * k[ch] / sigma - 1.0;
        sum_sq += rel * rel;
        fit.max_relative_error = std::max(fit.max_relative_error, std::abs(rel));
        ++fit.samples;
      }
    }
    (which == 0 ? fit.eumelanin : fit.pheomelanin) = Rgb{k[0], k[1], k[2]};
  }
  fit.rms_relative_error = std::sqrt(sum_sq / fit.samples);
  return fit;
}

SpectralMelanin::Fit SpectralMelanin::fit_rgb_cross_sections(FitRange range) const {
  require_positive("min_concentration", range.min_concentration);
  require_greater("max_concentration", range.max_concentration, range.min_concentration,
                  "must be a finite number > min_concentration");
  if (range.count < 2) throw_domain_error("count", "must be >= 2", static_cast<long long>(range.count));
  return fit_with_scale(options_.spectral_scale, range, false);
}

SpectralMelanin::Fit SpectralMelanin::fit_rgb_cross_sections() const { return fit_rgb_cross_sections(FitRange{}); }

}  // namespace hairlut
