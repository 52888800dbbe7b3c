// What the ports of pbrt-v4's and Mitsuba 3's hair tests share (test_hair_scattering.cpp,
// test_fourier_scattering.cpp, test_material_scattering.cpp): the peers' roughness mappings, their
// direction sampling, pbrt's HOnTheEdge, Mitsuba's per-lane weights and its χ² test on the sphere.
// A fiber F is a Fiber, or a prepared runtime's PreparedFiber (HairScattering::fiber).
//   pbrt-v4 src/pbrt/bsdfs_test.cpp at commit 00aad0a68d6672d0e52f3d9c730406eee720f2b5;
//   Mitsuba 3 src/bsdfs/tests/test_hair.py and src/python/python/chi2.py at commit
//   0fec507e35a820a2fc0f3079686a3ee34b5697ad.
#pragma once

#include <hairlut/sampler/hair_scattering.hpp>

#include <algorithm>
#include <boost/math/special_functions/gamma.hpp>
#include <cmath>
#include <cstddef>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace peer {

constexpr double kPi = 3.14159265358979323846;

// The peers take roughness in [0, 1]; their plugins map it to the Bessel M_p's variance
// v = (0.726 β_m + 0.812 β_m² + 3.7 β_m²⁰)² and to a logistic scale s = √(π/8) (0.265 β_n + 1.194
// β_n² + 5.372 β_n²²). hairlut's β_m is √v and its β_n the standard deviation of a Gaussian, taken
// as that of the logistic (π s / √3).
inline double pbrt_beta_m(double b) { return 0.726 * b + 0.812 * b * b + 3.7 * std::pow(b, 20); }
inline double pbrt_beta_n(double b) {
  const double s = std::sqrt(kPi / 8.0) * (0.265 * b + 1.194 * b * b + 5.372 * std::pow(b, 22));
  return kPi * s / std::sqrt(3.0);
}

struct Rng {
  std::mt19937_64 g;
  explicit Rng(unsigned long long seed) : g(seed) {}
  double operator()() { return std::uniform_real_distribution<double>(0.0, 1.0)(g); }
};
// A grey fiber (σa in every channel) with the peers' roughness, clamped to [lo, hi] (a set's β range).
inline hairlut::sampler::Fiber grey_fiber(double pbrt_m, double pbrt_n, double sigma_a, double lo, double hi) {
  hairlut::sampler::Fiber f;
  f.beta_m = std::clamp(pbrt_beta_m(pbrt_m), lo, hi);
  f.beta_n = std::clamp(pbrt_beta_n(pbrt_n), lo, hi);
  f.sigma_a[0] = f.sigma_a[1] = f.sigma_a[2] = sigma_a;
  return f;
}
inline void uniform_sphere(double u0, double u1, double* w) {
  const double z = 1.0 - 2.0 * u0, r = std::sqrt(std::max(0.0, 1.0 - z * z)), a = 2.0 * kPi * u1;
  w[0] = r * std::cos(a), w[1] = r * std::sin(a), w[2] = z;
}
inline double average(const double* rgb) { return (rgb[0] + rgb[1] + rgb[2]) / 3.0; }

// pbrt-v4's Hair.WhiteFurnace and Hair.WhiteFurnaceSampled at one fiber and wo: S (the channels'
// mean) integrated over the sphere from `count` uniform directions, and the mean weight of 10⁴
// importance samples (pbrt: within [0.95, 1.05] and [0.99, 1.01] for a white fiber).
struct Furnaces {
  double uniform = 0.0, sampled = 0.0;
};
template <class T, class F>
Furnaces white_furnaces(const hairlut::sampler::HairScattering<T>& rt, const F& f, const double* wo, Rng& rng, int count) {
  Furnaces r;
  double sum = 0.0;
  for (int i = 0; i < count; ++i) {
    double wi[3], rgb[3];
    uniform_sphere(rng(), rng(), wi);
    rt.eval(f, wo, wi, rgb);
    sum += average(rgb);
  }
  r.uniform = sum / (count / (4.0 * kPi));
  for (int i = 0; i < 10000; ++i) {
    const double u[3] = {rng(), rng(), rng()};
    const hairlut::sampler::ScatteringSample s = rt.sample(f, wo, u);
    if (s.pdf > 0.0) r.sampled += average(s.weight) / 10000;
  }
  return r;
}

