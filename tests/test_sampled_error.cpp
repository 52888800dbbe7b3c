// The sampled-error measure (error where a renderer samples): it finds interpolation errors known
// in closed form, applies the denominator rules of the conventions, is deterministic for any thread
// count, and the validator fails a table that is exact at its nodes but wrong between them.
#include <algorithm>
#include <cmath>
#include <hairlut/util/angles.hpp>
#include <hairlut/physics/azimuthal_np.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/sampled_error.hpp>
#include <hairlut/bake/table_truth.hpp>
#include <hairlut/report/validate.hpp>

#include "catch.hpp"

using namespace hairlut;
using json = nlohmann::json;

namespace {

GridAxis axis(const std::string& name, double lo, double hi, int count, Interpolation interp = Interpolation::linear) {
  GridAxis a;
  a.name = name;
  a.units = "1";
  a.lo = lo, a.hi = hi, a.count = count;
  a.interpolation = interp;
  return a;
}

// A float64 table of f over the axes' nodes.
Table tabulate(const std::vector<GridAxis>& axes, const std::function<double(const std::vector<double>&)>& f) {
  Table t;
  t.group = "test", t.name = "f", t.quantity = "energy";
  t.axes = axes;
  t.allocate(Precision::float64);
  std::vector<std::vector<double>> nodes;
  for (const GridAxis& a : axes) nodes.push_back(a.nodes());
  std::vector<double> x(axes.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    std::size_t r = i;
    for (std::size_t k = axes.size(); k-- > 0;) {
      x[k] = nodes[k][r % nodes[k].size()];
      r /= nodes[k].size();
    }
    t.set(i, f(x));
  }
  return t;
}

// A reference from a closed form, relative to max(|f|, floor).
TableTruth closed_form(std::function<double(const std::vector<double>&)> f, double floor) {
  TableTruth tr;
  tr.make = [f](const std::vector<double>&) { return PointFunction(f); };
  tr.absolute_floor = floor;
  tr.denominator = "test";
  return tr;
}

}  // namespace

TEST_CASE("The sampled error finds linear interpolation's error of x^2 (h^2/4 worst, h^2/6 mean)", "[sampled_error]") {
  TableSet set;
  const int n = 11;  // h = 0.1
  set.tables.push_back(tabulate({axis("x", 0.0, 1.0, n)}, [](const std::vector<double>& x) { return x[0] * x[0]; }));
  const TableTruth tr = closed_form([](const std::vector<double>& x) { return x[0] * x[0]; }, 1.0);  // denominator 1: absolute error
  SampledErrorOptions o;
  o.points = 20000;
  const SampledError r = measure_sampled_error(set, set.tables[0], tr, o);
  const double h = 0.1, worst = h * h / 4.0;
  CHECK(r.error.points >= 20000);
  CHECK(r.error.worst <= worst * (1.0 + 1e-12));
  CHECK(r.error.worst >= worst * (1.0 - 1e-3));
  // Within a cell the error is h² u(1 − u), u uniform: P(e > t) = √(1 − 4t/h²), so p99 = (h²/4)(1 − 1e−4).
  CHECK(r.error.p99 >= worst * (1.0 - 1e-3));
  CHECK(r.error.mean == Approx(h * h / 6.0).epsilon(0.02));
  // The worst point lies close to a cell's midpoint.
  const double u = r.worst_at[0] / h - std::floor(r.worst_at[0] / h);
  CHECK(std::abs(u - 0.5) < 0.05);
}

