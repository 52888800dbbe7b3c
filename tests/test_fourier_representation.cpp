// N_p in the Fourier representation (tables.np.representation "fourier"): the baked coefficients
// against the adaptive reference N_p (at the nodes, for every β, and between the nodes), the
// header-only evaluator (sampler/fourier_np.hpp) against the library's plain evaluation
// (fourier_tables.hpp) and against the physics it restates (term count, least absorption, sine and
// cosine), its edges (NaN, signs, periods, clamps), a written and read file, thread counts, and
// config errors.
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/io/hdf5_io.hpp>
#include <hairlut/bake/outputs.hpp>
#include <hairlut/io/table_io.hpp>
#include <hairlut/physics/attenuation.hpp>
#include <hairlut/physics/azimuthal_fourier.hpp>
#include <hairlut/physics/azimuthal_np.hpp>
#include <hairlut/physics/lobe_energy.hpp>
#include <hairlut/sampler/fourier_np.hpp>
#include <hairlut/tables/fourier_tables.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/util/angles.hpp>
#include <random>
#include <unistd.h>
#include <vector>

#include "catch.hpp"

using namespace hairlut;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hairlut-fourier-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A Fourier config over a small domain (β 5°–20°, σa 0–2, θd 0–60°).
json fourier_config(int theta = 24, int sigma = 6, const std::string& precision = "float32", double tolerance = 1e-4) {
  json j = json::parse(R"({
    "name": "fourier",
    "lobes": { "explicit": ["R", "TT", "TRT", "TRRT"], "residual": true },
    "tables": { "np": {
      "representation": "fourier",
      "axes": {
        "beta": { "range_deg": [5, 20] },
        "sigma_a": { "count": 6, "range": [0, 2], "spacing": "sqrt", "interpolation": "cubic", "lo_end": "mirror" },
        "theta_d": { "count": 24, "range_deg": [0, 60], "spacing": "cos", "interpolation": "cubic" } },
      "fourier": { "tolerance": 1e-4 } } },
    "output": { "basename": "fourier", "formats": ["hdf5"] }
  })");
  j["tables"]["np"]["axes"]["theta_d"]["count"] = theta;
  j["tables"]["np"]["axes"]["sigma_a"]["count"] = sigma;
  j["tables"]["np"]["fourier"]["tolerance"] = tolerance;
  j["output"]["hdf5"] = {{"precision", precision}};
  return j;
}

BakeConfig config_in(const fs::path& dir, const json& j) { return parse_config(j, "fourier.json", dir); }

std::string config_error(const json& j) {
  try {
    parse_config(j, "f.json", fs::temp_directory_path());
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

// The peak over φ of the exact N_p of lobe p at (β, σa, θd) (adaptive reference on 91 φ).
double slice_peak(const AttenuationSlice& slice, int p, double beta) {
  double peak = 0.0;
  for (int j = 0; j <= 90; ++j) peak = std::max(peak, azimuthal_np_reference(slice, p, beta, kPi * j / 90.0, 1e-10).value[0]);
  return peak;
}

// An in-memory Fourier table of arbitrary coefficients (decaying with n, of either sign).
Table synthetic_table(int terms, int nt, int ns, Spacing theta_spacing, Interpolation ti, Spacing sigma_spacing, Interpolation si,
                      std::uint64_t seed) {
  FourierTableInfo info;
  info.params.terms = terms, info.params.beta_min = radians(3.0), info.params.tolerance = 1e-12, info.params.eta = 1.55;
  info.params.absorption_p = 2, info.beta_max = radians(30.0), info.lobe = "TRT", info.p = 2;
  GridAxis th, sg;
  th.name = "theta_d", th.units = "rad", th.spacing = theta_spacing, th.wrap = Wrap::even, th.lo = 0.0, th.hi = radians(85.0), th.count = nt;
  th.interpolation = ti;
  sg.name = "sigma_a", sg.units = "1/radius", sg.spacing = sigma_spacing, sg.lo = 0.0, sg.hi = 3.0, sg.count = ns, sg.interpolation = si;
  if (sigma_spacing == Spacing::sqrt && si == Interpolation::cubic) sg.lo_end = End::mirror;
  Table t;
  t.group = kFourierGroup, t.name = "TRT", t.quantity = kFourierQuantity, t.units = "1";
  t.axes = {th, sg, fourier_n_axis(terms)};
  t.attributes = fourier_attributes(info, "chord");
  t.allocate(Precision::float32);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t i = 0; i < t.size(); ++i) {
    const auto n = static_cast<double>(i % static_cast<std::size_t>(terms));
    t.set(i, (n == 0 ? 0.3 + 0.1 * u(rng) : 0.2 * u(rng)) * std::exp(-n / 25.0));
  }
  return t;
}

}  // namespace

