// The baker and the table files: baked values against direct evaluation, exact round trips through
// HDF5 and OpenEXR, sampling, determinism across thread counts, up-to-date detection, lobe folding,
// scene mode, and clear errors for bad files.
#include <hdf5.h>

#include <Imath/half.h>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <hairlut/hairlut.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/physics/melanin.hpp>
#include <hairlut/io/hdf5_io.hpp>
#include <hairlut/bake/outputs.hpp>
#include <hairlut/io/table_io.hpp>
#include <hairlut/report/validate.hpp>
#include <random>
#include <sstream>
#include <tuple>
#include <unistd.h>

#include "catch.hpp"

using namespace hairlut;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hairlut-test-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

json small_config() {
  return json::parse(R"({
    "name": "unit",
    "lobes": { "explicit": ["R", "TT", "TRT", "TRRT"], "residual": true, "tilt_deg": { "R": -4, "TT": 2, "TRT": 6, "residual": 8 } },
    "quadrature": { "method": "gauss-legendre", "order": 96 },
    "tables": {
      "np": { "axes": {
        "theta_d": { "count": 5, "range_deg": [0, 85], "spacing": "cos" },
        "phi": { "count": 9, "symmetry": "even" },
        "sigma_a": { "count": 3, "range": [0, 4], "spacing": "sqrt" },
        "beta": { "count": 3, "range_deg": [8, 40], "spacing": "log" } } },
      "mp": { "axes": {
        "theta_i": { "count": 7, "range_deg": [-90, 90], "spacing": "sin" },
        "theta_r": { "count": 9, "range_deg": [-90, 90] },
        "beta": { "count": 2, "range_deg": [5, 20] } } },
      "melanin": { "axes": { "eumelanin": { "count": 4, "range": [0, 8] }, "pheomelanin": { "count": 3, "range": [0, 2] } } }
    },
    "output": { "basename": "unit", "formats": ["hdf5", "exr"] }
  })");
}

BakeConfig config_in(const fs::path& dir, const json& j = small_config()) { return parse_config(j, "unit.json", dir); }

std::string file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out << bytes;
}

std::string io_error(const fs::path& p) {
  try {
    load_tables(p);
  } catch (const IoError& e) {
    return e.what();
  }
  return "(loaded)";
}

}  // namespace

TEST_CASE("Baked N_p, energies and M_p equal direct evaluation at the nodes", "[bake]") {
  const BakeConfig c = config_in(temp_dir("direct"));
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  REQUIRE(set.find("np/TRT") != nullptr);
  const Table& t = *set.find("np/TRT");
  REQUIRE(t.axes.size() == 4);
  const auto betas = t.axes[0].nodes(), sigmas = t.axes[1].nodes(), thetas = t.axes[2].nodes(), phis = t.axes[3].nodes();
  const GaussLegendreRule rule(96), energy_rule(128);
  std::size_t k = 0;
  for (double b : betas)
    for (double s : sigmas)
      for (double th : thetas)
        for (double ph : phis) {
          const AttenuationSlice slice(1.55, th, s);
          CHECK(t.f32[k++] == static_cast<float>(azimuthal_np(slice, 2, b, ph, rule)));
        }
  const Table& e = *set.find("np/energy_TT");
  const Table& r = *set.find("np/residual");
  k = 0;
  for (double s : sigmas)
    for (double th : thetas) {
      const auto ref = lobe_energies(AttenuationSlice(1.55, th, s), {4, true}, energy_rule);
      CHECK(e.f32[k] == static_cast<float>(ref[1]));
      CHECK(r.f32[k] == static_cast<float>(ref[4] / kTwoPi));
      ++k;
    }
  const Table& m = *set.find("mp/R");
  const auto mb = m.axes[0].nodes(), mi = m.axes[1].nodes(), mr = m.axes[2].nodes();
  k = 0;
  for (double b : mb)
    for (double ti : mi)
      for (double tr : mr) CHECK(m.f32[k++] == static_cast<float>(longitudinal_deon_tilted(b * b, radians(-4.0), ti, tr)));
  CHECK(set.find("mp/TRRT")->attributes["alpha"].get<double>() == 0.0);  // not listed in tilt_deg
  CHECK(set.find("mp/residual")->attributes["alpha"].get<double>() == Approx(radians(8.0)));
  // Melanin: d'Eon's cross-sections.
  const Table& mel = *set.find("melanin/sigma_a_deon");
  const auto ce = mel.axes[0].nodes(), cp = mel.axes[1].nodes();
  const Rgb rgb = melanin_sigma_a_rgb(ce[2], cp[1]);
  CHECK(mel.f32[(2 * cp.size() + 1) * 3 + 2] == static_cast<float>(rgb.b));
  CHECK(report.entries > 0);
  CHECK(report.folded.empty());
}

