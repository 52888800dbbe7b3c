// A set validated in parts (validate_tables_in_parts, for sets larger than memory): a part
// interpolates exactly as the whole set does where it is measured, the parts tile the β axis, the
// merged report has the whole report's checks and shape, and a fault in any one part, or on a row
// two parts share, fails the set.
#include <cmath>
#include <filesystem>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/io/hdf5_io.hpp>
#include <hairlut/report/validate.hpp>
#include <hairlut/util/error.hpp>
#include <random>
#include <set>
#include <unistd.h>

#include "catch.hpp"

using namespace hairlut;
using json = nlohmann::json;
using ojson = nlohmann::ordered_json;
namespace fs = std::filesystem;

namespace {

TableSet parts_set() {
  const json j = json::parse(R"({
    "name": "parts-unit",
    "lobes": { "explicit": ["R", "TT", "TRT"], "residual": true },
    "quadrature": { "order": 128 },
    "tables": {
      "np": { "axes": {
        "theta_d": { "count": 10, "range_deg": [0, 80], "spacing": "cos" }, "phi": { "count": 33 },
        "sigma_a": { "count": 4, "range": [0, 2], "spacing": "sqrt" }, "beta": { "count": 12, "range_deg": [4, 40], "spacing": "log", "interpolation": "cubic" } } }
    },
    "output": { "basename": "p", "formats": ["hdf5"], "sampling_data": false } })");
  return bake(parse_config(j, "p.json", "/tmp"));
}

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hairlut-parts-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

const ojson& find_check(const ojson& report, const std::string& id) {
  for (const ojson& c : report["checks"])
    if (c["id"] == id) return c;
  FAIL("no check " << id);
  static const ojson none;
  return none;
}

// A budget that holds the tables other than N_p and `rows` β rows of the N_p tables.
std::uint64_t budget_for(const TableSet& set, int rows) {
  std::uint64_t rest = 0, row = 0;
  for (const Table& t : set.tables) {
    const std::uint64_t b = t.size() * (t.precision == Precision::float64 ? 8u : 4u);
    if (t.group == "np" && t.axes.size() == 4 && t.axes[0].name == "beta") row += b / static_cast<std::uint64_t>(t.axes[0].count);
    else rest += b;
  }
  return kValidationPartOverhead + rest + static_cast<std::uint64_t>(rows) * row;
}

}  // namespace

TEST_CASE("A part of a set interpolates as the whole set does over its own cells, and only with the row beyond each end", "[validate][parts]") {
  const fs::path file = scratch("interp.h5");
  write_hdf5(parts_set(), file);
  const TableSet whole = read_hdf5(file);
  Hdf5Rows rows;
  rows.first = 3, rows.count = 5;  // nodes 3 … 7: cells 4 to 6 measured, one node beyond each end
  const TableSet part = read_hdf5_rows(file, rows);
  rows.first = 4, rows.count = 3;  // nodes 4 … 6 alone: the cubic taps beyond them are missing
  const TableSet bare = read_hdf5_rows(file, rows);
  const Table& tw = *whole.find("np/TT");
  const Table& tp = *part.find("np/TT");
  const Table& tb = *bare.find("np/TT");
  REQUIRE(tp.axes[0].count == 5);
  REQUIRE(tp.size() == tw.size() / 12 * 5);
  const auto beta = tw.axes[0].nodes();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst_part = 0.0, worst_bare = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const double b = std::exp(std::log(beta[4]) + u(rng) * (std::log(beta[6]) - std::log(beta[4])));
    const std::vector<double> x = {b, 2.0 * u(rng) * u(rng), 1.3 * u(rng), 3.14159 * (2.0 * u(rng) - 1.0)};
    const double w = whole.sample_value(tw, x), scale = std::max(std::abs(w), 1e-3);
    worst_part = std::max(worst_part, std::abs(part.sample_value(tp, x) - w) / scale);
    worst_bare = std::max(worst_bare, std::abs(bare.sample_value(tb, x) - w) / scale);
  }
  CHECK(worst_part < 1e-12);  // the part's nodes are the whole axis's to rounding
  CHECK(worst_bare > 1e-6);   // without the taps beyond its ends a part would interpolate otherwise
  // Rows outside the axis are refused with the table named.
  rows.first = 10, rows.count = 5;
  CHECK_THROWS_WITH(read_hdf5_rows(file, rows), Catch::Contains("np/R") && Catch::Contains("rows 10 to 14"));
}

