// pbrt-v4's HairBxDF::f re-implemented operation for operation (files and commit in the header).
#include "pbrt_hair.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

namespace bench {
namespace {

// pbrt's Pi is a Float constant; its other literals are float (0.726f, ...) and are promoted
// where Float is double, as the code below keeps them.
template <class F>
constexpr F kPi = static_cast<F>(3.14159265358979323846);

template <class F>
F sq(F v) { return v * v; }
template <class F>
F safe_sqrt(F v) { return std::sqrt(std::max<F>(0, v)); }
template <class F>
F safe_asin(F v) { return std::asin(std::clamp<F>(v, -1, 1)); }
template <class F>
F pow_n(F v, int n) {  // pbrt's Pow<n> by repeated squaring
  if (n == 0) return 1;
  const F half = pow_n(v, n / 2);
  return (n & 1) ? half * half * v : half * half;
}

// 2^x' with x' = x log2 e: integer part into the exponent bits, 2^f by a cubic with fused steps.
float fast_exp(float x) {
  const float xp = x * 1.442695041f;
  const float fxp = std::floor(xp), f = xp - fxp;
  const int i = static_cast<int>(fxp);
  const float two_f = std::fma(f, std::fma(f, std::fma(f, 0.0781455737f, 0.226173572f), 0.695556856f), 1.0f);
  const int exponent = static_cast<int>(std::bit_cast<std::uint32_t>(two_f) >> 23) - 127 + i;
  if (exponent < -126) return 0.0f;
  if (exponent > 127) return INFINITY;
  std::uint32_t bits = std::bit_cast<std::uint32_t>(two_f);
  bits &= 0b10000000011111111111111111111111u;
  bits |= static_cast<std::uint32_t>(exponent + 127) << 23;
  return std::bit_cast<float>(bits);
}

// I0(x) ≈ Σ_{i<10} x^{2i} / (4^i (i!)²), integer factorials as there.
template <class F>
F bessel_i0(F x) {
  F val = 0, x2i = 1;
  std::int64_t ifact = 1;
  int i4 = 1;
  for (int i = 0; i < 10; ++i) {
    if (i > 1) ifact *= i;
    val += x2i / static_cast<F>(i4 * ifact * ifact);
    x2i *= x * x;
    i4 *= 4;
  }
  return val;
}

template <class F>
F log_bessel_i0(F x) {
  if (x > 12.0f) return x + 0.5f * (-std::log(2.0f * kPi<F>) + std::log(1.0f / x) + 1.0f / (8.0f * x));
  return std::log(bessel_i0(x));
}

// FastExp takes and returns float in either build, as pbrt's does.
template <class F>
F longitudinal(F cos_i, F cos_o, F sin_i, F sin_o, F v) {
  const F a = cos_i * cos_o / v, b = sin_i * sin_o / v;
  return v <= 0.1f ? fast_exp(static_cast<float>(log_bessel_i0(a) - b - 1.0f / v + 0.6931f + std::log(1.0f / (2.0f * v))))
                   : (fast_exp(static_cast<float>(-b)) * bessel_i0(a)) / (std::sinh(1.0f / v) * 2.0f * v);
}

template <class F>
F fresnel_dielectric(F cos_i, F eta) {
  cos_i = std::clamp<F>(cos_i, -1, 1);
  if (cos_i < 0.0f) {
    eta = 1.0f / eta;
    cos_i = -cos_i;
  }
  const F sin2_t = (1.0f - sq(cos_i)) / sq(eta);
  if (sin2_t >= 1.0f) return 1;
  const F cos_t = safe_sqrt<F>(1.0f - sin2_t);
  const F parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const F perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return (sq(parl) + sq(perp)) / 2.0f;
}

template <class F>
F trimmed_logistic(F x, F s) {
  // Logistic(x, s) / (LogisticCDF(π, s) − LogisticCDF(−π, s)).
  x = std::abs(x);
  const F logistic = std::exp(-x / s) / (s * sq<F>(1.0f + std::exp(-x / s)));  // two exp() calls, as there
  return logistic / (1.0f / (1.0f + std::exp(-kPi<F> / s)) - 1.0f / (1.0f + std::exp(kPi<F> / s)));
}

template <class F>
F azimuthal(F phi, int p, F s, F gamma_o, F gamma_t) {
  F dphi = phi - (2.0f * static_cast<F>(p) * gamma_t - 2.0f * gamma_o + static_cast<F>(p) * kPi<F>);
  while (dphi > kPi<F>) dphi -= 2.0f * kPi<F>;
  while (dphi < -kPi<F>) dphi += 2.0f * kPi<F>;
  return trimmed_logistic(dphi, s);
}

// InvertLogisticSample and SampleLogistic; x drawn from the logistic of scale s trimmed to [a, b].
template <class F>
F sample_trimmed_logistic(F u, F s, F a, F b) {
  auto cdf = [s](F x) { return 1.0f / (1.0f + fast_exp(static_cast<float>(-x / s))); };
  const F ca = cdf(a), cb = cdf(b);
  u = (1.0f - u) * ca + u * cb;
  return std::clamp<F>(-s * std::log(1.0f / u - 1.0f), a, b);
}

// The index whose cumulative weight brackets u · Σ w, and u remapped into that weight
// (OneMinusEpsilon: the largest Float below 1).
template <class F, std::size_t N>
int sample_discrete(const std::array<F, N>& w, F u, F* remapped) {
  F total = 0;
  for (F x : w) total += x;
  F up = u * total;
  if (up == total) up = std::nextafter(up, F(0));
  int k = 0;
  F sum = 0;
  while (sum + w[static_cast<std::size_t>(k)] <= up) sum += w[static_cast<std::size_t>(k++)];
  *remapped = std::min<F>((up - sum) / w[static_cast<std::size_t>(k)], std::nextafter(F(1), F(0)));
  return k;
}

// pbrt's Ap(cos θo, η, h, T).
template <std::size_t N, class F, std::size_t K>
std::array<std::array<F, K>, N> attenuation(F cos_o, F eta, F h, const std::array<F, K>& T) {
  std::array<std::array<F, K>, N> ap{};
  const F fr = fresnel_dielectric<F>(cos_o * safe_sqrt<F>(1.0f - sq(h)), eta);
  for (std::size_t k = 0; k < K; ++k) ap[0][k] = fr, ap[1][k] = sq<F>(1.0f - fr) * T[k];
  for (std::size_t p = 2; p + 1 < N; ++p)
    for (std::size_t k = 0; k < K; ++k) ap[p][k] = ap[p - 1][k] * T[k] * fr;
  bool any = false;
  for (std::size_t k = 0; k < K; ++k) any |= (1.0f - T[k] * fr) != 0.0f;
  if (any)
    for (std::size_t k = 0; k < K; ++k) ap[N - 1][k] = ap[N - 2][k] * fr * T[k] / (1.0f - T[k] * fr);
  return ap;
}

}  // namespace

template <class F>
PbrtHairT<F>::PbrtHairT(F h, F eta, const Spectrum& sigma_a, F beta_m, F beta_n, F alpha_deg)
    : h_(h), eta_(eta), sigma_a_(sigma_a) {
  v_[0] = sq(0.726f * beta_m + 0.812f * sq(beta_m) + 3.7f * pow_n(beta_m, 20));
  v_[1] = 0.25f * v_[0];
  v_[2] = 4.0f * v_[0];
  for (int p = 3; p <= kPMax; ++p) v_[p] = v_[2];
  s_ = 0.626657069f * (0.265f * beta_n + 1.194f * sq(beta_n) + 5.372f * pow_n(beta_n, 22));
  sin2k_[0] = std::sin(alpha_deg * (kPi<F> / 180.0f));
  cos2k_[0] = safe_sqrt(1.0f - sq(sin2k_[0]));
  for (int i = 1; i < kPMax; ++i) {
    sin2k_[i] = 2.0f * cos2k_[i - 1] * sin2k_[i - 1];
    cos2k_[i] = sq(cos2k_[i - 1]) - sq(sin2k_[i - 1]);
  }
}

template <class F>
typename PbrtHairT<F>::Spectrum PbrtHairT<F>::f(Vec3 wo, Vec3 wi) const {
  const F sin_o = wo.x, cos_o = safe_sqrt(1.0f - sq(sin_o));
  const F phi_o = std::atan2(wo.z, wo.y);
  const F gamma_o = safe_asin(h_);
  const F sin_i = wi.x, cos_i = safe_sqrt(1.0f - sq(sin_i));
  const F phi_i = std::atan2(wi.z, wi.y);
  const F sin_t = sin_o / eta_, cos_t = safe_sqrt(1.0f - sq(sin_t));
  const F etap = safe_sqrt(sq(eta_) - sq(sin_o)) / cos_o;
  const F sin_gt = h_ / etap, cos_gt = safe_sqrt(1.0f - sq(sin_gt));
  const F gamma_t = safe_asin(sin_gt);
  Spectrum T;
  for (int k = 0; k < kSamples; ++k) T[k] = std::exp(-sigma_a_[k] * (2.0f * cos_gt / cos_t));
  const F phi = phi_i - phi_o;

  // A_p: Fresnel at the first hit, then (1 − f)² T (T f)^{p−1}, and the tail after pMax.
  std::array<Spectrum, kPMax + 1> ap{};
  const F fr = fresnel_dielectric(cos_o * safe_sqrt(1.0f - sq(h_)), eta_);
  for (int k = 0; k < kSamples; ++k) {
    ap[0][k] = fr;
    ap[1][k] = sq(1.0f - fr) * T[k];
  }
  for (int p = 2; p < kPMax; ++p)
    for (int k = 0; k < kSamples; ++k) ap[p][k] = ap[p - 1][k] * T[k] * fr;
  bool any = false;
  for (int k = 0; k < kSamples; ++k) any |= (1.0f - T[k] * fr) != 0.0f;
  if (any)
    for (int k = 0; k < kSamples; ++k) ap[kPMax][k] = ap[kPMax - 1][k] * fr * T[k] / (1.0f - T[k] * fr);

  Spectrum sum{};
  for (int p = 0; p < kPMax; ++p) {
    F sin_po, cos_po;
    if (p == 0) {
      sin_po = sin_o * cos2k_[1] - cos_o * sin2k_[1];
      cos_po = cos_o * cos2k_[1] + sin_o * sin2k_[1];
    } else if (p == 1) {
      sin_po = sin_o * cos2k_[0] + cos_o * sin2k_[0];
      cos_po = cos_o * cos2k_[0] - sin_o * sin2k_[0];
    } else {
      sin_po = sin_o * cos2k_[2] + cos_o * sin2k_[2];
      cos_po = cos_o * cos2k_[2] - sin_o * sin2k_[2];
    }
    cos_po = std::abs(cos_po);
    const F mp = longitudinal(cos_i, cos_po, sin_i, sin_po, v_[p]);
    const F np = azimuthal(phi, p, s_, gamma_o, gamma_t);
    for (int k = 0; k < kSamples; ++k) sum[k] += mp * ap[p][k] * np;
  }
  const F mtail = longitudinal(cos_i, cos_o, sin_i, sin_o, v_[kPMax]);
  for (int k = 0; k < kSamples; ++k) sum[k] += mtail * ap[kPMax][k] / (2.0f * kPi<F>);
  const F abs_cos = std::abs(wi.z);
  if (abs_cos > 0.0f)
    for (int k = 0; k < kSamples; ++k) sum[k] /= abs_cos;
  return sum;
}

}  // namespace bench

