#include "hairlut/report/benchmark.hpp"

#include <cmath>

#include "hairlut/util/angles.hpp"

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

}  // namespace hairlut