TEST_CASE("Fourier: the evaluator's term count is the library's and its tail bound holds", "[fourier-representation]") {
  std::vector<float> dummy(4096, 0.0f);
  sampler::Axis th, sg;
  th.spacing = sampler::Spacing::cos, th.hi = 1.5, th.count = 1;
  sg.count = 1;
  for (double tol : {1e-2, 1e-4, 1e-8}) {
    sampler::FourierNpParams p;
    p.terms = 4096, p.beta_min = radians(0.5), p.tolerance = tol;
    const sampler::FourierNp<float, double> view(dummy.data(), th, sg, p);
    REQUIRE(view.valid());
    for (double beta_deg : {0.5, 0.77, 2.0, 7.0, 30.0, 90.0, 400.0}) {
      const double beta = radians(beta_deg);
      const int n = view.series_terms(beta);
      CHECK(n == fourier_terms(beta, tol));
      double tail = 0.0;
      for (int k = n + 1; k < n + 100000; ++k) tail += std::exp(-0.5 * k * k * beta * beta);
      CHECK(2.0 * tail <= 0.5 * tol);
      const int summed = view.summed_terms(beta);
      CHECK(summed >= n + 1);
      CHECK(summed % 4 == 0);
      CHECK(summed < n + 5);
    }
    CHECK(view.series_terms(radians(0.1)) == view.series_terms(radians(0.5)));  // β below β_min reads β_min
  }
}

TEST_CASE("Fourier: the evaluator's least absorption F is the physics' T(±1)^p", "[fourier-representation]") {
  double worst = 0.0;
  for (double eta : {1.2, 1.55, 2.5})
    for (AbsorptionPath path : {AbsorptionPath::chord, AbsorptionPath::papers})
      for (int p = 0; p <= 4; ++p)
        for (double td : {0.0, 20.0, 60.0, 89.0, 90.0})
          for (double sigma : {0.0, 0.3, 5.0}) {
            sampler::FourierNpParams f;
            f.eta = eta, f.absorption_p = p, f.papers_path = path == AbsorptionPath::papers;
            const double a = sampler::fourier_absorption<double>(f, sigma, std::cos(radians(td)));
            const double b = least_absorption(AttenuationSlice(eta, radians(td), sigma, path), p);
            worst = std::max(worst, std::abs(a - b) / b);
            // and the path's length at the edge is the segment length there
            CHECK(edge_segment_length(FiberGeometry::make(eta, radians(td)), path) > 0.0);
          }
  CHECK(worst < 1e-13);
}

