// pbrt-v4's analytic hair BSDF evaluation HairBxDF::f, re-implemented (not copied) from its
// published equations and code: src/pbrt/bxdfs.h and src/pbrt/bxdfs.cpp (HairBxDF constructor,
// f, Mp, Ap, Np, Phi), src/pbrt/util/math.h (I0, LogI0, FastExp, Logistic, TrimmedLogistic,
// SafeSqrt, SafeASin) and src/pbrt/util/scattering.h (FrDielectric) of github.com/mmp/pbrt-v4 at
// commit 5f7a606806a4ac7b939131ded9d7a30ebd02416e, and HairBxDF::Sample_f, PDF and ComputeApPDF
// with SampleDiscrete and SampleTrimmedLogistic (src/pbrt/util/sampling.h) as at commit
// 4607f0e485627e70dd838c66181016760c582c8b. Same algorithm and float arithmetic: the
// d'Eon/Chiang longitudinal M_p with pbrt's variance map, A_p up to pMax = 3 with the geometric
// tail, the trimmed logistic N_p, scale tilts by the 2^k α double-angle recurrence, and four
// spectral samples (pbrt's NSpectrumSamples). bench-hair-luts times it per call; the sampler's
// table lookups can be timed against it with the same directions.
#pragma once

#include <array>

namespace bench {

struct PbrtVec3 {
  float x, y, z;
};

class PbrtHair {
 public:
  static constexpr int kPMax = 3, kSamples = 4;
  using Spectrum = std::array<float, kSamples>;
  /// h ∈ [−1, 1] offset across the fiber, η, σa per spectral sample, β_m, β_n ∈ [0, 1], α in degrees.
  PbrtHair(float h, float eta, const Spectrum& sigma_a, float beta_m, float beta_n, float alpha_deg);
  /// f(wo, wi) in pbrt's hair frame (x along the fiber), divided by |cos θ| of wi as there.
  Spectrum f(PbrtVec3 wo, PbrtVec3 wi) const;
  /// Sample_f: the lobe by A_p at θo (uc, remapped for φ), θi by inverting M_p (u0, u1), φ by the
  /// trimmed logistic; the pdf summed over the lobes and f at the drawn direction, as there.
  struct Sampled {
    PbrtVec3 wi;
    Spectrum f;
    float pdf;
  };
  Sampled sample_f(PbrtVec3 wo, float uc, float u0, float u1) const;
  /// PDF(wo, wi), as there.
  float pdf(PbrtVec3 wo, PbrtVec3 wi) const;

 private:
  float mixture_pdf(float sin_o, float cos_o, float sin_i, float cos_i, float phi, float gamma_o, float gamma_t,
                    const std::array<float, kPMax + 1>& apdf) const;
  float h_, eta_;
  Spectrum sigma_a_;
  float v_[kPMax + 1];
  float s_;
  float sin2k_[kPMax], cos2k_[kPMax];
};

}  // namespace bench
