// Melanin absorption: the RGB model, the embedded CIE/D65 tables, the sRGB matrix, the spectral
// model (against an independent re-implementation from the CSV files) and its fitted RGB
// cross-sections against d'Eon 2011's.
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <hairlut/util/error.hpp>
#include <hairlut/physics/melanin.hpp>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "catch.hpp"

using namespace hairlut;

#ifndef HAIRLUT_DATA_DIR
#define HAIRLUT_DATA_DIR "data"
#endif

namespace {

const double kInf = std::numeric_limits<double>::infinity();
const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kMaxSigma2 = std::log(1e30) / 2.0;  // σa of a clamped channel with L = 2

// The numeric rows of one of the data/ CSV files (comments '#', one header line), read here
// independently of the library's parser.
std::vector<std::vector<double>> read_csv(const std::string& name) {
  std::ifstream in(std::string(HAIRLUT_DATA_DIR) + "/" + name);
  REQUIRE(in);
  std::vector<std::vector<double>> rows;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::vector<double> row;
    std::stringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) row.push_back(std::stod(field));
    rows.push_back(row);
  }
  return rows;
}

std::array<double, 3> as_array(const Rgb& c) { return {c.r, c.g, c.b}; }

// Independent reference: XYZ sums of D65 · e^{−s(c_e σ_e + c_p σ_p) L} over the CSV rows, the
// sRGB matrix of IEC 61966-2-1 written out here, and per-channel white balance.
struct Reference {
  std::vector<std::vector<double>> cmf = read_csv("cie1931_2deg_5nm.csv"), d65 = read_csv("cie_d65_5nm.csv");

  std::array<double, 3> xyz(double ce, double cp, double s, double L, bool weight_eumelanin = false) const {
    std::array<double, 3> v{0, 0, 0};
    for (std::size_t i = 0; i < cmf.size(); ++i) {
      const double l = cmf[i][0];
      const double se = 6.6e10 * std::pow(l, -3.33), sp = 2.9e14 * std::pow(l, -4.75);
      double w = d65[i][1] * std::exp(-s * (ce * se + cp * sp) * L);
      if (weight_eumelanin) w *= se;
      for (std::size_t k = 0; k < 3; ++k) v[k] += w * cmf[i][k + 1];
    }
    return v;
  }
  static std::array<double, 3> rgb(const std::array<double, 3>& v) {
    return {3.2406 * v[0] - 1.5372 * v[1] - 0.4986 * v[2], -0.9689 * v[0] + 1.8758 * v[1] + 0.0415 * v[2],
            0.0557 * v[0] - 0.2040 * v[1] + 1.0570 * v[2]};
  }
  std::array<double, 3> transmittance(double ce, double cp, double s, double L) const {
    const auto t = rgb(xyz(ce, cp, s, L)), w = rgb(xyz(0, 0, s, L));
    return {t[0] / w[0], t[1] / w[1], t[2] / w[2]};
  }
  // First order in c of pure eumelanin: σa_c(c) = c k0_c + O(c²), k0_c = s RGB_c(Σ D65 σ_e x̄ȳz̄) / RGB_c(Σ D65 x̄ȳz̄).
  std::array<double, 3> eumelanin_first_order(double s) const {
    const auto a = rgb(xyz(0, 0, s, 1, true)), w = rgb(xyz(0, 0, s, 1));
    return {s * a[0] / w[0], s * a[1] / w[1], s * a[2] / w[2]};
  }
};

}  // namespace

