// The worst-point search of the sampled-error measure: it finds errors that uniform random points
// miss (a narrow feature inside an end cell, a corner, a grazing end), its local maximisation
// reaches maxima known in closed form, it counts the points of every stage, it is the same for any
// thread count, and the validator judges and reports the worst it found.
#include <algorithm>
#include <cmath>
#include <hairlut/bake/sampled_error.hpp>
#include <hairlut/bake/table_truth.hpp>
#include <hairlut/report/validate.hpp>

#include "catch.hpp"

using namespace hairlut;

namespace {

GridAxis axis(const std::string& name, double lo, double hi, int count) {
  GridAxis a;
  a.name = name;
  a.units = "1";
  a.lo = lo, a.hi = hi, a.count = count;
  a.interpolation = Interpolation::linear;
  return a;
}

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

TableTruth absolute(std::function<double(const std::vector<double>&)> f) {
  TableTruth tr;
  tr.make = [f](const std::vector<double>&) { return PointFunction(f); };
  tr.absolute_floor = 1.0;  // denominator 1: the absolute error
  tr.denominator = "test";
  return tr;
}

std::size_t points_of(const SampledError& r, const std::string& stage) {
  for (const SearchStage& s : r.stages)
    if (s.name == stage) return s.points;
  return 0;
}

}  // namespace

TEST_CASE("The search finds a narrow bump in the last cell that random points miss", "[sampled_error][search]") {
  // x on [0, 1] with 101 nodes; the truth has a bump of height 1 and half-width 2e-4 at x = 0.9955,
  // inside the last cell and between nodes, so the table (exact at its nodes) reads ~0 there.
  auto f = [](const std::vector<double>& x) { return std::exp(-std::pow((x[0] - 0.9955) / 2e-4, 2)); };
  TableSet set;
  set.tables.push_back(tabulate({axis("x", 0.0, 1.0, 101)}, f));
  SampledErrorOptions o;
  o.points = 256;
  o.seed = 7;
  const SampledError plain = measure_sampled_error(set, set.tables[0], absolute(f), o);
  o.search = true;
  const SampledError r = measure_sampled_error(set, set.tables[0], absolute(f), o);
  INFO("random only " << plain.found << ", with the search " << r.found << " at " << r.worst_at[0]);
  // The table is ~e^{-(0.0045/2e-4)^2} ≈ 0 at the nodes 0.99 and 1, so the largest error is the
  // bump's height minus a linear blend of two negligible values: 1 to 1e-12.
  CHECK(r.found > 0.999);
  CHECK(r.found <= 1.0 + 1e-12);
  CHECK(std::abs(r.worst_at[0] - 0.9955) < 1e-5);
  CHECK(plain.found < 0.5);  // 256 uniform points: the chance of one within 1e-4 of the bump is ~5%
  // The random stage is the plain measure's points, the other stages add their own.
  CHECK(points_of(r, "random") == plain.error.points);
  CHECK(points_of(r, "edges") > 0);
  CHECK(points_of(r, "climb") > 0);
  CHECK(r.error.worst == plain.error.worst);
}

TEST_CASE("The search's local maximisation reaches linear interpolation's h^2/4 of x^2 + y^2 at a cell centre", "[sampled_error][search]") {
  auto f = [](const std::vector<double>& x) { return x[0] * x[0] + x[1] * x[1]; };
  TableSet set;
  set.tables.push_back(tabulate({axis("x", 0.0, 1.0, 5), axis("y", -1.0, 1.0, 9)}, f));
  SampledErrorOptions o;
  o.points = 64;  // too few to land near a cell centre by chance
  o.seed = 3;
  o.search = true;
  const SampledError r = measure_sampled_error(set, set.tables[0], absolute(f), o);
  const double worst = (0.25 * 0.25 + 0.25 * 0.25) / 4.0;  // (hx² + hy²)/4 at the centre of any cell
  CHECK(r.found <= worst * (1.0 + 1e-12));
  CHECK(r.found >= worst * (1.0 - 1e-6));
}

TEST_CASE("The search finds a corner's error and names it", "[sampled_error][search]") {
  // Exact but in the corner cell x > 0.9, y > 0.9, where the truth has a bump the nodes miss.
  auto f = [](const std::vector<double>& x) {
    return std::exp(-(std::pow((x[0] - 0.97) / 0.01, 2) + std::pow((x[1] - 0.96) / 0.01, 2)));
  };
  TableSet set;
  set.tables.push_back(tabulate({axis("x", 0.0, 1.0, 11), axis("y", 0.0, 1.0, 11)}, f));
  SampledErrorOptions o;
  o.points = 256;
  o.seed = 11;
  o.search = true;
  const SampledError r = measure_sampled_error(set, set.tables[0], absolute(f), o);
  INFO("found " << r.found << " at " << r.worst_at[0] << ", " << r.worst_at[1]);
  CHECK(r.found > 0.999);  // the bump's height 1 minus the table there (below 1e-10)
  CHECK(std::abs(r.worst_at[0] - 0.97) < 1e-3);
  CHECK(std::abs(r.worst_at[1] - 0.96) < 1e-3);
  CHECK(points_of(r, "corners") > 0);
}