TEST_CASE("The sampled error of a bilinear table of x^2 + y^2 is (hx^2 + hy^2)/4, and exp with geometric interpolation is exact",
          "[sampled_error]") {
  TableSet set;
  set.tables.push_back(tabulate({axis("x", 0.0, 1.0, 5), axis("y", -1.0, 1.0, 9)},
                                [](const std::vector<double>& x) { return x[0] * x[0] + x[1] * x[1]; }));
  SampledErrorOptions o;
  o.points = 40000;
  const SampledError r =
      measure_sampled_error(set, set.tables[0], closed_form([](const std::vector<double>& x) { return x[0] * x[0] + x[1] * x[1]; }, 1.0), o);
  const double worst = (0.25 * 0.25 + 0.25 * 0.25) / 4.0;
  CHECK(r.error.worst <= worst * (1.0 + 1e-12));
  CHECK(r.error.worst >= worst * 0.98);
  // Relative to the value itself (floor 1e-9): e^{-8x} interpolated geometrically along x is exact
  // (to rounding); linearly it is wrong by a known factor at the cell's middle.
  auto f = [](const std::vector<double>& x) { return std::exp(-8.0 * x[0]); };
  TableSet geo, lin;
  geo.tables.push_back(tabulate({axis("x", 0.0, 1.0, 5, Interpolation::geometric)}, f));
  lin.tables.push_back(tabulate({axis("x", 0.0, 1.0, 5)}, f));
  CHECK(measure_sampled_error(geo, geo.tables[0], closed_form(f, 1e-9), o).error.worst < 1e-12);
  // Linear between e^0 and e^{-2} (one cell of width 0.25): the relative error (lerp − e^{−8x})/e^{−8x}
  // is largest where its derivative vanishes; its maximum over u ∈ [0, 1] of ((1 − u) + u e^{−2}) e^{2u} − 1.
  double expect = 0.0;
  for (int i = 0; i <= 200000; ++i) {
    const double u = i / 200000.0;
    expect = std::max(expect, ((1.0 - u) + u * std::exp(-2.0)) * std::exp(2.0 * u) - 1.0);
  }
  const double got = measure_sampled_error(lin, lin.tables[0], closed_form(f, 1e-9), o).error.worst;
  CHECK(got <= expect * (1.0 + 1e-9));
  CHECK(got >= expect * (1.0 - 1e-3));
}

TEST_CASE("The sampled error divides by the slice's peak, floored at 1e-3 of the white slice's", "[sampled_error]") {
  // Table of zeros over (sigma_a, phi): the error is the exact value itself. Exact: e^{−20σ} cos²φ,
  // white (σ = 0) slice cos²φ; the peak over φ ∈ [0, π] of the slice is e^{−20σ}, of the white 1.
  TableSet set;
  set.tables.push_back(tabulate({axis("sigma_a", 0.0, 1.0, 3), axis("phi", 0.0, kPi, 5)}, [](const std::vector<double>&) { return 0.0; }));
  TableTruth tr;
  tr.slab_axes = {0};
  tr.make = [](const std::vector<double>& x) {
    const double s = std::exp(-20.0 * x[0]);
    return PointFunction([s](const std::vector<double>& y) { return s * std::cos(y[1]) * std::cos(y[1]); });
  };
  tr.make_white = [](const std::vector<double>&) {
    return PointFunction([](const std::vector<double>& y) { return std::cos(y[1]) * std::cos(y[1]); });
  };
  tr.peak_axis = 1, tr.peak_lo = 0.0, tr.peak_hi = kPi;
  tr.white_floor = 1e-3;
  tr.absolute_floor = 1e-300;
  SampledErrorOptions o;
  o.points = 4000;
  o.keep_points = true;
  const SampledError r = measure_sampled_error(set, set.tables[0], tr, o);
  REQUIRE(r.x.size() == r.rel.size());
  std::size_t floored = 0;
  for (std::size_t i = 0; i < r.x.size(); ++i) {
    const double s = std::exp(-20.0 * r.x[i][0]), c2 = std::cos(r.x[i][1]) * std::cos(r.x[i][1]);
    if (s < 1e-3) ++floored;
    CHECK(r.rel[i] == Approx(s * c2 / std::max(s, 1e-3)).epsilon(1e-9).margin(1e-15));
  }
  CHECK(floored > r.x.size() / 2);  // σ > ln(1000)/20 ≈ 0.35: the lobe is absorbed below the floor
  CHECK(r.error.worst == Approx(1.0).epsilon(1e-3));
}