// pbrt-v4's Hair.HOnTheEdge, widened to the frame's edges: between pbrt's two vectors and the
// directions along, against and normal to the fiber, eval, sample (u = 0, ½ and 1 in every
// coordinate) and pdf are finite and ≥ 0, and every sample has a density. The number of failed
// checks, the first of them described in `first`.
struct EdgeChecks {
  int failures = 0;
  std::string first;
  void fail(const std::string& what) {
    if (failures++ == 0) first = what;
  }
};
template <class T, class F>
EdgeChecks h_on_the_edge(const hairlut::sampler::HairScattering<T>& rt, const F& f) {
  EdgeChecks r;
  // pbrt's vectors (its z is the fiber's normal, x along the fiber as here).
  const double wo[3] = {0.54986966, 0.03359017, 0.83457476}, wi[3] = {-0.37383357, -0.91920084, 0.12376696};
  const double along[3] = {1.0, 0.0, 0.0}, against[3] = {-1.0, 0.0, 0.0}, normal[3] = {0.0, 1.0, 0.0};
  const double* dirs[5] = {wo, wi, along, against, normal};
  const char* names[5] = {"pbrt's wo", "pbrt's wi", "along", "against", "normal"};
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      const std::string pair = std::string(names[i]) + " -> " + names[j];
      double rgb[3];
      rt.eval(f, dirs[i], dirs[j], rgb);
      for (double v : rgb)
        if (!(std::isfinite(v) && v >= 0.0)) r.fail("eval " + pair + " = " + std::to_string(v));
      for (const double u0 : {0.0, 0.5, 1.0}) {
        const double u[3] = {u0, u0, u0};
        const hairlut::sampler::ScatteringSample s = rt.sample(f, dirs[i], u);
        if (!(s.pdf > 0.0)) r.fail("sample at " + std::string(names[i]) + ", u = " + std::to_string(u0) + ": pdf " + std::to_string(s.pdf));
        for (double w : s.weight)
          if (!(std::isfinite(w) && w >= 0.0)) r.fail("sample at " + std::string(names[i]) + ": weight " + std::to_string(w));
      }
      const double p = rt.pdf(f, dirs[i], dirs[j]);
      if (!(std::isfinite(p) && p >= 0.0)) r.fail("pdf " + pair + " = " + std::to_string(p));
    }
  // A direction along the fiber has no azimuth: the signs of its zero components must change
  // neither S nor the pdf, held or sampled.
  for (const double x : {1.0, -1.0})
    for (int i = 0; i < 2; ++i) {
      const double plain[3] = {x, 0.0, 0.0};
      double want[3], want_back[3];
      rt.eval(f, dirs[i], plain, want);
      rt.eval(f, plain, dirs[i], want_back);
      const double want_pdf = rt.pdf(f, dirs[i], plain), want_pdf_back = rt.pdf(f, plain, dirs[i]);
      for (const double y : {0.0, -0.0})
        for (const double z : {0.0, -0.0}) {
          const double signed_zeros[3] = {x, y, z};
          double got[3], got_back[3];
          rt.eval(f, dirs[i], signed_zeros, got);
          rt.eval(f, signed_zeros, dirs[i], got_back);
          const std::string what = std::string(names[i]) + " and (" + std::to_string(x) + ", " + (std::signbit(y) ? "-0" : "0") + ", " +
                                   (std::signbit(z) ? "-0" : "0") + ")";
          for (int c = 0; c < 3; ++c)
            if (got[c] != want[c] || got_back[c] != want_back[c]) r.fail("eval of " + what + " depends on the signs of zeros");
          if (rt.pdf(f, dirs[i], signed_zeros) != want_pdf || rt.pdf(f, signed_zeros, dirs[i]) != want_pdf_back)
            r.fail("pdf of " + what + " depends on the signs of zeros");
        }
    }
  return r;
}