TEST_CASE("The search is the same for any thread count and another seed looks elsewhere", "[sampled_error][search]") {
  auto f = [](const std::vector<double>& x) { return std::sin(7.0 * x[0]) * std::cos(5.0 * x[1]); };
  TableSet set;
  set.tables.push_back(tabulate({axis("x", 0.0, 1.0, 9), axis("y", 0.0, 1.0, 7)}, f));
  SampledErrorOptions o;
  o.points = 512;
  o.seed = 5;
  o.search = true;
  o.threads = 1;
  const SampledError a = measure_sampled_error(set, set.tables[0], absolute(f), o);
  o.threads = 4;
  const SampledError b = measure_sampled_error(set, set.tables[0], absolute(f), o);
  CHECK(a.found == b.found);
  CHECK(a.worst_at == b.worst_at);
  REQUIRE(a.stages.size() == b.stages.size());
  for (std::size_t i = 0; i < a.stages.size(); ++i) CHECK(a.stages[i].points == b.stages[i].points);
  o.seed = 6;
  CHECK(measure_sampled_error(set, set.tables[0], absolute(f), o).stages.front().at != a.stages.front().at);
}

TEST_CASE("The search looks at a grazing end of an angle axis, closer than any cell", "[sampled_error][search]") {
  // θ on [0, π/2] with 10 cells; the truth departs from the table only within 1e-3 rad of π/2.
  auto f = [](const std::vector<double>& x) { return std::exp(-(1.5707963267948966 - x[0]) / 2e-4); };
  GridAxis theta = axis("theta", 0.0, 1.5707963267948966, 11);
  theta.units = "rad";
  TableSet set;
  set.tables.push_back(tabulate({theta}, [&](const std::vector<double>& x) { return x[0] < 1.5 ? f(x) : 0.0; }));
  SampledErrorOptions o;
  o.points = 64;
  o.seed = 2;
  o.search = true;
  const SampledError r = measure_sampled_error(set, set.tables[0], absolute(f), o);
  // At θ = π/2 the truth is 1 and the table 0.
  CHECK(r.found == Approx(1.0).margin(1e-9));
  CHECK(points_of(r, "grazing") > 0);
}

TEST_CASE("The search follows a feature into a grazing corner, where random points across it miss", "[sampled_error][search]") {
  // M_p-like: a ridge narrow across the diagonal θr = α − θi (the truth names it as its feature
  // along the peak axis θr), present only within 2e-3 rad of θi = π/2 and between the θr nodes
  // there, so the table (exact at its nodes) reads 0 on it. Compact support: no slope anywhere
  // else for the local maximisation to follow, so only points placed on the ridge find it.
  const double half_pi = 1.5707963267948966, alpha = 0.3;
  auto f = [=](const std::vector<double>& x) {
    const double a = 1.0 - std::pow((x[1] - (alpha - x[0])) / 5e-4, 2), b = 1.0 - (half_pi - x[0]) / 2e-3;
    return a > 0.0 && b > 0.0 ? a * a * b * b : 0.0;
  };
  GridAxis ti = axis("theta_i", -half_pi, half_pi, 37), tr = axis("theta_r", -half_pi, half_pi, 37);
  ti.units = tr.units = "rad";
  TableSet set;
  set.tables.push_back(tabulate({ti, tr}, f));
  TableTruth truth = absolute(f);
  truth.peak_axis = 1;
  truth.features = [=](const std::vector<double>& x) { return std::vector<double>{alpha - x[0]}; };
  SampledErrorOptions o;
  o.points = 256;
  o.seed = 5;  // one whose random grazing points miss the ridge (without the ridge points: 0 found)
  o.search = true;
  const SampledError r = measure_sampled_error(set, set.tables[0], truth, o);
  INFO("found " << r.found << " at " << r.worst_at[0] << ", " << r.worst_at[1]);
  // At θi = π/2 the ridge has height 1 at θr = α − π/2, 0.43 of a cell from the nearest node.
  CHECK(r.found == Approx(1.0).margin(1e-9));
  CHECK(std::abs(r.worst_at[0] - half_pi) < 1e-6);
  CHECK(std::abs(r.worst_at[1] - (alpha - half_pi)) < 1e-6);
}