TEST_CASE("d'Eon's RGB cross-sections", "[melanin]") {
  const Rgb a = melanin_sigma_a_rgb(2.0, 0.5);
  CHECK(a.r == Approx(2.0 * 0.419 + 0.5 * 0.187).epsilon(1e-15));
  CHECK(a.g == Approx(2.0 * 0.697 + 0.5 * 0.4).epsilon(1e-15));
  CHECK(a.b == Approx(2.0 * 1.37 + 0.5 * 1.05).epsilon(1e-15));
  const Rgb e = melanin_sigma_a_rgb(1.0, 0.0), p = melanin_sigma_a_rgb(0.0, 1.0), z = melanin_sigma_a_rgb(0.0, 0.0);
  CHECK((e.r == 0.419 && e.g == 0.697 && e.b == 1.37));
  CHECK((p.r == 0.187 && p.g == 0.4 && p.b == 1.05));
  CHECK((z.r == 0.0 && z.g == 0.0 && z.b == 0.0));
  // Eumelanin and pheomelanin both absorb blue most and red least.
  CHECK((e.b > e.g && e.g > e.r));
  CHECK((p.b > p.g && p.g > p.r));
  CHECK_THROWS_AS(melanin_sigma_a_rgb(-1.0, 0.0), DomainError);
  CHECK_THROWS_AS(melanin_sigma_a_rgb(0.0, -1e-300), DomainError);
  CHECK_THROWS_AS(melanin_sigma_a_rgb(0.0, kNaN), DomainError);
  CHECK_THROWS_AS(melanin_sigma_a_rgb(kInf, 0.0), DomainError);
}

TEST_CASE("The embedded spectral tables are the shipped CSV files", "[melanin]") {
  const SpectralMelanin m = SpectralMelanin::builtin();
  const auto cmf = read_csv("cie1931_2deg_5nm.csv"), d65 = read_csv("cie_d65_5nm.csv");
  REQUIRE(cmf.size() == 81);
  REQUIRE(d65.size() == 81);
  REQUIRE(m.wavelengths_nm().size() == 81);
  REQUIRE(m.xbar().size() == 81);
  REQUIRE(m.d65().size() == 81);
  CHECK(m.wavelengths_nm().front() == 380.0);
  CHECK(m.wavelengths_nm().back() == 780.0);
  int mismatches = 0;
  for (std::size_t i = 0; i < 81; ++i) {
    const double l = 380.0 + 5.0 * static_cast<double>(i);
    if (m.wavelengths_nm()[i] != l || cmf[i][0] != l || d65[i][0] != l || m.xbar()[i] != cmf[i][1] ||
        m.ybar()[i] != cmf[i][2] || m.zbar()[i] != cmf[i][3] || m.d65()[i] != d65[i][1]) {
      ++mismatches;
      UNSCOPED_INFO("row " << i << " (" << l << " nm) differs");
    }
  }
  CHECK(mismatches == 0);
  // Spot values of the standard tables (CIE 15:2004; D65 is 100 at 560 nm).
  CHECK(m.ybar()[(555 - 380) / 5] == 1.0);
  CHECK(m.d65()[(560 - 380) / 5] == 100.0);
}

