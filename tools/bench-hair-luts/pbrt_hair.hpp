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

/// Float is pbrt's Float: float by default, double in a build with PBRT_FLOAT_AS_DOUBLE (FastExp
/// stays float there, as in pbrt).
template <class Float>
struct PbrtVec3T {
  Float x, y, z;
};

template <class Float>
class PbrtHairT {
 public:
  static constexpr int kPMax = 3, kSamples = 4;
  using Spectrum = std::array<Float, kSamples>;
  using Vec3 = PbrtVec3T<Float>;
  /// h ∈ [−1, 1] offset across the fiber, η, σa per spectral sample, β_m, β_n ∈ [0, 1], α in degrees.
  PbrtHairT(Float h, Float eta, const Spectrum& sigma_a, Float beta_m, Float beta_n, Float alpha_deg);
  /// f(wo, wi) in pbrt's hair frame (x along the fiber), divided by |cos θ| of wi as there.
  Spectrum f(Vec3 wo, Vec3 wi) const;
  /// Sample_f: the lobe by A_p at θo (uc, remapped for φ), θi by inverting M_p (u0, u1), φ by the
  /// trimmed logistic; the pdf summed over the lobes and f at the drawn direction, as there.
  struct Sampled {
    Vec3 wi;
    Spectrum f;
    Float pdf;
  };
  Sampled sample_f(Vec3 wo, Float uc, Float u0, Float u1) const;
  /// PDF(wo, wi), as there.
  Float pdf(Vec3 wo, Vec3 wi) const;

 private:
  Float mixture_pdf(Float sin_o, Float cos_o, Float sin_i, Float cos_i, Float phi, Float gamma_o, Float gamma_t,
                    const std::array<Float, kPMax + 1>& apdf) const;
  Float h_, eta_;
  Spectrum sigma_a_;
  Float v_[kPMax + 1];
  Float s_;
  Float sin2k_[kPMax], cos2k_[kPMax];
};

using PbrtVec3 = PbrtVec3T<float>;
using PbrtHair = PbrtHairT<float>;
extern template class PbrtHairT<float>;
extern template class PbrtHairT<double>;

}  // namespace bench