// Mitsuba 3's test04_sample_numeric for one fiber: `lanes` lanes, each wo uniform on the sphere
// and one sample; its weight is the Rec. 709 luminance of S cos / pdf (1 for a zero sample, as
// Mitsuba counts it), bad when |w − 1| > 1e-3. Adds to `acc` (Mitsuba runs 10⁵ lanes per fiber).
struct LaneWeights {
  long lanes = 0, bad = 0;
  double worst = 0.0;
};
template <class T, class F>
void sample_numeric(const hairlut::sampler::HairScattering<T>& rt, const F& f, Rng& rng, long lanes, LaneWeights& acc) {
  for (long i = 0; i < lanes; ++i) {
    double wo[3];
    uniform_sphere(rng(), rng(), wo);
    const double u[3] = {rng(), rng(), rng()};
    const hairlut::sampler::ScatteringSample s = rt.sample(f, wo, u);
    const double lum = s.pdf > 0.0 ? 0.212671 * s.weight[0] + 0.715160 * s.weight[1] + 0.072169 * s.weight[2] : 1.0;
    acc.worst = std::max(acc.worst, std::fabs(lum - 1.0));
    if (!(std::fabs(lum - 1.0) <= 1e-3)) ++acc.bad;
    ++acc.lanes;
  }
}

// pbrt-v4's Hair.SamplingWeights for one fiber: `count` samples, each at its own wo uniform on
// the sphere; a sample's weight (the channels' mean of S cos / pdf, divided by the albedo at wo
// where over_albedo) must lie in (0.99, 1.01). Adds to `acc` (pbrt draws 10⁴ per fiber).
struct WeightSpread {
  long total = 0, outside = 0;
  double lo = 1.0, hi = 1.0;
};
template <class T, class F>
void sampling_weights(const hairlut::sampler::HairScattering<T>& rt, const F& f, Rng& rng, long count, bool over_albedo,
                      WeightSpread& acc) {
  for (long i = 0; i < count; ++i) {
    double wo[3];
    uniform_sphere(rng(), rng(), wo);
    const double u[3] = {rng(), rng(), rng()};
    const auto sp = rt.at(f, wo);  // sp.sample(u) is rt.sample(f, wo, u); the albedo comes with it
    const hairlut::sampler::ScatteringSample s = sp.sample(u);
    if (!(s.pdf > 0.0)) continue;
    const double w = average(s.weight) / (over_albedo ? sp.albedo() : 1.0);
    ++acc.total;
    acc.lo = std::min(acc.lo, w), acc.hi = std::max(acc.hi, w);
    if (!(w > 0.99 && w < 1.01)) ++acc.outside;
  }
}

// pbrt-v4's Hair.SamplingConsistency at one shading point (f, wo): `count` draws, each giving an
// importance-sampled term S cos Li / pdf and a uniform one S cos Li 4π at a direction uniform on
// the sphere, with pbrt's Li(w) = w_z² (its z is our y). Returns the two estimates (pbrt: within 5%).
template <class T, class F>
std::pair<double, double> sampling_consistency(const hairlut::sampler::HairScattering<T>& rt, const F& f, const double* wo,
                                               Rng& rng, int count) {
  auto li = [](const double* w) { return w[1] * w[1]; };
  double importance = 0.0, uniform = 0.0;
  const auto sp = rt.at(f, wo);  // wo is held: rt.sample(f, wo, u) is sp.sample(u)
  for (int i = 0; i < count; ++i) {
    const double u[3] = {rng(), rng(), rng()};
    const hairlut::sampler::ScatteringSample s = sp.sample(u);
    if (s.pdf > 0.0) importance += average(s.weight) * li(s.wi) / count;
    double wi[3], rgb[3];
    uniform_sphere(u[1], u[2], wi);
    rt.eval(f, wo, wi, rgb);
    uniform += average(rgb) * li(wi) * 4.0 * kPi / count;
  }
  return {importance, uniform};
}