TEST_CASE("The Fourier method bakes N_p to the tolerance of the adaptive reference", "[bake]") {
  json j = small_config();
  j["quadrature"] = {{"method", "fourier"}, {"tolerance", 1e-12}};
  j["output"]["hdf5"] = {{"precision", "float64"}};
  j["tables"]["np"]["axes"]["beta"] = {{"values_deg", {0.5, 2.0, 20.0}}};
  j["tables"]["np"]["axes"]["sigma_a"] = {{"values", {0.0, 0.7, 30.0}}};
  const TableSet set = bake(config_in(temp_dir("fourier"), j));
  for (const char* name : {"np/R", "np/TT", "np/TRT", "np/TRRT"}) {
    const Table& t = *set.find(name);
    REQUIRE(t.precision == Precision::float64);
    const int p = t.attributes["p"].get<int>();
    const auto betas = t.axes[0].nodes(), sigmas = t.axes[1].nodes(), thetas = t.axes[2].nodes(), phis = t.axes[3].nodes();
    double worst = 0.0;
    for (std::size_t b = 0; b < betas.size(); ++b)
      for (std::size_t k = 0; k < sigmas.size(); ++k)
        for (std::size_t it = 0; it < thetas.size(); ++it) {
          const AttenuationSlice slice(1.55, thetas[it], sigmas[k]);
          std::vector<double> ref;
          double peak = 0.0;
          for (double ph : phis) ref.push_back(azimuthal_np_reference(slice, p, betas[b], ph, 1e-13).value[0]), peak = std::max(peak, ref.back());
          if (peak < 1e-250) continue;
          for (std::size_t ip = 0; ip < phis.size(); ++ip)
            worst = std::max(worst, std::abs(t.f64[((b * sigmas.size() + k) * thetas.size() + it) * phis.size() + ip] - ref[ip]) / peak);
        }
    INFO(name << ": largest error relative to the slice peak " << worst);
    CHECK(worst < 1e-10);
  }
}

TEST_CASE("A target error picks the N_p resolution and the baked table reaches it", "[bake]") {
  json j = small_config();
  j["tables"].erase("mp");
  j["tables"].erase("melanin");
  j["tables"]["np"]["target_error"] = 0.03;
  j["tables"]["np"]["target_points"] = 4000;  // the validator's default is 40,000 (slower)
  const BakeConfig c = config_in(temp_dir("target"), j);
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  REQUIRE(report.resolution.is_object());
  const double achieved = report.resolution["achieved_error"].get<double>();
  INFO(report.resolution.dump());
  CHECK(achieved <= 0.03);
  CHECK(achieved > 0.0);
  CHECK(set.metadata["resolution"]["counts"]["phi"].get<int>() >= 9);
  // The chosen counts are in the table, and a smaller target needs more nodes.
  CHECK(set.find("np/TT")->axes[3].count == set.metadata["resolution"]["counts"]["phi"].get<int>());
  // target_error accepts on points the plan never probed and a worst-point search; an independent
  // search by the validator (other random points, its own seed) finds nothing much worse than the
  // target: within 1.5 times it.
  ValidationOptions vo;
  vo.max_points = 4000;
  vo.seed = 12345;
  const auto v = validate_tables(set, "target", vo);
  double validator_worst = 0.0;
  for (const auto& acc : v["accuracy"]) {
    if (acc["kind"] == "np") validator_worst = std::max(validator_worst, acc["worst"]["max_rel"].get<double>());
  }
  INFO("validator's worst found " << validator_worst << ", target_error's " << achieved);
  CHECK(validator_worst <= 1.5 * 0.03);
  j["tables"]["np"]["target_error"] = 0.01;
  BakeReport finer;
  bake(config_in(temp_dir("target2"), j), {}, &finer);
  CHECK(finer.resolution["entries_per_lobe"].get<std::size_t>() > report.resolution["entries_per_lobe"].get<std::size_t>());
  CHECK(finer.resolution["achieved_error"].get<double>() <= 0.01);
}