TEST_CASE("The sRGB matrix maps D65's chromaticity to neutral: D65 white is (1, 1, 1)", "[melanin]") {
  // D65 white point x = 0.3127, y = 0.3290 with Y = 1 (independent of the tabulated spectrum).
  const double x = 0.3127, y = 0.3290;
  const Rgb w = srgb_linear_from_xyz(x / y, 1.0, (1.0 - x - y) / y);
  CHECK(w.r == Approx(1.0).margin(1e-3));
  CHECK(w.g == Approx(1.0).margin(1e-3));
  CHECK(w.b == Approx(1.0).margin(1e-3));
  // The tabulated D65 under the tabulated observer has that chromaticity, so the per-channel white
  // balance of the spectral model is a correction of well under a percent.
  const Reference ref;
  const auto d = ref.xyz(0, 0, 0, 1);
  CHECK(d[0] / (d[0] + d[1] + d[2]) == Approx(0.3127).margin(2e-4));
  CHECK(d[1] / (d[0] + d[1] + d[2]) == Approx(0.3290).margin(2e-4));
  const SpectralMelanin m = SpectralMelanin::builtin();
  const Rgb white = m.white_rgb();
  CHECK(white.r == Approx(1.0).margin(2e-3));
  CHECK(white.g == Approx(1.0).margin(2e-3));
  CHECK(white.b == Approx(1.0).margin(2e-3));
  WARN("white balance divisors (linear sRGB of tabulated D65, Y = 1): " << white.r << ", " << white.g << ", " << white.b);
  // A non-absorbing sample is exactly white, whatever the length; its σa is exactly +0.
  for (double L : {0.01, 2.0, 7.0}) {
    const Rgb clear = m.transmittance_rgb(0.0, 0.0, L);
    CHECK((clear.r == 1.0 && clear.g == 1.0 && clear.b == 1.0));
  }
  const Rgb s0 = m.sigma_a_rgb(0.0, 0.0);
  CHECK((s0.r == 0.0 && s0.g == 0.0 && s0.b == 0.0));
  CHECK_FALSE((std::signbit(s0.r) || std::signbit(s0.g) || std::signbit(s0.b)));
  const Rgb tiny = m.transmittance_rgb(1e-12, 1e-12, 2.0);
  CHECK(tiny.r == Approx(1.0).epsilon(1e-9));
  CHECK(tiny.g == Approx(1.0).epsilon(1e-9));
  CHECK(tiny.b == Approx(1.0).epsilon(1e-9));
}

TEST_CASE("Spectral transmittance agrees with an independent evaluation from the CSV files", "[melanin]") {
  const SpectralMelanin m = SpectralMelanin::builtin();
  const Reference ref;
  const double s = m.options().spectral_scale;
  for (const auto& [ce, cp, L] : std::vector<std::array<double, 3>>{{0.3, 0.15, 2.0}, {1.3, 0.2, 2.0}, {0.0, 2.0, 1.0}, {0.5, 0.5, 5.0}}) {
    const auto t = as_array(m.transmittance_rgb(ce, cp, L)), r = ref.transmittance(ce, cp, s, L);
    for (std::size_t k = 0; k < 3; ++k) {
      INFO("c_e = " << ce << ", c_p = " << cp << ", L = " << L << ", channel " << k);
      CHECK(t[k] == Approx(std::clamp(r[k], 1e-30, 1.0)).epsilon(1e-12));  // the last one leaves the gamut in blue
    }
  }
}

TEST_CASE("Spectral transmittance falls with concentration and with length", "[melanin]") {
  const SpectralMelanin m = SpectralMelanin::builtin();
  // Non-increasing everywhere; strictly decreasing until a channel reaches the 1e-30 clamp (dark
  // samples are so red that blue, then green, leave the sRGB gamut).
  auto check_path = [](auto transmittance, const std::vector<double>& xs, const char* what) {
    int violations = 0;
    std::array<double, 3> prev{1.0, 1.0, 1.0};
    for (double x : xs) {
      const auto t = as_array(transmittance(x));
      for (std::size_t k = 0; k < 3; ++k) {
        const bool ok = prev[k] > 1e-30 ? t[k] < prev[k] : t[k] == 1e-30;
        if (!ok && violations++ < 5) UNSCOPED_INFO(what << ": channel " << k << " at " << x << ": " << t[k] << " after " << prev[k]);
      }
      prev = t;
    }
    CHECK(violations == 0);
  };
  std::vector<double> cs, lengths;
  for (int i = 1; i <= 1000; ++i) cs.push_back(0.05 * i);                                   // 0.05 … 50
  for (int i = 0; i <= 200; ++i) lengths.push_back(0.01 * std::pow(4000.0, i / 200.0));  // 0.01 … 40
  check_path([&](double c) { return m.transmittance_rgb(c, 0.0, 2.0); }, cs, "eumelanin");
  check_path([&](double c) { return m.transmittance_rgb(0.0, c, 2.0); }, cs, "pheomelanin");
  check_path([&](double c) { return m.transmittance_rgb(c, 0.4 * c, 2.0); }, cs, "mixture 1 : 0.4");
  check_path([&](double c) { return m.transmittance_rgb(0.3, c, 2.0); }, cs, "pheomelanin over c_e = 0.3");
  check_path([&](double L) { return m.transmittance_rgb(1.3, 0.2, L); }, lengths, "length, brown");
  check_path([&](double L) { return m.transmittance_rgb(0.0, 0.5, L); }, lengths, "length, red");
  // The clamp is counted per channel.
  int clamped = 0;
  m.transmittance_rgb(0.1, 0.0, 2.0, &clamped);
  CHECK(clamped == 0);
  m.transmittance_rgb(8.0, 0.0, 2.0, &clamped);  // black hair: green and blue out of gamut
  CHECK(clamped == 2);
  m.sigma_a_rgb(50.0, 50.0, &clamped);
  CHECK(clamped == 4);
}

