#include "hairlut/melanin.hpp"

#include <array>
#include <cmath>
#include <sstream>
#include <string>

#include "hairlut/error.hpp"

namespace hairlut {
namespace detail {
extern const char* const cie1931_2deg_5nm_csv;  // generated from data/cie1931_2deg_5nm.csv
extern const char* const cie_d65_5nm_csv;       // generated from data/cie_d65_5nm.csv
}  // namespace detail

namespace {

// Rows of numbers from an embedded CSV (comment lines start with '#', one header line).
std::vector<std::vector<double>> parse_csv(const char* text, std::size_t columns) {
  std::vector<std::vector<double>> rows;
  std::istringstream in(text);
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
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

}  // namespace

Rgb melanin_sigma_a_rgb(double eumelanin, double pheomelanin) {
  check_concentrations(eumelanin, pheomelanin);
  return {eumelanin * 0.419 + pheomelanin * 0.187, eumelanin * 0.697 + pheomelanin * 0.4,
          eumelanin * 1.37 + pheomelanin * 1.05};
}

Rgb srgb_linear_from_xyz(double X, double Y, double Z) {
  return {3.2406 * X - 1.5372 * Y - 0.4986 * Z, -0.9689 * X + 1.8758 * Y + 0.0415 * Z, 0.0557 * X - 0.2040 * Y + 1.0570 * Z};
}

double eumelanin_absorption_mm(double lambda_nm) { return 6.6e10 * std::pow(lambda_nm, -3.33); }
double pheomelanin_absorption_mm(double lambda_nm) { return 2.9e14 * std::pow(lambda_nm, -4.75); }

SpectralMelanin SpectralMelanin::builtin() { return builtin(Options{}); }

SpectralMelanin SpectralMelanin::builtin(Options options) {
  require_positive("path_length", options.path_length);
  SpectralMelanin m;
  const auto cmf = parse_csv(detail::cie1931_2deg_5nm_csv, 4);
  const auto d65 = parse_csv(detail::cie_d65_5nm_csv, 2);
  if (cmf.size() != d65.size() || cmf.empty()) throw DomainError("embedded CIE and D65 tables differ in length");
  for (std::size_t i = 0; i < cmf.size(); ++i) {
    if (cmf[i][0] != d65[i][0]) throw DomainError("embedded CIE and D65 tables use different wavelengths");
    m.lambda_.push_back(cmf[i][0]);
    m.xbar_.push_back(cmf[i][1]);
    m.ybar_.push_back(cmf[i][2]);
    m.zbar_.push_back(cmf[i][3]);
    m.d65_.push_back(d65[i][1]);
  }
  m.options_ = options;
  m.options_.spectral_scale = 1.0;
  m.white_ = m.unbalanced_rgb(0.0, 0.0, 1.0);  // linear sRGB of D65 itself
  if (options.spectral_scale > 0.0) {
    m.options_.spectral_scale = options.spectral_scale;
  } else {
    // Calibrate s so that the fitted eumelanin green cross-section is d'Eon's 0.697: the fitted
    // value grows monotonically with s, so bisect on log s.
    double lo = 1e-6, hi = 1.0;
    for (int it = 0; it < 200 && hi / lo > 1.0 + 1e-13; ++it) {
      const double mid = std::sqrt(lo * hi);
      (m.fit_with_scale(mid).eumelanin.g < 0.697 ? lo : hi) = mid;
    }
    m.options_.spectral_scale = std::sqrt(lo * hi);
  }
  return m;
}

// Riemann sum over the 5 nm samples (the CIE tables are defined on them); the constant step
// cancels in the normalization by the illuminant's Y.
Rgb SpectralMelanin::unbalanced_rgb(double ce, double cp, double length) const {
  double X = 0.0, Y = 0.0, Z = 0.0, Yw = 0.0;
  for (std::size_t i = 0; i < lambda_.size(); ++i) {
    const double sigma =
        options_.spectral_scale * (ce * eumelanin_absorption_mm(lambda_[i]) + cp * pheomelanin_absorption_mm(lambda_[i]));
    const double t = std::exp(-sigma * length) * d65_[i];
    X += t * xbar_[i];
    Y += t * ybar_[i];
    Z += t * zbar_[i];
    Yw += d65_[i] * ybar_[i];
  }
  return srgb_linear_from_xyz(X / Yw, Y / Yw, Z / Yw);
}

Rgb SpectralMelanin::transmittance_raw(double ce, double cp, double length, int* clamped) const {
  const Rgb rgb = unbalanced_rgb(ce, cp, length);
  auto balance = [&](double v, double white) {
    v /= white;
    if (v < 1e-30 || v > 1.0) {
      ++*clamped;
      return v < 1e-30 ? 1e-30 : 1.0;
    }
    return v;
  };
  return {balance(rgb.r, white_.r), balance(rgb.g, white_.g), balance(rgb.b, white_.b)};
}

Rgb SpectralMelanin::transmittance_rgb(double ce, double cp, double length) const {
  check_concentrations(ce, cp);
  require_positive("length", length);
  if (ce == 0.0 && cp == 0.0) return {1.0, 1.0, 1.0};
  int clamped = 0;
  return transmittance_raw(ce, cp, length, &clamped);
}

Rgb SpectralMelanin::sigma_a_rgb(double ce, double cp) const {
  const double L = options_.path_length;
  const Rgb t = transmittance_rgb(ce, cp, L);
  return {-std::log(t.r) / L, -std::log(t.g) / L, -std::log(t.b) / L};
}

SpectralMelanin::Fit SpectralMelanin::fit_with_scale(double scale) const {
  SpectralMelanin m = *this;
  m.options_.spectral_scale = scale;
  Fit fit;
  fit.spectral_scale = scale;
  double sum_sq = 0.0;
  int count = 0;
  for (int which = 0; which < 2; ++which) {
    double num[3] = {0, 0, 0}, den[3] = {0, 0, 0};
    std::vector<std::array<double, 4>> samples;
    for (int i = 0; i < 40; ++i) {
      const double c = 0.05 * std::pow(8.0 / 0.05, i / 39.0);
      const double L = m.options_.path_length;
      const Rgb t = which == 0 ? m.transmittance_raw(c, 0.0, L, &fit.clamped) : m.transmittance_raw(0.0, c, L, &fit.clamped);
      const double s[3] = {-std::log(t.r) / L, -std::log(t.g) / L, -std::log(t.b) / L};
      // Relative least squares through the origin: minimize Σ (c k / σ − 1)².
      for (int ch = 0; ch < 3; ++ch) {
        const double a = c / s[ch];
        num[ch] += a;
        den[ch] += a * a;
      }
      samples.push_back({c, s[0], s[1], s[2]});
    }
    const Rgb k{num[0] / den[0], num[1] / den[1], num[2] / den[2]};
    (which == 0 ? fit.eumelanin : fit.pheomelanin) = k;
    for (const auto& smp : samples) {
      const double kk[3] = {k.r, k.g, k.b};
      for (int ch = 0; ch < 3; ++ch) {
        const double rel = smp[0] * kk[ch] / smp[static_cast<std::size_t>(ch) + 1] - 1.0;
        sum_sq += rel * rel;
        ++count;
      }
    }
  }
  fit.rms_relative_error = std::sqrt(sum_sq / count);
  return fit;
}

SpectralMelanin::Fit SpectralMelanin::fit_rgb_cross_sections() const { return fit_with_scale(options_.spectral_scale); }

}  // namespace hairlut