TEST_CASE("A target error weighs beta bands against one table and keeps the fewest entries", "[bake]") {
  json j = small_config();  // β 8°–40°: three bands of at most an octave compete
  j["tables"].erase("mp");
  j["tables"].erase("melanin");
  j["tables"]["np"]["target_error"] = 0.02;
  j["tables"]["np"]["target_points"] = 4000;
  BakeReport report;
  const TableSet set = bake(config_in(temp_dir("target_bands"), j), {}, &report);
  const json& r = report.resolution;
  INFO(r.dump());
  REQUIRE(r.contains("entries_beta_bands"));
  REQUIRE(r.contains("entries_shape_cubic"));
  std::size_t fewest = std::min(r["entries_beta_bands"].get<std::size_t>(), r["entries_shape_cubic"].get<std::size_t>());
  for (const char* k : {"entries_as_configured", "entries_fourier"})
    if (r.contains(k)) fewest = std::min(fewest, r[k].get<std::size_t>());
  CHECK(r["entries_per_lobe"].get<std::size_t>() == fewest);
  CHECK(r["achieved_error"].get<double>() <= 0.02);
  const bool bands = r["representation"].get<std::string>().find("beta bands") != std::string::npos;
  CHECK(bands == (r["entries_per_lobe"] == r["entries_beta_bands"]));
  if (bands) {
    // The bands tile β without gaps, each baked as its own table, and their entries add up.
    REQUIRE(set.metadata.contains("np_beta_bands"));
    const std::size_t n = set.metadata["np_beta_bands"].size();
    REQUIRE(n == r["bands"].size());
    std::size_t entries = 0;
    double lo = 8.0 * kPi / 180.0;
    for (std::size_t k = 0; k < n; ++k) {
      const Table* t = set.find(std::string("np/TT") + (k ? "_band" + std::to_string(k) : std::string()));
      REQUIRE(t);
      CHECK(t->axes[0].lo == Approx(lo).epsilon(1e-12));
      lo = t->axes[0].hi;
      entries += t->size();
    }
    CHECK(lo == Approx(40.0 * kPi / 180.0).epsilon(1e-12));
    CHECK(entries == r["entries_per_lobe"].get<std::size_t>());
  }
}

TEST_CASE("HDF5 and OpenEXR round trips return exactly what was baked", "[io]") {
  const fs::path dir = temp_dir("roundtrip");
  json j = small_config();
  j["output"]["exr"] = {{"precision", "half"}};
  const BakeConfig c = config_in(dir, j);
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  const auto files = write_outputs(set, c, report);
  REQUIRE(files.size() == 3);
  const TableSet h5 = load_tables(output_paths(c).hdf5);
  const TableSet exr = load_tables(output_paths(c).exr);
  REQUIRE(h5.tables.size() == set.tables.size());
  REQUIRE(exr.tables.size() == set.tables.size());
  CHECK(h5.metadata == set.metadata);
  CHECK(exr.metadata == set.metadata);
  for (const Table& t : set.tables) {
    INFO(t.path());
    const Table* a = h5.find(t.path());
    const Table* b = exr.find(t.path());
    REQUIRE(a);
    REQUIRE(b);
    CHECK(a->f32 == t.f32);  // bit-exact
    CHECK(a->f64 == t.f64);  // the float64 tables (sampling data) too
    REQUIRE(b->f32.size() == t.size());
    std::size_t mismatches = 0;
    for (std::size_t i = 0; i < t.size(); ++i)
      if (b->f32[i] != static_cast<float>(half(static_cast<float>(t.get(i))))) ++mismatches;
    CHECK(mismatches == 0);
    CHECK(a->describe() == t.describe());
    CHECK(b->describe() == t.describe());
  }
  // Sampling the loaded table at its nodes returns the stored values.
  const Table& np = *h5.find("np/TT");
  std::vector<std::vector<double>> nodes;
  for (const GridAxis& ax : np.axes) nodes.push_back(ax.nodes());
  std::size_t k = 0;
  for (double b : nodes[0])
    for (double s : nodes[1])
      for (double th : nodes[2])
        for (double ph : nodes[3]) CHECK(np.sample({b, s, th, ph}) == static_cast<double>(np.f32[k++]));
  // Between nodes the multilinear value lies within the range of the surrounding nodes.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    std::vector<double> x(4);
    for (std::size_t d = 0; d < 4; ++d) x[d] = nodes[d].front() + u(rng) * (nodes[d].back() - nodes[d].front());
    const double v = np.sample(x);
    CHECK(std::isfinite(v));
    CHECK(v >= 0.0);
  }
}