namespace bench {

// ComputeApPDF(cos θo): each lobe's A_p averaged over the spectral samples, over their sum.
template <class F>
static std::array<F, PbrtHairT<F>::kPMax + 1> ap_pdf(F cos_o, F eta, F h, const typename PbrtHairT<F>::Spectrum& sigma_a) {
  const F sin_o = safe_sqrt(1.0f - cos_o * cos_o);
  const F sin_t = sin_o / eta, cos_t = safe_sqrt(1.0f - sq(sin_t));
  const F etap = safe_sqrt(eta * eta - sq(sin_o)) / cos_o;
  const F sin_gt = h / etap, cos_gt = safe_sqrt(1.0f - sq(sin_gt));
  typename PbrtHairT<F>::Spectrum T;
  for (int k = 0; k < PbrtHairT<F>::kSamples; ++k) T[static_cast<std::size_t>(k)] = std::exp(-sigma_a[static_cast<std::size_t>(k)] * (2.0f * cos_gt / cos_t));
  const auto ap = attenuation<PbrtHairT<F>::kPMax + 1>(cos_o, eta, h, T);
  std::array<F, PbrtHairT<F>::kPMax + 1> pdf{};
  F sum = 0.0f;
  for (const auto& a : ap) sum += (a[0] + a[1] + a[2] + a[3]) / 4.0f;
  for (std::size_t p = 0; p < pdf.size(); ++p) pdf[p] = (ap[p][0] + ap[p][1] + ap[p][2] + ap[p][3]) / 4.0f / sum;
  return pdf;
}

// sin θo and cos θo of lobe p rotated by its scale tilt (pbrt's p = 0, 1, 2 cases).
template <class F>
static void tilted(int p, F sin_o, F cos_o, const F* sin2k, const F* cos2k, F& s, F& c) {
  if (p == 0) s = sin_o * cos2k[1] - cos_o * sin2k[1], c = cos_o * cos2k[1] + sin_o * sin2k[1];
  else if (p == 1) s = sin_o * cos2k[0] + cos_o * sin2k[0], c = cos_o * cos2k[0] - sin_o * sin2k[0];
  else if (p == 2) s = sin_o * cos2k[2] + cos_o * sin2k[2], c = cos_o * cos2k[2] - sin_o * sin2k[2];
  else s = sin_o, c = cos_o;
}

template <class F>
typename PbrtHairT<F>::Sampled PbrtHairT<F>::sample_f(Vec3 wo, F uc, F u0, F u1) const {
  const F sin_o = wo.x, cos_o = safe_sqrt(1.0f - sq(sin_o));
  const F phi_o = std::atan2(wo.z, wo.y);
  const auto apdf = ap_pdf(cos_o, eta_, h_, sigma_a_);
  const int p = sample_discrete(apdf, uc, &uc);
  F sin_po, cos_po;
  tilted(p, sin_o, cos_o, sin2k_, cos2k_, sin_po, cos_po);
  const F v = v_[p];
  const F cos_theta = 1.0f + v * std::log(std::max<F>(u0, 1e-5f) + (1.0f - u0) * fast_exp(static_cast<float>(-2.0f / v)));
  const F sin_theta = safe_sqrt(1.0f - sq(cos_theta)), cos_phi = std::cos(2.0f * kPi<F> * u1);
  const F sin_i = -cos_theta * sin_po + sin_theta * cos_phi * cos_po, cos_i = safe_sqrt(1.0f - sq(sin_i));
  const F etap = safe_sqrt(eta_ * eta_ - sq(sin_o)) / cos_o;
  const F gamma_o = safe_asin(h_), gamma_t = safe_asin(h_ / etap);
  const F dphi = p < kPMax ? 2.0f * static_cast<F>(p) * gamma_t - 2.0f * gamma_o + static_cast<F>(p) * kPi<F> + sample_trimmed_logistic(uc, s_, -kPi<F>, kPi<F>)
                               : 2.0f * kPi<F> * uc;
  const F phi_i = phi_o + dphi;
  Sampled r;
  r.wi = {sin_i, cos_i * std::cos(phi_i), cos_i * std::sin(phi_i)};
  r.pdf = mixture_pdf(sin_o, cos_o, sin_i, cos_i, dphi, gamma_o, gamma_t, apdf);
  r.f = f(wo, r.wi);
  return r;
}

template <class F>
F PbrtHairT<F>::pdf(Vec3 wo, Vec3 wi) const {
  const F sin_o = wo.x, cos_o = safe_sqrt(1.0f - sq(sin_o));
  const F phi_o = std::atan2(wo.z, wo.y);
  const F sin_i = wi.x, cos_i = safe_sqrt(1.0f - sq(sin_i));
  const F phi_i = std::atan2(wi.z, wi.y);
  const F etap = safe_sqrt(eta_ * eta_ - sq(sin_o)) / cos_o;
  const F gamma_o = safe_asin(h_), gamma_t = safe_asin(h_ / etap);
  const auto apdf = ap_pdf(cos_o, eta_, h_, sigma_a_);
  return mixture_pdf(sin_o, cos_o, sin_i, cos_i, phi_i - phi_o, gamma_o, gamma_t, apdf);
}

// Σ_p M_p(θi; tilted θo) · A_p pdf · N_p(φ) and the tail's M_p / 2π: the pdf Sample_f and PDF sum
// the same way.
template <class F>
F PbrtHairT<F>::mixture_pdf(F sin_o, F cos_o, F sin_i, F cos_i, F phi, F gamma_o, F gamma_t,
                            const std::array<F, kPMax + 1>& apdf) const {
  F pdf = 0.0f;
  for (int q = 0; q < kPMax; ++q) {
    F s, c;
    tilted(q, sin_o, cos_o, sin2k_, cos2k_, s, c);
    pdf += longitudinal(cos_i, std::abs(c), sin_i, s, v_[q]) * apdf[static_cast<std::size_t>(q)] * azimuthal(phi, q, s_, gamma_o, gamma_t);
  }
  pdf += longitudinal(cos_i, cos_o, sin_i, sin_o, v_[kPMax]) * apdf[kPMax] * (1.0f / (2.0f * kPi<F>));
  return pdf;
}

template class PbrtHairT<float>;
template class PbrtHairT<double>;

}  // namespace bench