TEST_CASE("Fourier: the evaluator's sine and cosine are the standard library's to rounding", "[fourier-representation]") {
  double worst_d = 0.0, worst_f = 0.0;
  for (int i = 0; i <= 20000; ++i) {
    const double x = kPi * i / 20000.0, y = kPi * (20000 - i) / 20000.0;
    double c0, s0, c1, s1;
    sampler::detail::sincos_0_pi(x, y, c0, s0, c1, s1);
    worst_d = std::max({worst_d, std::abs(c0 - std::cos(x)), std::abs(s0 - std::sin(x)), std::abs(c1 - std::cos(y)), std::abs(s1 - std::sin(y))});
    float cf, sf, cg, sg;
    sampler::detail::sincos_0_pi(static_cast<float>(x), static_cast<float>(y), cf, sf, cg, sg);
    const double xf = static_cast<float>(x);
    worst_f = std::max({worst_f, std::abs(cf - std::cos(xf)), std::abs(sf - std::sin(xf))});
  }
  CHECK(worst_d < 4e-16);  // a couple of ulps of 1
  CHECK(worst_f < 3e-7);
}

TEST_CASE("Fourier: at its nodes a baked table is the exact N_p for every beta, from the same coefficients", "[fourier-representation]") {
  // float64 coefficients, truncation 1e-10: at a node only the quadrature and the truncation remain.
  const TableSet set = bake(config_in(temp_dir("nodes"), fourier_config(4, 3, "float64", 1e-10)));
  for (const char* lobe : {"R", "TT", "TRT", "TRRT"}) {
    const Table& t = *set.find(std::string("np_fourier/") + lobe);
    const FourierNpReference ref(t);
    const auto view = fourier_np<double, double>(set, lobe);
    const int p = t.attributes["p"].get<int>();
    const auto thetas = t.axes[0].nodes(), sigmas = t.axes[1].nodes();
    double worst = 0.0;
    for (std::size_t i : {std::size_t{0}, std::size_t{3}})
      for (std::size_t k : {std::size_t{1}, std::size_t{2}}) {
        const AttenuationSlice slice(1.55, thetas[i], sigmas[k]);
        // Two β inside the baked range and one beyond it: the same coefficients serve every β.
        for (double beta_deg : {5.0, 11.7, 35.0}) {
          const double beta = radians(beta_deg), peak = slice_peak(slice, p, beta);
          REQUIRE(peak > 0.0);
          for (double phi : {0.0, 0.41, 1.3, 2.2, 3.0}) {
            const double exact = azimuthal_np_reference(slice, p, beta, phi, 1e-13).value[0];
            worst = std::max({worst, std::abs(view(beta, sigmas[k], thetas[i], phi) - exact) / peak,
                              std::abs(ref(beta, sigmas[k], thetas[i], phi) - exact) / peak});
          }
        }
        // Its energy is the coefficients' c_0 F.
        const double e = lobe_energies_reference(slice, {4, true}, 1e-13).value[static_cast<std::size_t>(p)];
        CHECK(view.energy(sigmas[k], thetas[i]) == Approx(e).epsilon(1e-9));
      }
    INFO(lobe << ": worst error at the nodes relative to the slice peak " << worst);
    CHECK(worst < 1e-8);
  }
  // The residual's one coefficient gives its uniform N: E_{≥P} / 2π.
  const auto res = fourier_np<double, double>(set, "residual");
  const AttenuationSlice slice(1.55, radians(60.0), 2.0);
  const double e = lobe_energies_reference(slice, {4, true}, 1e-13).value.back();
  CHECK(res(radians(7.0), 2.0, radians(60.0), 1.0) == Approx(e / kTwoPi).epsilon(1e-9));
}