TEST_CASE("Output is bit-identical for any thread count", "[bake]") {
  std::vector<std::string> bytes;
  for (int threads : {1, 2, 3}) {
    const fs::path dir = temp_dir("threads" + std::to_string(threads));
    const BakeConfig c = config_in(dir);
    BakeOptions opt;
    opt.threads = threads;
    BakeReport report;
    const TableSet set = bake(c, opt, &report);
    write_outputs(set, c, report);
    bytes.push_back(file_bytes(output_paths(c).hdf5) + file_bytes(output_paths(c).exr) + file_bytes(output_paths(c).sidecar));
  }
  CHECK(bytes[0].size() > 1000);
  CHECK(bytes[0] == bytes[1]);
  CHECK(bytes[0] == bytes[2]);
}

TEST_CASE("Up-to-date detection follows the config, the version and the files", "[io]") {
  const fs::path dir = temp_dir("uptodate");
  const BakeConfig c = config_in(dir);
  CHECK_FALSE(outputs_up_to_date(c));
  BakeReport report;
  write_outputs(bake(c, {}, &report), c, report);
  CHECK(outputs_up_to_date(c));
  json changed = small_config();
  changed["fiber"] = {{"eta", 1.56}};
  CHECK_FALSE(outputs_up_to_date(config_in(dir, changed)));
  json reordered = json::parse(small_config().dump());  // same content, different key order in the text
  CHECK(config_in(dir, reordered).hash == c.hash);
  fs::remove(output_paths(c).exr);
  CHECK_FALSE(outputs_up_to_date(c));
  // No temporary files are left behind.
  for (const auto& e : fs::directory_iterator(dir)) CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);
}

TEST_CASE("Cancelling stops the bake and the writer leaves nothing behind", "[bake]") {
  const fs::path dir = temp_dir("cancel");
  const BakeConfig c = config_in(dir);
  std::atomic<bool> cancel{true};
  BakeOptions opt;
  opt.cancel = &cancel;
  CHECK_THROWS_AS(bake(c, opt), BakeCancelled);
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  CHECK_THROWS_AS(write_outputs(set, c, report, &cancel), BakeCancelled);
  CHECK(fs::is_empty(dir));
}

TEST_CASE("Lobes below fold_below are folded into the residual and reported", "[bake]") {
  json j = small_config();
  j["lobes"]["fold_below"] = 0.02;
  j["tables"]["np"]["axes"]["sigma_a"] = {{"count", 2}, {"range", {2.0, 6.0}}};
  const BakeConfig c = config_in(temp_dir("fold"), j);
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  REQUIRE_FALSE(report.folded.empty());
  CHECK(report.folded.back().lobe == "TRRT");
  CHECK(report.folded.back().max_energy < 0.02);
  CHECK(set.find("np/TRRT") == nullptr);
  CHECK(set.metadata["folded_lobes"].size() == report.folded.size());
  // The residual now starts at the first folded lobe.
  const int P = report.explicit_lobes;
  const Table& res = *set.find("np/energy_residual");
  const auto sig = res.axes[0].nodes(), th = res.axes[1].nodes();
  const auto ref = lobe_energies(AttenuationSlice(1.55, th[2], sig[1]), {P, true}, GaussLegendreRule(128));
  CHECK(res.f32[1 * th.size() + 2] == static_cast<float>(ref.back()));
}