TEST_CASE("The N_p reference's denominator: an absorbed TT lobe is divided by 1e-3 of the white peak", "[sampled_error]") {
  // A zero N_p table at one (beta, sigma_a, theta_d): the relative error at phi is N_TT(phi) over
  // max(peak_phi N_TT, 1e-3 peak_phi N_TT(sigma_a = 0)), computed here on a dense phi grid.
  auto one = [](const std::string& name, double v) {
    GridAxis a = axis(name, v, v + 1.0, 1);
    return a;
  };
  const double beta = radians(10.0), theta_d = radians(20.0);
  for (double sigma : {0.5, 12.0}) {
    TableSet set;
    Table t = tabulate({one("beta", beta), one("sigma_a", sigma), one("theta_d", theta_d), axis("phi", 0.0, kPi, 2)},
                       [](const std::vector<double>&) { return 0.0; });
    t.group = "np", t.name = "TT", t.quantity = "N_p";
    t.attributes = {{"lobe", "TT"}, {"p", 1}};
    set.tables.push_back(t);
    const auto rule = std::make_shared<const GaussLegendreRule>(1024);
    const auto truth = table_truth(set.tables[0], TruthModel{}, rule);
    REQUIRE(truth);
    SampledErrorOptions o;
    o.points = 64;
    o.keep_points = true;
    const SampledError r = measure_sampled_error(set, set.tables[0], *truth, o);
    double peak = 0.0, white = 0.0;
    const AttenuationSlice s(1.55, theta_d, sigma), w(1.55, theta_d, 0.0);
    for (int i = 0; i <= 4000; ++i) {
      const double phi = kPi * i / 4000.0;
      peak = std::max(peak, azimuthal_np(s, 1, beta, phi, *rule));
      white = std::max(white, azimuthal_np(w, 1, beta, phi, *rule));
    }
    const double den = std::max(peak, 1e-3 * white);
    INFO("sigma_a " << sigma << ": peak " << peak << ", white peak " << white);
    CHECK((sigma > 10.0) == (peak < 1e-3 * white));  // the absorbed case uses the floor
    for (std::size_t i = 0; i < r.x.size(); ++i)
      CHECK(r.rel[i] == Approx(azimuthal_np(s, 1, beta, r.x[i][3], *rule) / den).epsilon(1e-5));
  }
}

TEST_CASE("The sampled error is the same for any thread count", "[sampled_error]") {
  TableSet set;
  set.tables.push_back(tabulate({axis("x", 0.0, 1.0, 7), axis("y", 0.1, 3.0, 6)},
                                [](const std::vector<double>& x) { return std::sin(3.0 * x[0]) * std::log(x[1] + 1.0); }));
  set.tables[0].axes[1].spacing = Spacing::log;
  const TableTruth tr = closed_form([](const std::vector<double>& x) { return std::sin(3.0 * x[0]) * std::log(x[1] + 1.0); }, 1e-3);
  SampledErrorOptions o;
  o.points = 5000;
  o.seed = 42;
  o.half_float = true;
  std::vector<SampledError> r;
  for (int threads : {1, 2, 3}) {
    o.threads = threads;
    r.push_back(measure_sampled_error(set, set.tables[0], tr, o));
  }
  for (std::size_t i = 1; i < r.size(); ++i) {
    CHECK(r[i].error.worst == r[0].error.worst);
    CHECK(r[i].error.p99 == r[0].error.p99);
    CHECK(r[i].error.mean == r[0].error.mean);
    CHECK(r[i].half.worst == r[0].half.worst);
    CHECK(r[i].worst_at == r[0].worst_at);
  }
  CHECK(r[0].half.points == r[0].error.points);  // half floats measured at the same points
  o.seed = 43;
  CHECK(measure_sampled_error(set, set.tables[0], tr, o).worst_at != r[0].worst_at);  // another seed, other points
  // Log axis: points log-uniform over [0.1, 3] (half of them below √0.3 ≈ 0.548).
  o.keep_points = true;
  const SampledError k = measure_sampled_error(set, set.tables[0], tr, o);
  const auto below = std::count_if(k.x.begin(), k.x.end(), [](const std::vector<double>& x) { return x[1] < std::sqrt(0.3); });
  CHECK(static_cast<double>(below) / static_cast<double>(k.x.size()) == Approx(0.5).margin(0.03));
}

