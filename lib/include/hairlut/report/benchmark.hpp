// Pieces of bench-hair-luts that tests also use: the stress set of N_p inputs.
#pragma once

#include <cstdint>
#include <vector>

#include "hairlut/physics/attenuation.hpp"

namespace hairlut {

/// One N_p slice of the stress set: everything but φ.
struct StressSlice {
  double beta, theta_d, sigma_a, eta;
  int p;
};

/// A deterministic sample of `count` slices from the product of the stress values (β 0.25°–90°,
/// θd 0°–89.9°, σa 0–1e3, η 1.01–3, p 0–8), always including the corners of the target domain.
std::vector<StressSlice> stress_slices(std::size_t count, std::uint64_t seed = 1);

}  // namespace hairlut
