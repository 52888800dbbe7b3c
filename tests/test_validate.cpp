// The validator: its checks pass on correct tables and fail on broken ones, and its reported
// off-node error bounds the error of the sampler at other points between the nodes.
#include <cmath>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/util/error.hpp>
#include <hairlut/report/report.hpp>
#include <hairlut/report/validate.hpp>
#include <hairlut/physics/azimuthal_np.hpp>
#include <hairlut/physics/longitudinal_mp.hpp>
#include <random>

#include "catch.hpp"

using namespace hairlut;
using json = nlohmann::json;
using ojson = nlohmann::ordered_json;

namespace {

TableSet small_set() {
  const json j = json::parse(R"({
    "name": "validate-unit",
    "lobes": { "explicit": ["R", "TT", "TRT"], "residual": true, "tilt_deg": { "R": -3 } },
    "quadrature": { "order": 128 },
    "tables": {
      "np": { "axes": {
        "theta_d": { "count": 6, "range_deg": [0, 80], "spacing": "cos" }, "phi": { "count": 25 },
        "sigma_a": { "count": 3, "range": [0, 2], "spacing": "sqrt" }, "beta": { "count": 3, "range_deg": [8, 30], "spacing": "log" } } },
      "mp": { "axes": { "theta_i": { "count": 13, "range_deg": [-90, 90] }, "theta_r": { "count": 25, "range_deg": [-90, 90] },
                        "beta": { "count": 2, "range_deg": [10, 30] } } }
    },
    "output": { "basename": "v", "formats": ["hdf5"] } })");
  return bake(parse_config(j, "v.json", "/tmp"));
}

const ojson& find_check(const ojson& report, const std::string& id) {
  for (const ojson& c : report["checks"])
    if (c["id"] == id) return c;
  FAIL("no check " << id);
  static const ojson none;
  return none;
}

}  // namespace

TEST_CASE("Correct tables pass the energy, sanity and paper checks", "[validate]") {
  const TableSet set = small_set();
  ValidationOptions opt;
  opt.max_points = 4000;
  const auto r = validate_tables(set, "unit", opt);
  for (const char* id : {"sanity_values", "sanity_lobes", "sanity_metadata", "furnace_direct", "furnace_table", "paper_truncation",
                         "longitudinal_deon", "paper_gaussian"})
    CHECK(find_check(r, id)["status"] == "pass");
  CHECK(find_check(r, "furnace_direct")["value"].get<double>() < 1e-9);
  CHECK(r["summary"]["failed"].get<int>() + r["summary"]["passed"].get<int>() + r["summary"]["skipped"].get<int>() ==
        static_cast<int>(r["checks"].size()));
  const std::string html = render_report_html(r);
  CHECK(html.find("<svg") != std::string::npos);
  CHECK(html.find("<script") == std::string::npos);
  CHECK(render_report_markdown(r).rfind("# hairlut validation: ", 0) == 0);
}

TEST_CASE("The reported off-node error bounds the sampler's error at other points", "[validate]") {
  const TableSet set = small_set();
  ValidationOptions opt;
  opt.max_points = 8000;  // random points per table
  opt.seed = 2;           // a fixed search, so that the test gives the same verdict in every run
  const auto r = validate_tables(set, "unit", opt);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const GaussLegendreRule rule(1024);
  for (const ojson& acc : r["accuracy"]) {
    const std::string path = acc["path"];
    if (path != "np/TRT" && path != "np/R" && path != "mp/R") continue;
    const Table& t = *set.find(path);
    const double reported = acc["off_node"]["max_abs"].get<double>();
    double worst = 0.0;
    for (int i = 0; i < 400; ++i) {
      std::vector<double> x;
      for (const GridAxis& a : t.axes) {
        const auto n = a.nodes();
        x.push_back(n.front() + u(rng) * (n.back() - n.front()));
      }
      double exact;
      if (t.quantity == "N_p") exact = azimuthal_np(AttenuationSlice(1.55, x[2], x[1]), t.attributes["p"].get<int>(), x[0], x[3], rule);
      else exact = longitudinal_deon_tilted(x[0] * x[0], t.attributes["alpha"].get<double>(), x[1], x[2]);
      worst = std::max(worst, std::abs(t.sample(x) - exact));
    }
    INFO(path << ": random-point error " << worst << ", reported " << reported);
    CHECK(worst <= 1.5 * reported);
  }
}

TEST_CASE("Broken tables fail the sanity checks", "[validate]") {
  ValidationOptions opt;
  opt.max_points = 500;
  {
    TableSet set = small_set();
    for (Table& t : set.tables)
      if (t.path() == "np/TT") t.set(5, NAN);
    CHECK(find_check(validate_tables(set, "nan", opt), "sanity_values")["status"] == "fail");
  }
  {
    TableSet set = small_set();
    std::erase_if(set.tables, [](const Table& t) { return t.path() == "np/TT"; });
    const auto r = validate_tables(set, "missing", opt);
    CHECK(find_check(r, "sanity_lobes")["status"] == "fail");
    CHECK(find_check(r, "sanity_lobes")["detail"].get<std::string>().find("np/TT") != std::string::npos);
    CHECK(r["summary"]["status"] == "fail");
  }
  {
    TableSet set = small_set();
    set.metadata["config_hash"] = "0000000000000000";
    CHECK(find_check(validate_tables(set, "hash", opt), "sanity_metadata")["status"] == "fail");
  }
  {
    TableSet set = small_set();
    set.metadata.erase("lobes");
    CHECK_THROWS_AS(validate_tables(set, "nolobes", opt), DomainError);
  }
  ValidationThresholds th;
  CHECK_THROWS_AS(th.set("accuracy", 0.1), DomainError);
  CHECK_THROWS_AS(th.set("accuracy_max_rel", -1.0), DomainError);
  th.set("accuracy_max_rel", 0.2);
  CHECK(th.accuracy_max_rel == 0.2);
}
