// The mirror lower end of a sqrt axis from 0 (Axis::lo_end = End::mirror): the cubic tap beyond
// σa = 0 is the mirror node. References: closed forms of the sampled functions, and Catmull–Rom
// written out by hand for the first cell (not through sampler.hpp's tap code).
#include <cmath>
#include <hairlut/tables/grid.hpp>
#include <hairlut/sampler/sampler_fixed.hpp>
#include <random>
#include <vector>

#include "catch.hpp"

using namespace hairlut::sampler;

namespace {

Axis sqrt_axis(int count, double hi, Placement placement, End end) {
  Axis a;
  a.spacing = Spacing::sqrt;
  a.placement = placement;
  a.lo = 0.0, a.hi = hi, a.count = count;
  a.interpolation = Interpolation::cubic;
  a.lo_end = end;
  return a;
}

std::vector<double> sampled(const Axis& a, double (*f)(double)) {
  std::vector<double> v(static_cast<std::size_t>(a.count));
  for (int i = 0; i < a.count; ++i) v[static_cast<std::size_t>(i)] = f(node(a, i));
  return v;
}

double linear_in_sigma(double s) { return 0.75 - 0.125 * s; }
double absorbed(double s) { return std::exp(-3.0 * s); }

}  // namespace

TEST_CASE("mirror lo_end: the first cell is Catmull-Rom with the mirror node", "[sampler][mirror]") {
  for (Placement pl : {Placement::edges, Placement::centers}) {
    const Axis a = sqrt_axis(9, 4.0, pl, End::mirror);
    const std::vector<double> v = sampled(a, absorbed);
    const TableView<double> view(v.data(), &a, 1);
    const FixedView<double, 1> fixed(v.data(), &a);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < 200; ++k) {
      const double t = u(rng);  // position in the first cell [node 0, node 1]
      const double t0 = std::sqrt(node(a, 0)), t1 = std::sqrt(node(a, 1));
      const double x = std::pow(t0 + t * (t1 - t0), 2.0);
      // Catmull–Rom of (v₋₁, v₀, v₁, v₂) with v₋₁ the mirror: v₁ about node 0 (edges, node 0 at
      // t = 0), v₀ about t = 0 (centres, node 0 at half a cell).
      const double vm = pl == Placement::edges ? v[1] : v[0];
      const double t2 = t * t, t3 = t2 * t;
      const double ref = 0.5 * ((-t3 + 2 * t2 - t) * vm + (3 * t3 - 5 * t2 + 2) * v[0] + (-3 * t3 + 4 * t2 + t) * v[1] + (t3 - t2) * v[2]);
      if (x < node(a, 0)) continue;  // centres: below node 0 the value is held
      CHECK(view(&x) == Approx(ref).epsilon(1e-13).margin(1e-15));
      CHECK(fixed(&x) == Approx(ref).epsilon(1e-13).margin(1e-15));
    }
  }
}

TEST_CASE("mirror lo_end: exact for f linear in sigma_a, closer than extrapolation for exp(-c sigma_a)", "[sampler][mirror]") {
  for (Placement pl : {Placement::edges, Placement::centers}) {
    const Axis m = sqrt_axis(8, 4.0, pl, End::mirror), e = sqrt_axis(8, 4.0, pl, End::extrapolate);
    const std::vector<double> lin = sampled(m, linear_in_sigma), ex = sampled(m, absorbed);
    const FixedView<double, 1> lin_m(lin.data(), &m), ex_m(ex.data(), &m), ex_e(ex.data(), &e);
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    double worst_m = 0.0, worst_e = 0.0;
    const double top = node(m, 1);  // the first cell (edges), the first cell and the held end (centres)
    for (int k = 0; k < 2000; ++k) {
      const double x = u(rng) * top;
      const double xs = std::max(x, node(m, 0));  // centres: below node 0 the value is held
      // f linear in σa is a quadratic in t, even about t = 0: the mirror node is exact.
      CHECK(lin_m(&x) == Approx(linear_in_sigma(xs)).epsilon(1e-13));
      worst_m = std::max(worst_m, std::abs(ex_m(&x) - absorbed(xs)));
      worst_e = std::max(worst_e, std::abs(ex_e(&x) - absorbed(xs)));
    }
    // e^{−3 t²} is even in t; its quadratic extrapolation beyond t = 0 is not.
    CHECK(worst_m < 0.5 * worst_e);
  }
}