TEST_CASE("Spectral sigma_a is linear in concentration at small concentration", "[melanin]") {
  const SpectralMelanin m = SpectralMelanin::builtin();
  const Reference ref;
  // First-order expansion of the transmittance: σa_c(c) = c k0_c + O(c²), k0 from the CSV files.
  const auto k0 = ref.eumelanin_first_order(m.options().spectral_scale);
  for (double c : {1e-6, 1e-5}) {
    const auto s = as_array(m.sigma_a_rgb(c, 0.0));
    for (std::size_t k = 0; k < 3; ++k) CHECK(s[k] / c == Approx(k0[k]).epsilon(1e-5));
  }
  // The second-order term is visible at larger c and σa(2c) − 2σa(c) shrinks like c².
  const auto s1 = as_array(m.sigma_a_rgb(1e-3, 0.0)), s2 = as_array(m.sigma_a_rgb(2e-3, 0.0));
  const auto s3 = as_array(m.sigma_a_rgb(1e-2, 0.0)), s4 = as_array(m.sigma_a_rgb(2e-2, 0.0));
  for (std::size_t k = 0; k < 3; ++k) {
    const double d_small = std::abs(s2[k] - 2 * s1[k]), d_large = std::abs(s4[k] - 2 * s3[k]);
    CHECK(d_small < 1e-4 * s1[k]);
    CHECK(d_large / d_small == Approx(100.0).epsilon(0.1));
  }
  // Mixtures add at first order.
  const Rgb e = m.sigma_a_rgb(1e-5, 0.0), p = m.sigma_a_rgb(0.0, 1e-5), ep = m.sigma_a_rgb(1e-5, 1e-5);
  CHECK(ep.r == Approx(e.r + p.r).epsilon(1e-5));
  CHECK(ep.g == Approx(e.g + p.g).epsilon(1e-5));
  CHECK(ep.b == Approx(e.b + p.b).epsilon(1e-5));
  WARN("spectral model, c -> 0 limit of sigma_a/c for eumelanin: " << k0[0] << ", " << k0[1] << ", " << k0[2]);
}

TEST_CASE("Both models absorb blue more than green more than red", "[melanin]") {
  const SpectralMelanin m = SpectralMelanin::builtin();
  int violations = 0;
  for (int which = 0; which < 2; ++which)
    for (int i = 0; i <= 400; ++i) {
      const double c = 1e-3 * std::pow(5e4, i / 400.0);  // 0.001 … 50
      int clamped = 0;
      const Rgb s = which == 0 ? m.sigma_a_rgb(c, 0.0, &clamped) : m.sigma_a_rgb(0.0, c, &clamped);
      // Strict while no channel is clamped; a clamped green equals a clamped blue.
      const bool ok = clamped == 0 ? (s.b > s.g && s.g > s.r) : (s.b >= s.g && s.g > s.r);
      if (!ok && violations++ < 5) UNSCOPED_INFO((which ? "pheomelanin " : "eumelanin ") << c << ": " << s.r << ", " << s.g << ", " << s.b);
    }
  CHECK(violations == 0);
}