TEST_CASE("The validator fails a table exact at its nodes but wrong between them", "[sampled_error][validate]") {
  const json j = json::parse(R"({
    "name": "sampled-unit",
    "lobes": { "explicit": ["R", "TT", "TRT"], "residual": true },
    "quadrature": { "order": 128 },
    "tables": {
      "np": { "axes": {
        "theta_d": { "count": 6, "range_deg": [0, 60], "spacing": "cos" }, "phi": { "count": 49 },
        "sigma_a": { "count": 2, "range": [0, 0.05], "spacing": "sqrt" }, "beta": { "count": 2, "range_deg": [8, 12], "spacing": "log" } } },
      "mp": { "axes": { "theta_i": { "count": 13, "range_deg": [-90, 90] }, "theta_r": { "count": 25, "range_deg": [-90, 90] },
                        "beta": { "count": 2, "range_deg": [10, 30] } } }
    },
    "output": { "basename": "v", "formats": ["hdf5"] } })");
  TableSet set = bake(parse_config(j, "v.json", "/tmp"));
  const auto rule_ptr = std::make_shared<const GaussLegendreRule>(1024);
  SampledErrorOptions so;
  so.points = 1000;
  auto measure = [&](const TableSet& s, const std::string& path) {
    const Table& t = *s.find(path);
    return measure_sampled_error(s, t, *table_truth(t, TruthModel{}, rule_ptr), so).error.worst;
  };
  const double before = measure(set, "np/TT");
  // Replace np/TT by a table with 2 phi nodes (0 and pi), exact at both.
  Table* r = nullptr;
  for (Table& t : set.tables)
    if (t.path() == "np/TT") r = &t;
  REQUIRE(r);
  const GaussLegendreRule& rule = *rule_ptr;
  std::vector<GridAxis> axes = r->axes;
  axes[3].count = 2;
  const Table coarse = tabulate(axes, [&](const std::vector<double>& x) { return azimuthal_np(AttenuationSlice(1.55, x[2], x[1]), 1, x[0], x[3], rule); });
  r->axes = axes;
  r->f32.clear();
  r->allocate(Precision::float32);
  for (std::size_t i = 0; i < coarse.size(); ++i) r->set(i, coarse.get(i));
  // Exact at the nodes: sampled at a node, the table gives the direct value (to float rounding).
  for (const double phi : axes[3].nodes()) {
    const std::vector<double> x = {axes[0].nodes()[1], axes[1].nodes()[1], axes[2].nodes()[3], phi};
    const double exact = azimuthal_np(AttenuationSlice(1.55, x[2], x[1]), 1, x[0], x[3], rule);
    CHECK(set.sample_value(*r, x) == Approx(exact).epsilon(1e-6).margin(1e-9));
  }
  const double after = measure(set, "np/TT");
  INFO("np/TT sampled error: " << before << " with 49 phi nodes, " << after << " with 2");
  CHECK(after > 0.3);
  CHECK(after > 5.0 * before);
  ValidationOptions opt;
  opt.max_points = 1000;
  opt.thresholds.set("accuracy_max_rel", 0.15);
  const auto report = validate_tables(set, "unit", opt);
  const nlohmann::ordered_json* acc = nullptr;
  for (const auto& c : report["checks"])
    if (c["id"] == "accuracy_max_rel") acc = &c;
  REQUIRE(acc);
  INFO((*acc).dump());
  CHECK((*acc)["status"] == "fail");
  CHECK((*acc)["value"].get<double>() >= after * 0.5);
  CHECK((*acc)["detail"].get<std::string>().find("denominator: peak over all phi") != std::string::npos);
  // The report lists every table with a reference, with its denominator and its points.
  std::size_t expected = 0, listed = 0;
  for (const Table& t : set.tables)
    if (t.quantity == "N_p" || t.quantity == "energy" || t.quantity == "M_p" || t.quantity == "sigma_a") ++expected;
  for (const auto& t : report["accuracy"]) {
    ++listed;
    CHECK_FALSE(t["denominator"].get<std::string>().empty());
    CHECK(t["off_node"]["points"].get<std::size_t>() >= 1000);
    if (t["path"] == "np/TT") CHECK(t["off_node"]["max_rel"].get<double>() == Approx(after).epsilon(0.5));
  }
  CHECK(listed == expected);
}

