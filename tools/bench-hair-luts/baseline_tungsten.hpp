// The per-material baseline of bench-hair-luts: Tungsten's HairBcsdf precomputation of d'Eon's
// azimuthal functions, re-implemented (not copied) operation for operation from
// src/core/bsdfs/HairBcsdf.cpp (precomputeAzimuthalDistributions), src/core/math/GaussLegendre.hpp,
// src/core/bsdfs/Fresnel.hpp (dielectricReflectance), src/core/bsdfs/PrecomputedAzimuthalLobe.cpp
// and src/core/sampling/InterpolatedDistribution1D.hpp of github.com/tunabrain/tungsten at commit
// 88ea02044dbaf20472a8173b6752460b50c096d8. Everything in float, as there.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace bench {

/// The inputs Tungsten's precompute reads: its constant η = 1.55, σa per colour channel and the
/// one width β (Tungsten's _betaR) used by the detector of all three lobes.
struct TungstenMaterial {
  float eta = 1.55f;
  std::array<float, 3> sigma_a{};
  float beta = 0.0f;
};

/// What one precompute produces: for each lobe R, TT, TRT the 64 × 64 RGB table over
/// (cos θd = y/63, φ = 2π x/63), value[(y · 64 + x) · 3 + c], and its sampling distribution
/// (dilated max-channel weights, per-row pdf/cdf and sums) as PrecomputedAzimuthalLobe builds it.
struct TungstenLobe {
  std::vector<float> value;          // 64 · 64 · 3
  std::vector<float> pdf, cdf, sum;  // 64 · 64, 64 · 65, 64
};
struct TungstenTables {
  static constexpr int kResolution = 64, kNodes = 140, kDetectorSamples = 2048;
  std::array<TungstenLobe, 3> lobe;
};

/// Runs the whole precompute: the 140-point Gauss–Legendre rule (roots by Newton in double,
/// rounded to float), the three 2048-sample detector tables (all of width β), the 64 × 64 tables
/// of the three lobes and their sampling distributions. Nothing is cached between calls.
void tungsten_precompute(const TungstenMaterial& m, TungstenTables& out);

/// Operation counts of one precompute, from its loop structure (and, for the wrapped Gaussian,
/// from running its terminating loop): what anyone can check against the source.
struct TungstenCounts {
  std::int64_t rule_newton_steps = 0;      // Newton iterations for the 140 roots (each a degree-140 recurrence)
  std::int64_t detector_gaussians = 0;     // exp() calls in the 3 × 2048 wrapped-Gaussian samples
  std::int64_t row_asin = 0, row_cos = 0, row_exp = 0, row_fresnel = 0;  // per-(θd row, node) precomputation
  std::int64_t node_visits = 0;            // (θd, φ, node) triples of the inner loop
  std::int64_t detector_lookups = 0;       // table lookups, each shared by the three colour channels
  std::int64_t colour_multiply_adds = 0;   // scalar multiply–adds of the Vec3 accumulations
  std::int64_t table_entries = 0;          // values written (3 lobes × 64 × 64 × RGB)
};
TungstenCounts tungsten_counts(const TungstenMaterial& m);

}  // namespace bench