TEST_CASE("Scene mode bakes only what the materials need", "[bake]") {
  json j = small_config();
  j["scene"] = json::parse(R"({ "mode": "per-material", "materials": [
      { "name": "blonde", "melanin": { "eumelanin": 0.3, "pheomelanin": 0.1 }, "beta_deg": { "R": 6, "TT": 3, "TRT": 12 } },
      { "name": "grey", "sigma_a": [0.2, 0.25, 0.3], "beta_deg": { "R": 9 } } ] })");
  const BakeConfig c = config_in(temp_dir("scene"), j);
  const TableSet set = bake(c);
  CHECK(set.find("np/R") == nullptr);  // no generic table
  const Table* trt = set.find("materials/blonde/np_TRT");
  REQUIRE(trt);
  REQUIRE(trt->axes.size() == 3);
  CHECK(trt->axes[0].name == "channel");
  const Rgb s = melanin_sigma_a_rgb(0.3, 0.1);
  const auto th = trt->axes[1].nodes(), ph = trt->axes[2].nodes();
  const GaussLegendreRule rule(96);
  // Blue channel, θd node 3, φ node 4; TRRT (not listed) takes TRT's roughness.
  CHECK(trt->f32[(2 * th.size() + 3) * ph.size() + 4] == static_cast<float>(azimuthal_np(AttenuationSlice(1.55, th[3], s.b), 2, radians(12.0), ph[4], rule)));
  CHECK(set.find("materials/blonde/np_TRRT")->attributes["beta"].get<double>() == Approx(radians(12.0)));
  CHECK(set.find("materials/grey/np_TT")->attributes["beta"].get<double>() == Approx(radians(9.0)));
  CHECK(set.find("materials/grey/mp_R") != nullptr);
  // restrict-generic: generic axes narrowed to the materials' sigma_a and beta ranges.
  j["scene"]["mode"] = "restrict-generic";
  const BakeConfig r = config_in(temp_dir("scene2"), j);
  std::vector<std::string> notes;
  const auto axes = restricted_np_axes(r, &notes);
  CHECK(axes[1].lo == Approx(std::min(s.r, 0.2)));
  CHECK(axes[1].hi == Approx(std::max(s.b, 0.3)));
  CHECK(axes[0].lo == Approx(radians(3.0)));
  CHECK(axes[0].hi == Approx(radians(12.0)));
  CHECK(notes.size() == 2);
}