TEST_CASE("Fourier: between nodes a table meets the 1e-3 target against the adaptive reference", "[fourier-representation]") {
  const TableSet set = bake(config_in(temp_dir("between"), fourier_config(128, 10)));  // about the node spacing of the generic tables (256 cos θd over 0–89°)
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const char* lobe : {"R", "TT", "TRT", "TRRT"}) {
    const auto view = fourier_np<float, float>(set, lobe);
    const int p = lobe_index(set, lobe);
    double worst = 0.0;
    for (int s = 0; s < 12; ++s) {
      const double sigma = 2.0 * u(rng), theta = radians(60.0) * u(rng), beta = radians(5.0) * std::pow(4.0, u(rng));
      const AttenuationSlice slice(1.55, theta, sigma), white(1.55, theta, 0.0);
      const double den = std::max(slice_peak(slice, p, beta), 1e-3 * slice_peak(white, p, beta));  // docs/conventions.md
      for (int j = 0; j < 4; ++j) {
        const double phi = kPi * u(rng);
        const double exact = azimuthal_np_reference(slice, p, beta, phi, 1e-13).value[0];
        const double got = view(static_cast<float>(beta), static_cast<float>(sigma), static_cast<float>(theta), static_cast<float>(phi));
        worst = std::max(worst, std::abs(got - exact) / den);
      }
    }
    INFO(lobe << ": worst error between nodes " << worst);
    CHECK(worst > 0.0);
    CHECK(worst <= 1e-3);
  }
}

TEST_CASE("Fourier: the header-only evaluator equals the library's evaluation", "[fourier-representation]") {
  struct Variant {
    int terms, nt, ns;
    Spacing ts;
    Interpolation ti;
    Spacing ss;
    Interpolation si;
  };
  const Variant variants[] = {{64, 9, 5, Spacing::cos, Interpolation::cubic, Spacing::sqrt, Interpolation::cubic},
                              {61, 7, 4, Spacing::uniform, Interpolation::cubic, Spacing::uniform, Interpolation::linear},
                              {13, 6, 3, Spacing::cos, Interpolation::linear, Spacing::sqrt, Interpolation::cubic},
                              {30, 5, 2, Spacing::uniform, Interpolation::linear, Spacing::sqrt, Interpolation::linear},
                              {8, 1, 1, Spacing::cos, Interpolation::linear, Spacing::sqrt, Interpolation::linear}};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const Variant& v : variants) {
    const Table t = synthetic_table(v.terms, v.nt, v.ns, v.ts, v.ti, v.ss, v.si, 11);
    const FourierNpReference ref(t);
    const FourierTableInfo info = fourier_table_info(t);
    const sampler::FourierNp<float, double> vd(t.f32.data(), t.axes[0].view(), t.axes[1].view(), info.params);
    const sampler::FourierNp<float, float> vf(t.f32.data(), t.axes[0].view(), t.axes[1].view(), info.params);
    REQUIRE(vd.valid());
    double worst_d = 0.0, worst_f = 0.0;
    for (int i = 0; i < 400; ++i) {
      // Beyond every range too: θd signed and past θ_max, σa past its ends, β below β_min, φ any angle.
      const double beta = radians(1.0) * std::pow(60.0, u(rng)), sigma = -0.5 + 4.0 * u(rng), theta = radians(-100.0 + 200.0 * u(rng));
      const double phi = -10.0 + 20.0 * u(rng);
      // The scale of the sum: a bound of Σ (2 − δ_n0) e^{−n²β²/2} |c_n| F / 2π at the point (|c_n| ≤ 0.4 e^{−n/25}).
      const double b = std::max(beta, info.params.beta_min);
      double scale = 0.0;
      for (int n = 0; n < v.terms; ++n) scale += (n ? 2.0 : 1.0) * std::exp(-0.5 * n * n * b * b) * 0.4 * std::exp(-n / 25.0);
      const double th = std::clamp(std::abs(theta), 0.0, t.axes[0].hi), sg = std::clamp(sigma, 0.0, t.axes[1].hi);
      scale *= sampler::fourier_absorption<double>(info.params, sg, std::cos(th)) / kTwoPi;
      const double r = ref(beta, sigma, theta, phi);
      worst_d = std::max(worst_d, std::abs(vd(beta, sigma, theta, phi) - r) / scale);
      worst_f = std::max(worst_f, std::abs(vf(static_cast<float>(beta), static_cast<float>(sigma), static_cast<float>(theta), static_cast<float>(phi)) - r) / scale);
    }
    INFO("terms " << v.terms << " axes " << v.nt << " x " << v.ns << ": double " << worst_d << ", float " << worst_f);
    CHECK(worst_d < 1e-10);  // double arithmetic: rounding only
    CHECK(worst_f < 1e-4);   // float arithmetic: at most a tenth of the 1e-3 target
  }
}