TEST_CASE("No NaN, Inf or negative absorption for concentrations 0 to 50", "[melanin]") {
  for (double L : {0.5, 2.0, 10.0}) {
    SpectralMelanin::Options o;
    o.path_length = L;
    const SpectralMelanin m = SpectralMelanin::builtin(o);
    const double smax = std::log(1e30) / L;
    int bad = 0;
    for (int i = 0; i <= 200; ++i)
      for (int j = 0; j <= 200; ++j) {
        const double ce = 0.25 * i, cp = 0.25 * j;
        const auto s = as_array(m.sigma_a_rgb(ce, cp)), t = as_array(m.transmittance_rgb(ce, cp, L)),
                   d = as_array(melanin_sigma_a_rgb(ce, cp));
        for (std::size_t k = 0; k < 3; ++k) {
          const bool ok = std::isfinite(s[k]) && s[k] >= 0.0 && s[k] <= smax * (1 + 1e-12) && t[k] >= 1e-30 && t[k] <= 1.0 &&
                          std::isfinite(d[k]) && d[k] >= 0.0;
          if (!ok && bad++ < 5) UNSCOPED_INFO("L = " << L << ", c_e = " << ce << ", c_p = " << cp << ", channel " << k << ": " << s[k]);
        }
      }
    CHECK(bad == 0);
  }
}

TEST_CASE("Spectral model options and domain errors", "[melanin]") {
  const SpectralMelanin m = SpectralMelanin::builtin();
  CHECK(m.options().path_length == 2.0);
  CHECK(m.options().spectral_scale == Approx(0.01346).epsilon(1e-3));
  // An explicit scale is used as it is: the calibrated one reproduces the default model.
  SpectralMelanin::Options o;
  o.spectral_scale = m.options().spectral_scale;
  const SpectralMelanin same = SpectralMelanin::builtin(o);
  CHECK(same.options().spectral_scale == m.options().spectral_scale);
  CHECK(same.sigma_a_rgb(1.3, 0.2).b == m.sigma_a_rgb(1.3, 0.2).b);
  o.spectral_scale = 2 * m.options().spectral_scale;  // σa depends on s c only
  CHECK(SpectralMelanin::builtin(o).sigma_a_rgb(0.5, 0.1).g == Approx(m.sigma_a_rgb(1.0, 0.2).g).epsilon(1e-12));
  // Calibration at another reference length still gives d'Eon's eumelanin green.
  SpectralMelanin::Options o1;
  o1.path_length = 1.0;
  CHECK(SpectralMelanin::builtin(o1).fit_rgb_cross_sections().eumelanin.g == Approx(0.697).epsilon(1e-9));

  CHECK_THROWS_AS(m.transmittance_rgb(-0.1, 0.0, 2.0), DomainError);
  CHECK_THROWS_AS(m.transmittance_rgb(0.1, kNaN, 2.0), DomainError);
  CHECK_THROWS_AS(m.transmittance_rgb(0.1, 0.0, 0.0), DomainError);
  CHECK_THROWS_AS(m.transmittance_rgb(0.1, 0.0, -1.0), DomainError);
  CHECK_THROWS_AS(m.transmittance_rgb(0.1, 0.0, kInf), DomainError);
  CHECK_THROWS_AS(m.sigma_a_rgb(kInf, 0.0), DomainError);
  CHECK_THROWS_AS(m.sigma_a_rgb(0.0, -2.0), DomainError);
  for (double L : {0.0, -2.0, kNaN, kInf}) {
    SpectralMelanin::Options bad;
    bad.path_length = L;
    CHECK_THROWS_AS(SpectralMelanin::builtin(bad), DomainError);
  }
  for (double s : {-0.01, kNaN, kInf}) {
    SpectralMelanin::Options bad;
    bad.spectral_scale = s;
    CHECK_THROWS_AS(SpectralMelanin::builtin(bad), DomainError);
  }
  CHECK_THROWS_AS(eumelanin_absorption_mm(0.0), DomainError);
  CHECK_THROWS_AS(pheomelanin_absorption_mm(-550.0), DomainError);
  CHECK(eumelanin_absorption_mm(550.0) == Approx(6.6e10 * std::pow(550.0, -3.33)).epsilon(1e-15));
  CHECK(pheomelanin_absorption_mm(550.0) == Approx(2.9e14 * std::pow(550.0, -4.75)).epsilon(1e-15));
  using R = SpectralMelanin::FitRange;
  CHECK_THROWS_AS(m.fit_rgb_cross_sections(R{0.0, 8.0, 40}), DomainError);
  CHECK_THROWS_AS(m.fit_rgb_cross_sections(R{1.0, 1.0, 40}), DomainError);
  CHECK_THROWS_AS(m.fit_rgb_cross_sections(R{0.05, kInf, 40}), DomainError);
  CHECK_THROWS_AS(m.fit_rgb_cross_sections(R{0.05, 8.0, 1}), DomainError);
  CHECK_THROWS_AS(m.fit_rgb_cross_sections(R{20.0, 50.0, 10}), DomainError);  // blue clamped throughout
}