TEST_CASE("mirror lo_end: away from the lower end nothing changes, refused off sqrt axes from 0", "[sampler][mirror]") {
  const Axis m = sqrt_axis(8, 4.0, Placement::edges, End::mirror), e = sqrt_axis(8, 4.0, Placement::edges, End::extrapolate);
  const std::vector<double> v = sampled(m, absorbed);
  const TableView<double> vm(v.data(), &m, 1), ve(v.data(), &e, 1);
  for (double x = node(m, 1); x <= 4.0; x += 0.01) CHECK(vm(&x) == ve(&x));

  hairlut::GridAxis g;
  g.name = "sigma_a", g.units = "1/radius", g.spacing = Spacing::sqrt, g.lo = 0.0, g.hi = 4.0, g.count = 8;
  g.interpolation = Interpolation::cubic, g.lo_end = End::mirror;
  CHECK_NOTHROW(g.validate("sigma_a"));
  const hairlut::GridAxis back = hairlut::GridAxis::from_json(g.to_json(), "sigma_a");
  CHECK(back.lo_end == End::mirror);
  g.lo = 0.01;
  CHECK_THROWS(g.validate("sigma_a"));
  g.lo = 0.0, g.spacing = Spacing::uniform;
  CHECK_THROWS(g.validate("sigma_a"));
  // A description without lo_end (a format 1.0 file) reads as extrapolate.
  g.spacing = Spacing::sqrt, g.lo_end = End::extrapolate;
  nlohmann::json j = g.to_json();
  CHECK_FALSE(j.contains("lo_end"));
  CHECK(hairlut::GridAxis::from_json(j, "sigma_a").lo_end == End::extrapolate);
}

TEST_CASE("even end of a cos-spaced axis: extrapolated, exact for quadratics of cos x", "[sampler][mirror]") {
  // θd over [0, 89°] with nodes evenly spaced in t = cos θd and wrap even (as N_p's energy axes):
  // f = a + b cos x + c cos² x is a quadratic of t, which Catmull–Rom with the quadratic
  // extrapolation beyond t(0) = 1 reproduces exactly; mirroring the index (v₋₁ = v₁) would not.
  const double pi = 3.14159265358979323846;
  auto f = [](double x) { return 0.3 + 0.5 * std::cos(x) - 0.25 * std::cos(x) * std::cos(x); };
  for (Placement pl : {Placement::edges, Placement::centers}) {
    Axis a;
    a.spacing = Spacing::cos;
    a.placement = pl;
    a.wrap = Wrap::even;
    a.lo = 0.0, a.hi = 89.0 * pi / 180.0, a.count = 12;
    a.interpolation = Interpolation::cubic;
    std::vector<double> v(static_cast<std::size_t>(a.count));
    for (int i = 0; i < a.count; ++i) v[static_cast<std::size_t>(i)] = f(node(a, i));
    const TableView<double> view(v.data(), &a, 1);
    const FixedView<double, 1> fixed(v.data(), &a);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < 500; ++k) {
      const double x = u(rng) * node(a, 2);  // the first cells, next to the even end at 0
      if (x < node(a, 0)) continue;          // centres: below node 0 the value is held
      CHECK(view(&x) == Approx(f(x)).epsilon(1e-12));
      CHECK(fixed(&x) == Approx(f(x)).epsilon(1e-12));
      const double neg = -x;  // the even wrap folds a signed angle
      CHECK(view(&neg) == Approx(f(x)).epsilon(1e-12));
    }
  }
}