TEST_CASE("Validation in parts tiles the beta axis and gives the whole validation's checks and report shape", "[validate][parts]") {
  const fs::path file = scratch("tiles.h5");
  const TableSet baked = parts_set();
  write_hdf5(baked, file);
  ValidationOptions opt;
  opt.max_points = 2000;
  opt.seed = 11;
  ValidationOptions quick = opt;  // the whole set's run gives the checks to compare with: no search
  quick.search = false;
  const ojson whole = validate_tables(read_hdf5(file), "unit", quick);
  const ojson parts = validate_tables_in_parts(file, "unit", budget_for(baked, 5), opt);
  const ojson& list = parts["parts"]["parts"];
  REQUIRE(list.size() >= 3);
  const auto beta = baked.find("np/R")->axes[0].nodes();
  int next = 0;
  for (const ojson& p : list) {
    const int c0 = p["beta_nodes"][0], c1 = p["beta_nodes"][1];
    CHECK(c0 == next);
    CHECK(c1 > c0);
    CHECK(p["rows_read"][0].get<int>() == std::max(c0 - 1, 0));
    CHECK(p["rows_read"][1].get<int>() == std::min(c1 + 1, 11));
    CHECK(p["beta_range"][0].get<double>() == beta[static_cast<std::size_t>(c0)]);
    CHECK(p["bytes_held"].get<double>() < 0.6 * static_cast<double>(baked.bytes()));
    next = c1;
  }
  CHECK(next == 11);
  std::set<std::string> ids_whole, ids_parts;
  for (const ojson& c : whole["checks"]) ids_whole.insert(c["id"]);
  for (const ojson& c : parts["checks"]) ids_parts.insert(c["id"]);
  CHECK(ids_whole == ids_parts);
  // The model's furnace is judged at each part's own β nodes (first, middle, last of each).
  CHECK(find_check(parts, "furnace_direct")["value"].get<double>() < 1e-9);
  CHECK(parts["furnace"]["curves"].size() > whole["furnace"]["curves"].size());
  CHECK(find_check(parts, "sanity_values")["value"].get<double>() == 0.0);
  CHECK(find_check(parts, "sanity_values")["status"] == "pass");
  // One accuracy entry per table, over the whole β axis.
  int np_r = 0;
  for (const ojson& a : parts["accuracy"]) {
    if (a["path"] != "np/R") continue;
    ++np_r;
    CHECK(a["off_node"]["points"].get<std::size_t>() >= opt.max_points);
    for (const ojson& pa : a["per_axis"])
      if (pa["axis"] == "beta") CHECK(pa["cells_max_rel"].size() == 11);
    for (const ojson& h : a["heatmaps"])
      if (h["y"] == "beta") CHECK(h["max_rel"].size() == 11);
  }
  CHECK(np_r == 1);
  // Too small a budget is refused in one line that says what a part needs.
  CHECK_THROWS_WITH(validate_tables_in_parts(file, "unit", budget_for(baked, 2), opt), Catch::Contains("--memory-budget") && Catch::Contains("at least"));
}

TEST_CASE("A fault in one part, or on a row two parts share, fails the set validated in parts", "[validate][parts]") {
  TableSet set = parts_set();
  const std::uint64_t budget = budget_for(set, 5);  // parts of 3 cells: nodes 0-3, 3-6, 6-9, 9-11
  Table& tt = const_cast<Table&>(*set.find("np/TT"));
  const std::size_t row = tt.size() / 12;
  ValidationOptions opt;  // random points alone: the search is the test above's
  opt.max_points = 3000;
  opt.seed = 5;
  opt.search = false;
  SECTION("a slice scaled on a shared row") {
    // β node 6 ends part 2 and starts part 3; one (σa, θd) slice of it scaled by 1.3.
    const std::size_t slice = 33, at = 6 * row + (1 * 10 + 4) * slice;
    for (std::size_t i = 0; i < slice; ++i) tt.set(at + i, tt.get(at + i) * 1.3);
    const fs::path file = scratch("scaled.h5");
    write_hdf5(set, file);
    const ojson whole = validate_tables(read_hdf5(file), "unit", opt);
    const ojson parts = validate_tables_in_parts(file, "unit", budget, opt);
    const ojson& w = find_check(whole, "accuracy_max_rel");
    const ojson& p = find_check(parts, "accuracy_max_rel");
    INFO("whole " << w["value"] << ", parts " << p["value"] << ": " << p["detail"]);
    CHECK(w["value"].get<double>() > 0.05);
    CHECK(p["value"].get<double>() > 0.05);
    CHECK(p["status"] == "fail");
    CHECK(parts["summary"]["status"] == "fail");
  }
  SECTION("a NaN on a shared row is counted once") {
    tt.set(3 * row + 17, std::nan(""));
    const fs::path file = scratch("nan.h5");
    write_hdf5(set, file);
    bool loaded = true;
    try {
      (void)read_hdf5(file);
    } catch (const IoError&) {
      loaded = false;  // the loader refuses it before any check
    }
    if (loaded) {
      opt.max_points = 100;
      const ojson parts = validate_tables_in_parts(file, "unit", budget, opt);
      CHECK(find_check(parts, "sanity_values")["value"].get<double>() == 1.0);
      CHECK(find_check(parts, "sanity_values")["status"] == "fail");
    } else {
      CHECK_THROWS_AS(validate_tables_in_parts(file, "unit", budget, opt), IoError);
    }
  }
}
