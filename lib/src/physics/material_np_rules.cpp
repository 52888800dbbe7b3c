// The quadrature rules of per-material N_p (material_np.hpp): how many nodes, the transplanted
// Gauss–Legendre rule itself, the rules shared by a bake's materials, and Gauss–Legendre by Newton.
#include <algorithm>
#include <cmath>

#include "hairlut/physics/material_np.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

// The Kosloff–Tal-Ezer parameter of a 2m-point transplanted rule: the map's singularities at
// s = ±1/α lie on the Bernstein ellipse ρ with ρ^{−4m} = tolerance / 1000, so that the map costs
// the rule a thousandth of the tolerance (Hale & Trefethen 2008, §3).
double map_alpha(int m, double tolerance) { return 1.0 / std::cosh(std::log(1e3 / tolerance) / (4.0 * m)); }

}  // namespace

int material_np_nodes(double beta, int p, const FiberGeometry& g, double tol) {
  require_positive("beta", beta);
  if (!(tol > 0.0 && tol < 1.0)) throw_domain_error("tolerance", "must lie in (0, 1)", tol);
  const double rate = std::max(std::abs(2.0 * p * g.inv_eta_prime - 2.0), 2.0);
  const double h = kPi * (beta / rate) * std::sqrt(2.0 / std::log(10.0 / tol));  // widest spacing allowed
  // m = π² α / (4 h asin α) with α = map_alpha(m): two fixed-point passes from α → 1.
  double m = kPi / (2.0 * h);
  for (int pass = 0; pass < 2; ++pass) {
    const double a = map_alpha(std::max(1, static_cast<int>(std::ceil(m))), tol);
    m = kPi * kPi * a / (4.0 * h * std::asin(a));
  }
  const double scale = std::max(1.0, std::log(1.0 / tol) / std::log(1e10));
  const double floor = std::max(32.0, 12.0 + 12.0 / std::sqrt(std::max(g.eta - 1.0, 1e-4))) * scale;
  const double n = std::min(std::max(m + 4.0, floor), 16384.0);
  return static_cast<int>(std::ceil(n / 8.0)) * 8;
}

TransplantedRule transplanted_rule(int m, double tol) {
  std::vector<double> s, w;
  newton_gauss_legendre(2 * m, s, w);
  const double a = map_alpha(m, tol), as = std::asin(a);
  TransplantedRule n;
  for (std::size_t i = static_cast<std::size_t>(m); i < s.size(); ++i) {
    const double gamma = 0.5 * kPi * std::asin(a * s[i]) / as;
    // dγ/ds = (π/2) α / (asin α √(1 − α²s²)); the node also stands for its mirror −γ.
    const double weight = w[i] * 0.5 * kPi * a / (as * std::sqrt((1.0 - a * s[i]) * (1.0 + a * s[i])));
    n.gamma.push_back(gamma);
    n.cos_gamma.push_back(std::cos(gamma));
    n.sin_gamma.push_back(std::sin(gamma));
    n.weight.push_back(weight * n.cos_gamma.back());
    n.cos_2gamma.push_back(std::cos(2.0 * gamma));
    n.sin_2gamma.push_back(std::sin(2.0 * gamma));
  }
  return n;
}

const TransplantedRule& MaterialNpRules::get(int m, double tol) {
  auto it = rules_.find({m, tol});
  if (it == rules_.end()) it = rules_.emplace(std::pair{m, tol}, transplanted_rule(m, tol)).first;
  return it->second;
}

void newton_gauss_legendre(int m, std::vector<double>& nodes, std::vector<double>& weights) {
  if (m < 1 || m > 32768) throw_domain_error("quadrature order", "must lie in [1, 32768]", static_cast<long long>(m));
  const auto M = static_cast<std::size_t>(m), half = (M + 1) / 2;
  const double n = m;
  // P_k = a_k x P_{k−1} − b_k P_{k−2}, a_k = (2k − 1)/k, b_k = (k − 1)/k.
  std::vector<double> a(M + 1), b(M + 1);
  for (std::size_t k = 2; k <= M; ++k) a[k] = (2.0 * static_cast<double>(k) - 1.0) / static_cast<double>(k), b[k] = (static_cast<double>(k) - 1.0) / static_cast<double>(k);
  std::vector<double> x(half), value(half), deriv(half), p0(half), p1(half);
  // Tricomi's first guess (1 − 1/8m² + 1/8m³) cos(π(4i + 3)/(4m + 2)), within O(m⁻⁴) of the root.
  for (std::size_t i = 0; i < half; ++i)
    x[i] = (1.0 - 1.0 / (8.0 * n * n) + 1.0 / (8.0 * n * n * n)) * std::cos(kPi * (4.0 * static_cast<double>(i) + 3.0) / (4.0 * n + 2.0));
  // P_m and P_m' = m (x P_m − P_{m−1}) / (x² − 1) at every root estimate at once (a loop over the
  // roots inside the recurrence, which vectorizes).
  auto evaluate = [&] {
    for (std::size_t i = 0; i < half; ++i) p0[i] = 1.0, p1[i] = x[i];
    for (std::size_t k = 2; k <= M; ++k) {
      const double ak = a[k], bk = b[k];
#pragma omp simd
      for (std::size_t i = 0; i < half; ++i) {
        const double p2 = ak * x[i] * p1[i] - bk * p0[i];
        p0[i] = p1[i];
        p1[i] = p2;
      }
    }
    for (std::size_t i = 0; i < half; ++i) value[i] = p1[i], deriv[i] = n * (x[i] * p1[i] - p0[i]) / (x[i] * x[i] - 1.0);
  };
  // Newton until every step is below 1e−15, then one more (quadratic convergence).
  bool last = false;
  for (int it = 0; it < 100; ++it) {
    evaluate();
    double worst = 0.0;
    for (std::size_t i = 0; i < half; ++i) {
      const double dx = value[i] / deriv[i];
      x[i] -= dx;
      worst = std::max(worst, std::abs(dx));
    }
    if (last) break;
    last = worst <= 1e-15;
  }
  evaluate();  // P_m' at the converged roots
  nodes.assign(M, 0.0);
  weights.assign(M, 0.0);
  for (std::size_t i = 0; i < half; ++i) {
    nodes[M - 1 - i] = x[i];
    nodes[i] = -x[i];
    weights[M - 1 - i] = weights[i] = 2.0 / ((1.0 - x[i] * x[i]) * deriv[i] * deriv[i]);
  }
  if (M % 2 == 1) nodes[M / 2] = 0.0;
}

}  // namespace hairlut
