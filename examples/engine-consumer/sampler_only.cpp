// The header-only sampler alone, compiled as C++17 with no other dependency: an engine that
// uploads the tables itself and samples them on the CPU. Builds a small table of a function that
// is linear in each axis's mapped coordinate (cos θ, log σ), which multilinear interpolation in
// those coordinates reproduces exactly, and checks a few samples between the nodes.
#include <cmath>
#include <cstdio>
#include <hairlut/sampler/sampler.hpp>
#include <hairlut/sampler/sampler_fixed.hpp>
#include <vector>

static_assert(__cplusplus >= 201703L && __cplusplus < 202002L, "this consumer checks that C++17 suffices");

int main() {
  using namespace hairlut::sampler;
  Axis axes[2];
  axes[0].spacing = Spacing::cos;  // theta in [0, 1.2], nodes even in cos theta
  axes[0].lo = 0.0;
  axes[0].hi = 1.2;
  axes[0].count = 7;
  axes[1].spacing = Spacing::log;  // sigma in [0.1, 10], nodes even in ln sigma
  axes[1].lo = 0.1;
  axes[1].hi = 10.0;
  axes[1].count = 5;
  auto f = [](double theta, double sigma) { return 2.0 * std::cos(theta) - 0.5 * std::log(sigma) + 1.0; };
  std::vector<float> data;
  for (int i = 0; i < axes[0].count; ++i)
    for (int j = 0; j < axes[1].count; ++j) data.push_back(static_cast<float>(f(node(axes[0], i), node(axes[1], j))));
  // A view built once (axis mappings prepared, the loop nest fixed for two axes), then lookups.
  const FixedView<float, 2> view(data.data(), axes);
  double worst = 0.0;
  for (double theta : {0.05, 0.4, 0.77, 1.19})
    for (double sigma : {0.13, 0.9, 3.3, 9.7}) {
      const double x[2] = {theta, sigma};
      worst = std::fmax(worst, std::fabs(sample(data.data(), axes, 2, x) - f(theta, sigma)));
      worst = std::fmax(worst, std::fabs(view(x) - f(theta, sigma)));
    }
  std::printf("sampler-only (C++%ld): worst error %.3g on a function linear in the mapped coordinates\n",
              static_cast<long>(__cplusplus / 100 % 100), worst);
  return worst < 1e-6 ? 0 : 1;  // float storage: ~1e-7 of values of order 1
}
