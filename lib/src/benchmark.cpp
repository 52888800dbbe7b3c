#include "hairlut/benchmark.hpp"

#include <algorithm>
#include <cmath>

#include "hairlut/angles.hpp"
#include "hairlut/error.hpp"
#include "hairlut/fresnel.hpp"
#include "hairlut/gaussian_detector.hpp"
#include "hairlut/quadrature.hpp"

namespace hairlut {

std::vector<StressSlice> stress_slices(std::size_t count, std::uint64_t seed) {
  const double betas[] = {0.25, 0.5, 1.0, 2.0, 5.0, 20.0, 90.0};
  const double thetas[] = {0.0, 30.0, 60.0, 85.0, 89.5, 89.9};
  const double sigmas[] = {0.0, 0.3, 3.0, 30.0, 1000.0};
  const double etas[] = {1.01, 1.2, 1.55, 2.5, 3.0};
  const int lobes[] = {0, 1, 2, 3, 5, 8};
  std::vector<StressSlice> out;
  // The corners of the target domain (β 0.5°, θd near 90°, σa 0 and 1e3, η 1.01 and 3, p 8).
  for (double b : {0.5, 90.0})
    for (double t : {0.0, 89.9})
      for (int p : {1, 8}) out.push_back({radians(b), radians(t), p == 1 ? 0.0 : 1000.0, p == 1 ? 1.01 : 3.0, p});
  // Then a splitmix64 sample of the product.
  std::uint64_t state = seed;
  auto next = [&state]() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  };
  while (out.size() < count)
    out.push_back({radians(betas[next() % 7]), radians(thetas[next() % 6]), sigmas[next() % 5], etas[next() % 5],
                   lobes[next() % 6]});
  out.resize(count);
  return out;
}

void renderer_baseline_material(double eta, const double (&sigma_a)[3], const double (&betas)[3], const std::vector<double>& phis,
                                const std::vector<double>& cos_thetas, const GaussLegendreRule& rule, std::vector<float>& out) {
  const std::size_t nphi = phis.size(), ncos = cos_thetas.size();
  out.assign(3 * ncos * nphi * 3, 0.0f);
  if (rule.order() != 140) throw DomainError("the renderer baseline uses a 140-point rule");
  const float pi = static_cast<float>(kPi), two_pi = static_cast<float>(kTwoPi);
  for (int p = 0; p < 3; ++p) {
    // The detector tabulated at 2048 samples over [−π, π], linear interpolation, in float.
    std::vector<float> detector(2049);
    for (std::size_t i = 0; i < detector.size(); ++i)
      detector[i] = static_cast<float>(gaussian_detector(betas[p], -kPi + kTwoPi * static_cast<double>(i) / 2048.0));
    auto D = [&](float x) {
      x = x - two_pi * std::floor((x + pi) / two_pi);  // wrap to [−π, π)
      const float s = (x + pi) / two_pi * 2048.0f;
      const int i = std::clamp(static_cast<int>(s), 0, 2047);
      const float w = s - static_cast<float>(i);
      return detector[static_cast<std::size_t>(i)] * (1.0f - w) + detector[static_cast<std::size_t>(i) + 1] * w;
    };
    for (std::size_t t = 0; t < ncos; ++t) {
      const float cd = static_cast<float>(cos_thetas[t]);
      const float sd2 = 1.0f - cd * cd;
      const float e = static_cast<float>(eta);
      const float inv_ep = cd / std::sqrt(e * e - sd2);  // 1/η'
      const float cos_t = std::sqrt(e * e - sd2) / e;     // cos θt
      for (int i = 0; i < 140; ++i) {
        const float h = static_cast<float>(rule.nodes()[static_cast<std::size_t>(i)]);
        const float w = static_cast<float>(rule.weights()[static_cast<std::size_t>(i)]);
        const float gi = std::asin(h), gt = std::asin(h * inv_ep);
        const float c = cd * std::sqrt(1.0f - h * h);
        // Unpolarized Fresnel in float.
        const float st2 = (1.0f - c * c) / (e * e);
        const float ct = std::sqrt(std::max(0.0f, 1.0f - st2));
        const float rs = (c - e * ct) / (c + e * ct), rp = (e * c - ct) / (e * c + ct);
        const float f = 0.5f * (rs * rs + rp * rp);
        const float Phi = 2.0f * static_cast<float>(p) * gt - 2.0f * gi + static_cast<float>(p) * pi;
        for (int ch = 0; ch < 3; ++ch) {
          const float T = std::exp(-2.0f * static_cast<float>(sigma_a[ch]) / cos_t * std::cos(gt));
          const float A = p == 0 ? f : (1.0f - f) * (1.0f - f) * std::pow(f, static_cast<float>(p - 1)) * std::pow(T, static_cast<float>(p));
          for (std::size_t j = 0; j < nphi; ++j)
            out[((static_cast<std::size_t>(p) * ncos + t) * nphi + j) * 3 + static_cast<std::size_t>(ch)] +=
                0.5f * w * A * D(static_cast<float>(phis[j]) - Phi);
        }
      }
    }
  }
}

}  // namespace hairlut