TEST_CASE("Fourier: NaN, signs, periods and clamps", "[fourier-representation]") {
  const Table t = synthetic_table(24, 6, 4, Spacing::cos, Interpolation::cubic, Spacing::sqrt, Interpolation::cubic, 5);
  const FourierTableInfo info = fourier_table_info(t);
  const sampler::FourierNp<float, double> v(t.f32.data(), t.axes[0].view(), t.axes[1].view(), info.params);
  const double nan = std::nan("");
  CHECK(std::isnan(v(nan, 1.0, 0.2, 0.3)));
  CHECK(std::isnan(v(0.1, nan, 0.2, 0.3)));
  CHECK(std::isnan(v(0.1, 1.0, nan, 0.3)));
  CHECK(std::isnan(v(0.1, 1.0, 0.2, nan)));
  CHECK(std::isnan(v(0.1, 1.0, 0.2, INFINITY)));
  CHECK(std::isnan(v.energy(nan, 0.2)));
  const double x = v(0.1, 1.0, 0.4, 0.7);
  CHECK(v(0.1, 1.0, -0.4, 0.7) == x);                                   // θd → |θd|
  CHECK(v(0.1, 1.0, 0.4, -0.7) == Approx(x).epsilon(1e-12));            // even in φ
  CHECK(v(0.1, 1.0, 0.4, 0.7 + 4.0 * kPi) == Approx(x).epsilon(1e-12));  // 2π-periodic
  CHECK(v(0.1, 3.0, 0.4, 0.7) == v(0.1, 7.0, 0.4, 0.7));                // σa held beyond its range
  CHECK(v(0.1, 0.0, 0.4, 0.7) == v(0.1, -1.0, 0.4, 0.7));
  CHECK(v(0.1, 1.0, radians(85.0), 0.7) == v(0.1, 1.0, radians(89.0), 0.7));  // θd held beyond θ_max
  CHECK(v(radians(3.0), 1.0, 0.4, 0.7) == v(radians(1.0), 1.0, 0.4, 0.7));     // β below β_min reads β_min
  // Never negative: a table whose c_0 is negative gives 0, not its sum.
  Table neg = t;
  for (std::size_t i = 0; i < neg.size(); ++i) neg.set(i, i % 24 == 0 ? -1.0 : 0.0);
  const sampler::FourierNp<float, double> vn(neg.f32.data(), neg.axes[0].view(), neg.axes[1].view(), info.params);
  CHECK(vn(0.1, 1.0, 0.4, 0.7) == 0.0);
  CHECK(FourierNpReference(neg)(0.1, 1.0, 0.4, 0.7) == 0.0);
  // A view of an axis the evaluator cannot read is invalid and gives NaN.
  sampler::Axis logs = t.axes[1].view();
  logs.spacing = sampler::Spacing::log, logs.lo = 0.1;
  const sampler::FourierNp<float, double> bad(t.f32.data(), t.axes[0].view(), logs, info.params);
  CHECK(!bad.valid());
  CHECK(std::isnan(bad(0.1, 1.0, 0.4, 0.7)));
}