struct Chi2 {
  bool valid = false;
  double chi2 = 0.0, p = 0.0;
  int dof = 0;
};
// Mitsuba's ChiSquareTest on its SphericalDomain for one shading point: bins uniform in (azimuth,
// cos of the polar angle) — here the fiber frame's φi = atan2(z, y) and x = sin θi, the same
// equal-area grid — na × nb bins, `count` samples, expected counts from pdf() integrated over each
// bin (4 × 4 midpoints, Mitsuba's ires 4), bins expected below 5 pooled in increasing order of
// expectation, then the χ² p-value.
template <class T>
Chi2 chi2_sphere(const typename hairlut::sampler::HairScattering<T>::ShadingPoint& sp, unsigned long long seed, int na, int nb, long count) {
  Chi2 res;
  res.valid = sp.valid();
  if (!res.valid) return res;
  Rng rng(seed);
  std::vector<double> observed(static_cast<std::size_t>(na * nb), 0.0), expected(observed.size(), 0.0);
  for (long i = 0; i < count; ++i) {
    const double u[3] = {rng(), rng(), rng()};
    const hairlut::sampler::ScatteringSample s = sp.sample(u);
    if (!(s.pdf > 0.0)) continue;
    const double az = std::atan2(s.wi[2], s.wi[1]);
    const int a = std::clamp(static_cast<int>((az + kPi) / (2.0 * kPi) * na), 0, na - 1);
    const int b = std::clamp(static_cast<int>((s.wi[0] + 1.0) / 2.0 * nb), 0, nb - 1);
    observed[static_cast<std::size_t>(a * nb + b)] += 1.0;
  }
  const double cell = (2.0 * kPi / na) * (2.0 / nb) / 16.0;
  for (int a = 0; a < na; ++a)
    for (int b = 0; b < nb; ++b) {
      double sum = 0.0;
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
          const double az = -kPi + (a + (i + 0.5) / 4.0) * 2.0 * kPi / na, x = -1.0 + (b + (j + 0.5) / 4.0) * 2.0 / nb;
          const double r = std::sqrt(std::max(0.0, 1.0 - x * x)), wi[3] = {x, r * std::cos(az), r * std::sin(az)};
          sum += sp.pdf(wi);
        }
      expected[static_cast<std::size_t>(a * nb + b)] = sum * cell * static_cast<double>(count);
    }
  std::vector<std::size_t> order(observed.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return expected[x] < expected[y]; });
  double pool_o = 0.0, pool_e = 0.0;
  for (std::size_t k : order) {
    if (expected[k] < 5.0) {
      pool_o += observed[k], pool_e += expected[k];
      if (pool_e >= 5.0) res.chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e, ++res.dof, pool_o = pool_e = 0.0;
      continue;
    }
    res.chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
    ++res.dof;
  }
  if (pool_e > 0.0) res.chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e, ++res.dof;
  res.p = boost::math::gamma_q(0.5 * (res.dof - 1), 0.5 * res.chi2);
  return res;
}

// Not a peer's test: a prepared runtime's S against the runtime it was prepared from
// (HairScattering(source, roughness)) at the directions the prepared one draws, `per_wo` at each
// of `count` wo uniform on the sphere; the largest |difference| per channel over the largest S of
// the source drawn at the same wo. Returns −1 where a draw fails.
template <class T>
double prepared_error_over_peak(const hairlut::sampler::HairScattering<T>& source, const hairlut::sampler::HairScattering<T>& prepared,
                                const hairlut::sampler::Fiber& f, Rng& rng, int count, int per_wo) {
  const hairlut::sampler::PreparedFiber pf = prepared.fiber(f);
  double worst = 0.0;
  for (int k = 0; k < count; ++k) {
    double wo[3];
    uniform_sphere(rng(), rng(), wo);
    double peak[3] = {0.0, 0.0, 0.0}, err[3] = {0.0, 0.0, 0.0};
    for (int j = 0; j < per_wo; ++j) {
      const double u[3] = {rng(), rng(), rng()};
      const hairlut::sampler::ScatteringSample s = prepared.sample(pf, wo, u);
      if (!(s.pdf > 0.0)) return -1.0;
      double a[3], b[3];
      source.eval(f, wo, s.wi, a);
      prepared.eval(pf, wo, s.wi, b);
      for (int c = 0; c < 3; ++c) peak[c] = std::max(peak[c], a[c]), err[c] = std::max(err[c], std::fabs(a[c] - b[c]));
    }
    for (int c = 0; c < 3; ++c)
      if (peak[c] > 0.0) worst = std::max(worst, err[c] / peak[c]);
  }
  return worst;
}

}  // namespace peer
