#include "hairlut/util/quadrature.hpp"

#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/special_functions/legendre.hpp>

#include "hairlut/util/error.hpp"

namespace hairlut {

GaussLegendreRule::GaussLegendreRule(int order) {
  if (order < 1 || order > 32768) throw_domain_error("quadrature order", "must lie in [1, 32768]", static_cast<long long>(order));
  const std::vector<double> zeros = boost::math::legendre_p_zeros<double>(order);  // the zeros ≥ 0
  const auto n = static_cast<std::size_t>(order);
  nodes_.resize(n);
  weights_.resize(n);
  for (std::size_t j = 0; j < zeros.size(); ++j) {
    const double x = zeros[j];
    const double dp = boost::math::legendre_p_prime(order, x);
    const double w = 2.0 / ((1.0 - x) * (1.0 + x) * dp * dp);
    // zeros ascend from 0 (odd n) or from the smallest positive zero (even n).
    const std::size_t pos = n / 2 + j;
    nodes_[pos] = x;
    weights_[pos] = w;
    nodes_[n - 1 - pos] = -x;
    weights_[n - 1 - pos] = w;
  }
}

const GaussLegendreRule& GaussLegendreCache::get(int order) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto& rule = rules_[order];
  if (!rule) rule = std::make_unique<GaussLegendreRule>(order);
  return *rule;
}

KronrodTables kronrod21_tables() {
  using K = boost::math::quadrature::gauss_kronrod<double, 21>;
  using G = boost::math::quadrature::gauss<double, 10>;
  return {std::span<const double>(K::abscissa().data(), K::abscissa().size()),
          std::span<const double>(K::weights().data(), K::weights().size()),
          std::span<const double>(G::weights().data(), G::weights().size())};
}

}  // namespace hairlut