TEST_CASE("Fourier: a written and read file holds the tables baked, and records the format version of every file", "[fourier-representation][io]") {
  const fs::path dir = temp_dir("io");
  const BakeConfig c = config_in(dir, fourier_config(8, 4));
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  write_outputs(set, c, report);
  const TableSet back = load_tables(output_paths(c).hdf5);
  REQUIRE(back.tables.size() == set.tables.size());
  CHECK(back.metadata == set.metadata);
  for (const Table& t : set.tables) {
    const Table* b = back.find(t.path());
    REQUIRE(b);
    CHECK(b->f32 == t.f32);
    CHECK(b->attributes == t.attributes);
    CHECK(b->describe() == t.describe());
  }
  const auto a = fourier_np<float, double>(set, "TRT"), b = fourier_np<float, double>(back, "TRT");
  for (double phi : {0.0, 1.0, 2.0}) CHECK(a(0.2, 0.7, 0.5, phi) == b(0.2, 0.7, 0.5, phi));
  // The file's format version: what a set of these tables records (Fourier tables add nothing to it).
  const hid_t f = H5Fopen(output_paths(c).hdf5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(f >= 0);
  const hid_t attr = H5Aopen(f, "hairlut_format_version", H5P_DEFAULT);
  const hid_t type = H5Aget_type(attr);
  std::string version(H5Tget_size(type), '\0');
  H5Aread(attr, type, version.data());
  H5Tclose(type), H5Aclose(attr), H5Fclose(f);
  CHECK(std::string(version.c_str()) == format_version_text(set));
  // OpenEXR is refused before anything is written.
  BakeConfig exr = c;
  exr.output.exr = true;
  exr.output.basename = "with-exr";
  CHECK_THROWS_WITH(write_outputs(set, exr, report), Catch::Matchers::Contains("HDF5 only"));
  CHECK(!fs::exists(output_paths(exr).hdf5));
  CHECK(!fs::exists(output_paths(exr).exr));
}

TEST_CASE("Fourier: a theta_d axis reaching 90 deg stores c_n / g and follows the model up to grazing", "[fourier-representation][grazing]") {
  // θd uniform to 90° in cells of 0.47° (cos θd steps of 8.2e-3 at grazing, where the stored c_n / g
  // still varies by 30% over 0.02 in cos θd for TRRT: (1 − f)² f² with 1 − f ≈ 5.75 cos θd).
  json j = fourier_config(192, 12);
  j["tables"]["np"]["axes"]["theta_d"]["range_deg"] = {0, 90};
  j["tables"]["np"]["axes"]["theta_d"]["spacing"] = "uniform";
  const TableSet set = bake(config_in(temp_dir("grazing"), j));
  CHECK(!set.find("np_fourier/R")->attributes.contains("cos_theta_d_power"));
  for (const char* lobe : {"TT", "TRT", "TRRT"}) CHECK(set.find(std::string("np_fourier/") + lobe)->attributes.value("cos_theta_d_power", 0) == 2);
  CHECK(set.find("np_fourier/residual")->attributes.contains("grazing_absorption"));
  CHECK(format_version_text(set) == "3.0");
  // The same coefficients as such a set stored them before: c_n itself (g multiplied back at the
  // nodes), no attributes. It holds the same nodes, so only the interpolation near 90° differs.
  auto undivided = [&](const char* lobe) {
    Table t = *set.find(std::string("np_fourier/") + lobe);
    const sampler::GrazingFactor g = t.grazing_factor();
    const std::vector<double> th = t.axes[0].nodes(), sg = t.axes[1].nodes();
    const std::size_t terms = static_cast<std::size_t>(t.axes[2].count);
    for (std::size_t i = 0; i < t.size(); ++i) t.set(i, t.get(i) * g(sg[(i / terms) % sg.size()], th[i / terms / sg.size()]));
    t.attributes.erase("cos_theta_d_power");
    return t;
  };
  double worst = 0.0, worst_before = 0.0, worst_energy = 0.0;
  std::string worst_at;
  for (const char* lobe : {"R", "TT", "TRT", "TRRT"}) {
    const int p = lobe_index(set, lobe);
    const FourierNpReference now(*set.find(std::string("np_fourier/") + lobe));
    const Table old_table = undivided(lobe);
    const FourierNpReference before(old_table);
    for (double deg : {80.0, 88.0, 89.5, 89.9, 89.99}) {
      const double td = radians(deg);
      for (double sa : {0.0, 0.3, 2.0}) {
        const AttenuationSlice slice(1.55, td, sa), white(1.55, td, 0.0);
        for (double beta : {radians(5.0), radians(12.0)}) {
          const double den = std::max(slice_peak(slice, p, beta), 1e-3 * slice_peak(white, p, beta));  // docs/conventions.md
          for (int k = 0; k <= 12; ++k) {
            const double phi = kPi * k / 12.0, exact = azimuthal_np_reference(slice, p, beta, phi, 1e-12).value[0];
            INFO(lobe << " at theta_d " << deg << " deg, sigma_a " << sa << ", beta " << beta << ", phi " << phi << ": exact " << exact);
            const double err = std::abs(now(beta, sa, td, phi) - exact) / den;
            if (err > worst) worst = err, worst_at = std::string(lobe) + " at theta_d " + std::to_string(deg) + " deg, sigma_a " + std::to_string(sa);
            worst_before = std::max(worst_before, std::abs(before(beta, sa, td, phi) - exact) / den);
          }
        }
        const double e = lobe_energies(slice, LobeSet{4, false}, GaussLegendreRule(256))[static_cast<std::size_t>(p)];
        const double e_white = lobe_energies(white, LobeSet{4, false}, GaussLegendreRule(256))[static_cast<std::size_t>(p)];
        worst_energy = std::max(worst_energy, std::abs(now.energy(sa, td) - e) / std::max(e, 1e-3 * e_white));
      }
    }
    // At 90° itself every lobe but R has vanished (cos θd = 6.1e-17 at the double nearest π/2).
    for (double phi : {0.0, 1.0, kPi}) {
      const double v = now(radians(5.0), 0.3, 0.5 * kPi, phi);
      CHECK(std::isfinite(v));
      CHECK(v >= 0.0);
      if (p > 0) CHECK(v <= 1e-28);
    }
  }
  WARN("Fourier N_p at theta_d 80-89.99 deg, 192 theta_d x 12 sqrt sigma_a nodes: worst error " << worst << " of the local peak (" << worst_at
                                                                                                 << "; c_n stored undivided: " << worst_before
                                                                                                 << "); energies " << worst_energy);
  CHECK(worst <= 1e-3);
  CHECK(worst_energy <= 1e-3);
  CHECK(worst_before > 10.0 * worst);
}

TEST_CASE("Fourier: the coefficients are bit-identical for any thread count", "[fourier-representation]") {
  const BakeConfig c = config_in(temp_dir("threads"), fourier_config(10, 5));
  BakeOptions one, two;
  one.threads = 1, two.threads = 2;
  const TableSet a = bake(c, one), b = bake(c, two);
  REQUIRE(a.tables.size() == b.tables.size());
  for (std::size_t i = 0; i < a.tables.size(); ++i) CHECK(a.tables[i].f32 == b.tables[i].f32);
  CHECK(content_checksum(a) == content_checksum(b));
}

TEST_CASE("Fourier: bad configs are refused naming the key", "[fourier-representation][config]") {
  const json good = fourier_config();
  CHECK(config_error(good).empty());
  auto with = [&](const std::function<void(json&)>& edit) {
    json j = good;
    edit(j);
    return config_error(j);
  };
  CHECK_THAT(with([](json& j) { j["tables"]["np"]["axes"]["phi"] = {{"count", 9}}; }), Catch::Matchers::Contains("tables.np.axes.phi"));
  CHECK_THAT(with([](json& j) { j["tables"]["np"]["axes"]["beta"]["count"] = 4; }), Catch::Matchers::Contains("tables.np.axes.beta"));
  CHECK_THAT(with([](json& j) { j["tables"]["np"]["axes"].erase("sigma_a"); }), Catch::Matchers::Contains("sigma_a"));
  CHECK_THAT(with([](json& j) { j["output"]["formats"] = {"hdf5", "exr"}; }), Catch::Matchers::Contains("output.formats"));
  CHECK_THAT(with([](json& j) { j["tables"]["np"]["normalize"] = "energy"; }), Catch::Matchers::Contains("tables.np.normalize"));
  CHECK_THAT(with([](json& j) { j["tables"]["np"]["fourier"]["tolerance"] = 0.5; }), Catch::Matchers::Contains("tables.np.fourier.tolerance"));
  CHECK_THAT(with([](json& j) { j["tables"]["np"]["representation"] = "spline"; }), Catch::Matchers::Contains("tables.np.representation"));
  CHECK_THAT(with([](json& j) {
               json& a = j["tables"]["np"]["axes"]["sigma_a"];
               a["spacing"] = "log", a["range"] = {0.1, 2}, a.erase("lo_end");
             }),
             Catch::Matchers::Contains("tables.np.axes.sigma_a.spacing"));
  CHECK_THAT(with([](json& j) { j["quadrature"] = {{"method", "gauss-legendre"}}; }), Catch::Matchers::Contains("quadrature.method"));
  CHECK_THAT(with([](json& j) { j["tables"]["np"].erase("representation"); }), Catch::Matchers::Contains("tables.np"));
  // The errors are one line each.
  CHECK(with([](json& j) { j["tables"]["np"]["axes"]["phi"] = {{"count", 9}}; }).find('\n') == std::string::npos);
}

TEST_CASE("Fourier: target_error chooses the Fourier tables where they are the fewest entries, and they reach the target", "[fourier-representation][bake]") {
  // Tensor axes given (β 8°–16°, σa 0–4, θd 0–60°, all φ): every representation competes.
  json j = json::parse(R"({
    "name": "target-fourier",
    "lobes": { "explicit": ["R", "TT", "TRT", "TRRT"], "residual": true },
    "tables": { "np": { "target_error": 0.02, "target_points": 4000, "axes": {
      "theta_d": { "count": 5, "range_deg": [0, 60], "spacing": "cos" },
      "phi": { "count": 9, "symmetry": "even" },
      "sigma_a": { "count": 3, "range": [0, 4], "spacing": "sqrt" },
      "beta": { "count": 3, "range_deg": [8, 16], "spacing": "log" } } } },
    "output": { "basename": "target", "formats": ["hdf5"] }
  })");
  BakeReport report;
  const TableSet set = bake(config_in(temp_dir("target"), j), {}, &report);
  const json r = report.resolution;
  INFO(r.dump());
  REQUIRE(r.contains("entries_fourier"));
  std::size_t fewest = r["entries_fourier"].get<std::size_t>();
  for (const char* k : {"entries_as_configured", "entries_shape_cubic", "entries_beta_bands"})
    if (r.contains(k)) fewest = std::min(fewest, r[k].get<std::size_t>());
  CHECK(r["entries_per_lobe"].get<std::size_t>() == fewest);
  CHECK(r["entries_per_lobe"] == r["entries_fourier"]);
  CHECK(r["representation"].get<std::string>().find("Fourier") != std::string::npos);
  CHECK(r["achieved_error"].get<double>() <= 0.02);
  CHECK(r["achieved_error"].get<double>() > 0.0);
  // What was chosen is what was baked: Fourier tables with the reported counts, no tensor N_p.
  const Table* t = set.find("np_fourier/TT");
  REQUIRE(t);
  CHECK(set.find("np/TT") == nullptr);
  CHECK(t->axes[0].count == r["counts"]["theta_d"].get<int>());
  CHECK(t->axes[1].count == r["counts"]["sigma_a"].get<int>());
  CHECK(t->axes[2].count == r["counts"]["terms"].get<int>());
  CHECK(t->size() == r["entries_per_lobe"].get<std::size_t>());
  CHECK(set.metadata["resolution"]["achieved_error"].get<double>() == r["achieved_error"].get<double>());
}