TEST_CASE("Bad table files give one-line errors", "[io]") {
  const fs::path dir = temp_dir("bad");
  const BakeConfig c = config_in(dir);
  BakeReport report;
  write_outputs(bake(c, {}, &report), c, report);
  const fs::path h5 = output_paths(c).hdf5, exr = output_paths(c).exr;
  const std::string h5b = file_bytes(h5), exrb = file_bytes(exr);

  CHECK(io_error(dir / "missing.h5").find("cannot open file") != std::string::npos);
  write_bytes(dir / "text.h5", "hello, not a table");
  CHECK(io_error(dir / "text.h5").find("not a hairlut table file") != std::string::npos);
  // Truncated files.
  write_bytes(dir / "trunc.h5", h5b.substr(0, h5b.size() / 2));
  CHECK(io_error(dir / "trunc.h5").rfind((dir / "trunc.h5").string() + ": ", 0) == 0);
  write_bytes(dir / "trunc.exr", exrb.substr(0, exrb.size() / 2));
  CHECK(io_error(dir / "trunc.exr").find("truncated or corrupted") != std::string::npos);
  // Corrupted bytes anywhere: the loader either rejects the file with a one-line error or returns
  // exactly the original content (bytes in unused space change nothing); it never crashes and
  // never returns altered values.
  const TableSet original_h5 = load_tables(h5), original_exr = load_tables(exr);
  std::mt19937 rng(11);
  std::size_t rejected = 0, trials = 0;
  for (const auto& [bytes, original, ext] : {std::tuple{h5b, &original_h5, ".h5"}, std::tuple{exrb, &original_exr, ".exr"}}) {
    std::uniform_int_distribution<std::size_t> pos(0, bytes.size() - 8);
    for (int trial = 0; trial < 60; ++trial) {
      std::string bad = bytes;
      const std::size_t offset = pos(rng);
      for (std::size_t i = 0; i < 8; ++i) bad[offset + i] = static_cast<char>(bad[offset + i] ^ 0x5a);
      const fs::path p = dir / (std::string("corrupt") + ext);
      write_bytes(p, bad);
      ++trials;
      try {
        const TableSet got = load_tables(p);
        CHECK(content_checksum(got) == content_checksum(*original));
      } catch (const IoError& e) {
        ++rejected;
        CHECK(std::string(e.what()).find('\n') == std::string::npos);
      }
    }
  }
  CHECK(rejected > trials / 4);
  // A table whose metadata attribute was removed.
  fs::copy_file(h5, dir / "nometa.h5");
  {
    const hid_t f = H5Fopen((dir / "nometa.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const hid_t d = H5Dopen2(f, "/np/TT", H5P_DEFAULT);
    H5Adelete(d, "hairlut_table");
    H5Dclose(d);
    H5Fclose(f);
  }
  CHECK(io_error(dir / "nometa.h5").find("np/TT: missing attribute hairlut_table") != std::string::npos);
  // An HDF5 file that is not a hairlut table file.
  {
    const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_LATEST);
    const hid_t f = H5Fcreate((dir / "other.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    H5Fclose(f);
    H5Pclose(fapl);
  }
  CHECK(io_error(dir / "other.h5").find("missing attribute hairlut_metadata") != std::string::npos);
}

TEST_CASE("A normalized N_p table is read as shape times energy, and a signed theta_d folds to its magnitude", "[bake][sampler]") {
  json j = small_config();
  j["quadrature"] = {{"method", "fourier"}, {"tolerance", 1e-12}};
  j["tables"]["np"]["normalize"] = "energy";
  j["tables"]["np"]["axes"]["phi"]["interpolation"] = "cubic";
  j["tables"]["np"]["energy_axes"] = {{"sigma_a", {{"count", 9}, {"range", {0, 4}}, {"interpolation", "geometric"}}},
                                      {"theta_d", {{"count", 17}, {"range_deg", {0, 85}}, {"spacing", "cos"}, {"interpolation", "cubic"}}}};
  const fs::path dir = temp_dir("normalized");
  const TableSet set = bake(config_in(dir, j));
  const Table& trt = *set.find("np/TRT");
  REQUIRE(trt.factor() == "np/energy_TRT");
  const Table& e = *set.find("np/energy_TRT");
  CHECK(e.axes[0].count == 9);
  CHECK(e.axes[1].count == 17);
  // At the nodes of N_p, shape x energy is the baked N_p: compare with direct evaluation there.
  const auto betas = trt.axes[0].nodes(), sigmas = trt.axes[1].nodes(), thetas = trt.axes[2].nodes(), phis = trt.axes[3].nodes();
  const AttenuationSlice slice(1.55, thetas[2], sigmas[1]);
  const double exact = azimuthal_np_reference(slice, 2, betas[1], phis[3], 1e-12).value[0];
  CHECK(set.sample_value(trt, {betas[1], sigmas[1], thetas[2], phis[3]}) == Approx(exact).epsilon(2e-6));
  // The shape integrates to one over phi at every node (even phi axis: trapezoid over [0, pi], twice).
  double integral = 0.0;
  for (std::size_t k = 0; k < phis.size(); ++k) {
    const double w = (k == 0 || k + 1 == phis.size() ? 0.5 : 1.0) * (phis[1] - phis[0]);
    integral += w * trt.sample({betas[1], sigmas[1], thetas[2], phis[k]});
  }
  CHECK(2.0 * integral == Approx(1.0).epsilon(1e-5));
  // theta_d is folded: N_p at -20 degrees is N_p at +20 degrees (it depends on cos theta_d only).
  const double t = radians(20.0);
  CHECK(set.sample_value(trt, {betas[1], 1.3, -t, 0.5}) == set.sample_value(trt, {betas[1], 1.3, t, 0.5}));
  // The HDF5 file keeps the energy table's own sigma_a and theta_d scales apart from N_p's.
  write_hdf5(set, dir / "n.h5");
  const TableSet back = load_tables(dir / "n.h5");
  CHECK(back.find("np/energy_TRT")->axes[1].count == 17);
  CHECK(back.sample_value(*back.find("np/TRT"), {betas[1], 1.3, t, 0.5}) == set.sample_value(trt, {betas[1], 1.3, t, 0.5}));
}

TEST_CASE("Chunks deflated on the writer's threads are the bytes HDF5's own filters store", "[io]") {
  // Tables of several chunks (the last one partial) in float32 and float64 and one of a single
  // chunk, written by write_hdf5 on 1 and 3 threads. The reference: HDF5 itself filtering the same
  // values with the same creation properties (H5Dwrite into a second file); every stored chunk
  // (H5Dread_chunk: its bytes and filter mask) must be equal, and the values read back exact.
  const fs::path dir = temp_dir("chunks");
  auto axis = [](const std::string& name, int n) {
    GridAxis a;
    a.name = name, a.units = "1", a.lo = 0.0, a.hi = 1.0, a.count = n;
    return a;
  };
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 1e-3);
  TableSet set;
  auto add = [&](const std::string& name, std::vector<GridAxis> axes, Precision p) {
    Table t;
    t.group = "test", t.name = name, t.quantity = "energy", t.units = "1", t.long_name = name;
    t.axes = std::move(axes);
    t.allocate(p);
    for (std::size_t i = 0; i < t.size(); ++i) t.set(i, 1.0 + std::sin(1e-3 * static_cast<double>(i)) + noise(rng));
    set.tables.push_back(std::move(t));
  };
  add("f32_chunks", {axis("x", 37), axis("y", 160), axis("z", 200)}, Precision::float32);  // 4.5 MiB: chunks of 32 and 5 rows
  add("f64_chunks", {axis("x", 9), axis("y", 100), axis("z", 700)}, Precision::float64);   // 4.8 MiB: 7 and 2 rows
  add("f32_one", {axis("x", 50), axis("y", 60)}, Precision::float32);                       // 12 KB: one chunk
  std::vector<std::string> files;
  for (int threads : {1, 3}) {
    const fs::path p = dir / ("t" + std::to_string(threads) + ".h5");
    write_hdf5(set, p, {6, threads});
    files.push_back(file_bytes(p));
  }
  CHECK(files[0] == files[1]);

  const fs::path ours = dir / "t3.h5", ref = dir / "ref.h5";
  const hid_t fo = H5Fopen(ours.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t fr = H5Fcreate(ref.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  REQUIRE(fo >= 0);
  REQUIRE(fr >= 0);
  std::size_t chunks_compared = 0;
  for (const Table& t : set.tables) {
    INFO(t.path());
    const hid_t d = H5Dopen2(fo, t.path().c_str(), H5P_DEFAULT);
    REQUIRE(d >= 0);
    const hid_t dcpl = H5Dget_create_plist(d), space = H5Dget_space(d), type = H5Dget_type(d);
    REQUIRE(H5Pget_layout(dcpl) == H5D_CHUNKED);
    REQUIRE(H5Pget_nfilters(dcpl) == 3);
    const bool dbl = t.precision == Precision::float64;
    const hid_t mem = dbl ? H5T_NATIVE_DOUBLE : H5T_NATIVE_FLOAT;
    const void* values = dbl ? static_cast<const void*>(t.f64.data()) : static_cast<const void*>(t.f32.data());
    const hid_t r = H5Dcreate2(fr, t.name.c_str(), type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    REQUIRE(r >= 0);
    REQUIRE(H5Dwrite(r, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, values) >= 0);
    REQUIRE(H5Dflush(r) >= 0);  // chunks smaller than the chunk cache are stored on a flush
    // The values read back through HDF5's pipeline (it checks Fletcher-32 on the way).
    std::vector<unsigned char> back(t.size() * (dbl ? 8 : 4));
    REQUIRE(H5Dread(d, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, back.data()) >= 0);
    CHECK(std::memcmp(back.data(), values, back.size()) == 0);
    hsize_t count = 0;
    REQUIRE(H5Dget_num_chunks(d, space, &count) >= 0);
    CHECK(count == (t.name == "f32_one" ? 1u : 2u));
    for (hsize_t k = 0; k < count; ++k) {
      hsize_t offset[3] = {0, 0, 0}, size = 0, size_ref = 0;
      unsigned mask = 0;
      haddr_t addr = 0;
      REQUIRE(H5Dget_chunk_info(d, space, k, offset, &mask, &addr, &size) >= 0);
      REQUIRE(H5Dget_chunk_storage_size(r, offset, &size_ref) >= 0);
      std::vector<unsigned char> a(size), b(size_ref);
      std::uint32_t ma = 1, mb = 1;
      REQUIRE(H5Dread_chunk(d, H5P_DEFAULT, offset, &ma, a.data()) >= 0);
      REQUIRE(H5Dread_chunk(r, H5P_DEFAULT, offset, &mb, b.data()) >= 0);
      CHECK(ma == mb);
      CHECK(a == b);
      ++chunks_compared;
    }
    H5Dclose(r), H5Tclose(type), H5Sclose(space), H5Pclose(dcpl), H5Dclose(d);
  }
  CHECK(chunks_compared == 5);
  H5Fclose(fr), H5Fclose(fo);
}
