// Melanin absorption: the RGB model, the embedded CIE/D65 tables, the sRGB matrix, and the spectral
// model's RGB cross-sections against d'Eon 2011's.
#include <cmath>
#include <fstream>
#include <hairlut/error.hpp>
#include <hairlut/melanin.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "catch.hpp"

using namespace hairlut;

#ifndef HAIRLUT_DATA_DIR
#define HAIRLUT_DATA_DIR "data"
#endif

TEST_CASE("d'Eon's RGB cross-sections", "[melanin]") {
  const Rgb a = melanin_sigma_a_rgb(2.0, 0.5);
  CHECK(a.r == Approx(2.0 * 0.419 + 0.5 * 0.187).epsilon(1e-15));
  CHECK(a.g == Approx(2.0 * 0.697 + 0.5 * 0.4).epsilon(1e-15));
  CHECK(a.b == Approx(2.0 * 1.37 + 0.5 * 1.05).epsilon(1e-15));
  CHECK_THROWS_AS(melanin_sigma_a_rgb(-1.0, 0.0), DomainError);
  CHECK_THROWS_AS(melanin_sigma_a_rgb(0.0, NAN), DomainError);
}

TEST_CASE("The embedded spectral tables are the shipped CSV files", "[melanin]") {
  const SpectralMelanin m = SpectralMelanin::builtin();
  const auto& l = m.wavelengths_nm();
  REQUIRE(l.size() == 81);
  CHECK(l.front() == 380.0);
  CHECK(l.back() == 780.0);
  std::ifstream in(std::string(HAIRLUT_DATA_DIR) + "/cie1931_2deg_5nm.csv");
  REQUIRE(in);
  std::string line;
  std::size_t rows = 0;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#' && line[0] != 'w') CHECK(std::stod(line.substr(0, line.find(','))) == l[rows++]);
  CHECK(rows == 81);
}

TEST_CASE("The sRGB matrix maps D65's chromaticity to neutral; D65 white is (1, 1, 1)", "[melanin]") {
  // D65 white point x = 0.3127, y = 0.3290 with Y = 1 (independent of the tabulated spectrum).
  const double x = 0.3127, y = 0.3290;
  const Rgb w = srgb_linear_from_xyz(x / y, 1.0, (1.0 - x - y) / y);
  CHECK(w.r == Approx(1.0).margin(1e-3));
  CHECK(w.g == Approx(1.0).margin(1e-3));
  CHECK(w.b == Approx(1.0).margin(1e-3));
  const SpectralMelanin m = SpectralMelanin::builtin();
  const Rgb clear = m.transmittance_rgb(0.0, 0.0, 2.0);
  CHECK(clear.r == 1.0);
  CHECK(clear.g == 1.0);
  CHECK(clear.b == 1.0);
  const Rgb tiny = m.transmittance_rgb(1e-12, 0.0, 2.0);
  CHECK(tiny.r == Approx(1.0).epsilon(1e-9));
  CHECK(tiny.b == Approx(1.0).epsilon(1e-9));
}

TEST_CASE("Spectral transmittance falls with concentration and length; blue absorbs most", "[melanin]") {
  const SpectralMelanin m = SpectralMelanin::builtin();
  Rgb prev{1, 1, 1};
  for (double c : {0.1, 0.5, 1.0, 2.0, 4.0, 8.0}) {
    // Dark samples are so red that their blue leaves the sRGB gamut and is clamped to 1e-30:
    // strictly decreasing until then.
    const Rgb t = m.transmittance_rgb(c, 0.0, 2.0);
    CHECK(t.r < prev.r);
    CHECK(t.g < prev.g);
    CHECK(t.b <= prev.b);
    if (prev.b > 1e-30) CHECK(t.b < prev.b);
    CHECK(t.r > t.g);
    CHECK(t.g >= t.b);
    prev = t;
  }
  CHECK(m.transmittance_rgb(1.0, 0.3, 3.0).g < m.transmittance_rgb(1.0, 0.3, 1.0).g);
  for (double ce : {0.0, 0.5, 8.0, 50.0})
    for (double cp : {0.0, 1.0, 50.0}) {
      const Rgb s = m.sigma_a_rgb(ce, cp);
      CHECK(std::isfinite(s.r));
      CHECK(std::isfinite(s.b));
      CHECK(s.r >= 0.0);
      CHECK(s.g >= 0.0);
      CHECK(s.b >= 0.0);
      if (ce + cp > 0.0) CHECK(s.b > s.r);
    }
  // Small concentrations: σa is linear in c (first-order expansion of the transmittance).
  const Rgb s1 = m.sigma_a_rgb(1e-4, 0.0), s2 = m.sigma_a_rgb(2e-4, 0.0);
  CHECK(s2.g == Approx(2.0 * s1.g).epsilon(1e-4));
}

TEST_CASE("Fitted RGB cross-sections land near d'Eon's", "[melanin][paper]") {
  const SpectralMelanin m = SpectralMelanin::builtin();
  const SpectralMelanin::Fit f = m.fit_rgb_cross_sections();
  CHECK(f.eumelanin.g == Approx(0.697).epsilon(1e-6));  // the unit convention
  const double eu[3] = {0.419, 0.697, 1.37}, ph[3] = {0.187, 0.4, 1.05};
  const double fe[3] = {f.eumelanin.r, f.eumelanin.g, f.eumelanin.b};
  const double fp[3] = {f.pheomelanin.r, f.pheomelanin.g, f.pheomelanin.b};
  std::ostringstream report;
  report.precision(3);
  for (int c = 0; c < 3; ++c) {
    report << "RGB"[c] << ": eumelanin " << fe[c] << " (d'Eon " << eu[c] << ", " << 100 * (fe[c] / eu[c] - 1) << "%), pheomelanin "
           << fp[c] << " (d'Eon " << ph[c] << ", " << 100 * (fp[c] / ph[c] - 1) << "%); ";
    CHECK(fe[c] == Approx(eu[c]).epsilon(0.25));
    CHECK(fp[c] == Approx(ph[c]).epsilon(0.25));
  }
  report << "scale " << f.spectral_scale << ", rms relative fit error " << f.rms_relative_error << ", clamped " << f.clamped;
  WARN(report.str());
}