TEST_CASE("Fitted RGB cross-sections land near d'Eon's", "[melanin][paper]") {
  const SpectralMelanin m = SpectralMelanin::builtin();
  const SpectralMelanin::Fit f = m.fit_rgb_cross_sections();
  CHECK(f.spectral_scale == m.options().spectral_scale);
  CHECK(f.eumelanin.g == Approx(0.697).epsilon(1e-9));  // the unit convention
  CHECK(f.samples + f.clamped == 2 * 3 * 40);
  CHECK(f.clamped > 0);  // the darkest samples leave the sRGB gamut in blue/green
  CHECK(f.rms_relative_error < 0.1);
  const double eu[3] = {0.419, 0.697, 1.37}, ph[3] = {0.187, 0.4, 1.05};
  const auto fe = as_array(f.eumelanin), fp = as_array(f.pheomelanin);
  std::ostringstream report;
  report.precision(3);
  for (std::size_t c = 0; c < 3; ++c) {
    report << "RGB"[c] << ": eumelanin " << fe[c] << " (d'Eon " << eu[c] << ", " << std::showpos << 100 * (fe[c] / eu[c] - 1)
           << std::noshowpos << "%), pheomelanin " << fp[c] << " (d'Eon " << ph[c] << ", " << std::showpos
           << 100 * (fp[c] / ph[c] - 1) << std::noshowpos << "%); ";
    CHECK(fe[c] == Approx(eu[c]).epsilon(0.25));
    CHECK(fp[c] == Approx(ph[c]).epsilon(0.25));
    CHECK(fe[c] > fp[c]);
  }
  report << "scale " << f.spectral_scale << " mm/radius, rms relative fit error " << f.rms_relative_error << " (max "
         << f.max_relative_error << ") over " << f.samples << " samples, " << f.clamped << " clamped samples left out";
  WARN(report.str());
  // Over very light hair the fit tends to the first-order slopes (light absorbs in proportion).
  const Reference ref;
  const auto k0 = ref.eumelanin_first_order(m.options().spectral_scale);
  const SpectralMelanin::Fit light = m.fit_rgb_cross_sections({1e-4, 1e-3, 10});
  CHECK(light.clamped == 0);
  CHECK(light.eumelanin.r == Approx(k0[0]).epsilon(1e-3));
  CHECK(light.eumelanin.g == Approx(k0[1]).epsilon(1e-3));
  CHECK(light.eumelanin.b == Approx(k0[2]).epsilon(1e-3));
}