TEST_CASE("The sampled error measures a table with a factor table as the renderer sees it (shape times factor)", "[sampled_error]") {
  // Stored: the shape x² on (x, y) with 11 x nodes (2 y nodes, constant in y), attribute factor
  // "test/e"; test/e holds e^y on its own 5 y nodes, geometric (exact for e^y). The quantity is
  // x² e^y: interpolated it is lerp(x²) e^y, wrong by at most (h²/4) e^y, worst e/400 at y = 1.
  TableSet set;
  Table shape = tabulate({axis("x", 0.0, 1.0, 11), axis("y", 0.0, 1.0, 2)}, [](const std::vector<double>& x) { return x[0] * x[0]; });
  shape.attributes["factor"] = "test/e";
  Table e = tabulate({axis("y", 0.0, 1.0, 5, Interpolation::geometric)}, [](const std::vector<double>& x) { return std::exp(x[0]); });
  e.name = "e";
  set.tables = {shape, e};
  SampledErrorOptions o;
  o.points = 40000;
  const SampledError r = measure_sampled_error(
      set, set.tables[0], closed_form([](const std::vector<double>& x) { return x[0] * x[0] * std::exp(x[1]); }, 1.0), o);
  const double worst = 0.01 / 4.0 * std::exp(1.0);
  CHECK(r.error.worst <= worst * (1.0 + 1e-9));
  CHECK(r.error.worst >= worst * 0.98);
}

TEST_CASE("The dual-scattering reference agrees with the baked tables at their nodes", "[sampled_error][dual_scattering]") {
  const json j = json::parse(R"({
    "name": "ds-unit",
    "lobes": { "explicit": ["R", "TT", "TRT"], "residual": true },
    "quadrature": { "method": "fourier", "tolerance": 1e-10 },
    "tables": { "dual_scattering": { "axes": {
      "theta_i": { "count": 4, "range_deg": [0, 80], "spacing": "sin" },
      "beta": { "count": 3, "range_deg": [5, 20], "spacing": "log" },
      "sigma_a": { "count": 3, "range": [0, 2], "spacing": "sqrt" } } } },
    "output": { "basename": "ds", "formats": ["hdf5"] } })");
  const TableSet set = bake(parse_config(j, "ds.json", "/tmp"));
  const auto memo = make_dual_scattering_memo();
  std::size_t checked = 0;
  for (const Table& t : set.tables) {
    const auto truth = dual_scattering_truth(set, t, memo);
    if (!truth) continue;
    // At two nodes (the tables hold dual_scattering_grid's values, a different algorithm at 1e-4).
    const PointFunction f = truth->make({});
    for (std::size_t i : {std::size_t{5}, t.size() - 3}) {
      std::vector<double> x(t.axes.size());
      std::size_t r = i;
      for (std::size_t k = t.axes.size(); k-- > 0;) {
        x[k] = t.axes[k].nodes()[r % static_cast<std::size_t>(t.axes[k].count)];
        r /= static_cast<std::size_t>(t.axes[k].count);
      }
      INFO(t.path() << " at node " << i);
      CHECK(f(x) == Approx(t.get(i)).margin(2e-4).epsilon(1e-3));
    }
    ++checked;
  }
  CHECK(checked >= 5);  // a_f, a_b, ... and the mean energies
  // Sampled: every table of the groups at the same points, one dual_scattering() per point.
  SampledErrorOptions o;
  o.points = 32;
  const Table& a_f = *set.find(set.tables.front().path());
  const auto truth = dual_scattering_truth(set, a_f, memo);
  REQUIRE(truth);
  const SampledError r = measure_sampled_error(set, a_f, *truth, o);
  CHECK(r.error.points == 32);
  CHECK(std::isfinite(r.error.worst));
  CHECK_FALSE(r.denominator.empty());
}
