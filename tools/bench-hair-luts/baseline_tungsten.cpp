// Tungsten's HairBcsdf precompute, re-implemented operation for operation (see the header for the
// files and commit followed). The structure, the order of the loops and the float arithmetic follow
// that code, including its choices: three identical detector tables, the detector indexed modulo
// 2048 over 2047 intervals, cos γi recomputed per θd row. Written anew for hairlut; not its code.
#include "baseline_tungsten.hpp"

#include <algorithm>
#include <cmath>

namespace bench {
namespace {

// Tungsten's float constants (math/Angle.hpp).
constexpr float kPiF = 3.1415926536f;
constexpr float kTwoPiF = kPiF * 2.0f;
constexpr float kInvTwoPiF = 0.5f * (1.0f / kPiF);
constexpr int kRes = TungstenTables::kResolution;
constexpr int kM = TungstenTables::kNodes;
constexpr int kDet = TungstenTables::kDetectorSamples;

// Legendre polynomial P_n(x) by the three-term recurrence, in double.
double legendre_p(double x, int n) {
  if (n == 0) return 1.0;
  if (n == 1) return x;
  double prev = 1.0, cur = x;
  for (int k = 2; k <= n; ++k) {
    const double next = ((2.0 * k - 1.0) * x * cur - (k - 1.0) * prev) / k;
    prev = cur;
    cur = next;
  }
  return cur;
}

// P_n'(x) = n (x P_n − P_{n−1}) / (x² − 1): two more recurrences, as there.
double legendre_dp(double x, int n) { return n / (x * x - 1.0) * (x * legendre_p(x, n) - legendre_p(x, n - 1)); }

struct Rule {
  std::array<float, kM> x, w;
  int newton_steps = 0;
};

// Roots from Tricomi's first guess refined by Newton until |P_N| < 1e−6 (at most 100 steps), in
// double, then rounded to float; weights from the rounded roots.
void build_rule(Rule& r) {
  constexpr double N = kM;
  for (int k = 1; k <= kM; ++k) {
    double x = std::cos(static_cast<double>(kPiF) * (4.0 * k - 1.0) / (4.0 * N + 2.0)) * (1.0 - 1.0 / (8.0 * N * N) + 1.0 / (8.0 * N * N * N));
    for (int it = 0; it < 100; ++it) {
      ++r.newton_steps;
      const double f = legendre_p(x, kM);
      x -= f / legendre_dp(x, kM);
      if (std::abs(f) < 1e-6) break;
    }
    const auto i = static_cast<std::size_t>(k - 1);
    r.x[i] = static_cast<float>(x);
    const float x2 = r.x[i] * r.x[i];
    const double d = legendre_dp(r.x[i], kM);
    r.w[i] = static_cast<float>(2.0 / ((1.0 - x2) * (d * d)));
  }
}

float gaussian(float beta, float t) { return std::exp(-t * t / (2.0f * beta * beta)) / (std::sqrt(2.0f * kPiF) * beta); }

// The wrapped Gaussian detector summed image pair by image pair until a pair adds ≤ 1e−4.
float wrapped_detector(float beta, float phi, std::int64_t* gaussians) {
  float sum = 0.0f, pair = 0.0f, shift = 0.0f;
  do {
    pair = gaussian(beta, phi + shift) + gaussian(beta, phi - shift - kTwoPiF);
    if (gaussians) *gaussians += 2;
    sum += pair;
    shift += kTwoPiF;
  } while (pair > 1e-4f);
  return sum;
}

float exit_phi(float gi, float gt, int p) { return 2.0f * static_cast<float>(p) * gt - 2.0f * gi + static_cast<float>(p) * kPiF; }

// Unpolarised Fresnel reflectance with relative index `eta` (here 1/η) at incidence cosine c.
float fresnel(float eta, float c) {
  if (c < 0.0f) {
    eta = 1.0f / eta;
    c = -c;
  }
  const float s2 = eta * eta * (1.0f - c * c);
  if (s2 > 1.0f) return 1.0f;
  const float ct = std::sqrt(std::max(1.0f - s2, 0.0f));
  const float rs = (eta * c - ct) / (eta * c + ct);
  const float rp = (eta * ct - c) / (eta * ct + c);
  return (rs * rs + rp * rp) * 0.5f;
}

// The sampling distribution of one lobe: max over channels, dilated by one cell in x then y, and
// per θd row a normalised pdf and cdf (uniform when the row sums below 1e−4).
void build_sampler(TungstenLobe& l) {
  std::vector<float> w(static_cast<std::size_t>(kRes * kRes));
  for (std::size_t i = 0; i < w.size(); ++i) w[i] = std::max(std::max(l.value[3 * i], l.value[3 * i + 1]), l.value[3 * i + 2]);
  auto at = [&](int x, int y) -> float& { return w[static_cast<std::size_t>(x + y * kRes)]; };
  for (int y = 0; y < kRes; ++y) {
    for (int x = 0; x < kRes - 1; ++x) at(x, y) = std::max(at(x, y), at(x + 1, y));
    for (int x = kRes - 1; x > 0; --x) at(x, y) = std::max(at(x, y), at(x - 1, y));
  }
  for (int x = 0; x < kRes; ++x) {
    for (int y = 0; y < kRes - 1; ++y) at(x, y) = std::max(at(x, y), at(x, y + 1));
    for (int y = kRes - 1; y > 0; --y) at(x, y) = std::max(at(x, y), at(x, y - 1));
  }
  l.pdf = std::move(w);
  l.cdf.assign(static_cast<std::size_t>((kRes + 1) * kRes), 0.0f);
  l.sum.assign(kRes, 0.0f);
  for (int d = 0; d < kRes; ++d) {
    float* pdf = l.pdf.data() + d * kRes;
    float* cdf = l.cdf.data() + d * (kRes + 1);
    cdf[0] = 0.0f;
    for (int x = 0; x < kRes; ++x) cdf[x + 1] = pdf[x] + cdf[x];
    l.sum[static_cast<std::size_t>(d)] = cdf[kRes];
    if (cdf[kRes] < 1e-4f) {
      const float u = 1.0f / kRes;
      for (int x = 0; x < kRes; ++x) pdf[x] = u, cdf[x] = static_cast<float>(x) * u;
    } else {
      const float s = 1.0f / cdf[kRes];
      for (int x = 0; x < kRes; ++x) pdf[x] *= s, cdf[x] *= s;
    }
    cdf[kRes] = 1.0f;
  }
}

}  // namespace

void tungsten_precompute(const TungstenMaterial& m, TungstenTables& out) {
  for (TungstenLobe& l : out.lobe) l.value.assign(static_cast<std::size_t>(kRes * kRes * 3), 0.0f);
  Rule rule;
  build_rule(rule);
  std::array<float, kM> gi{};
  for (int i = 0; i < kM; ++i) gi[static_cast<std::size_t>(i)] = std::asin(rule.x[static_cast<std::size_t>(i)]);

  // Three detector tables (Tungsten fills one per lobe, each of width β), 2048 samples over [0, 2π].
  std::array<std::vector<float>, 3> det;
  for (auto& d : det) {
    d.resize(kDet);
    for (int i = 0; i < kDet; ++i) d[static_cast<std::size_t>(i)] = wrapped_detector(m.beta, static_cast<float>(i) / (kDet - 1.0f) * kTwoPiF, nullptr);
  }
  // Linear interpolation, index wrapped modulo 2048 (the table spans 2047 intervals).
  auto lookup = [&](int p, float phi) {
    float u = std::abs(phi * (kInvTwoPiF * (kDet - 1)));
    const int x0 = static_cast<int>(u);
    const int x1 = x0 + 1;
    u -= static_cast<float>(x0);
    const float* d = det[static_cast<std::size_t>(p)].data();
    return d[x0 % kDet] * (1.0f - u) + d[x1 % kDet] * u;
  };

  const float eta = m.eta;
  std::array<float, kM> gt{}, fr{};
  std::array<std::array<float, 3>, kM> T{};
  for (int y = 0; y < kRes; ++y) {
    const float cd = static_cast<float>(y) / (kRes - 1.0f);
    const float ior_prime = std::sqrt(eta * eta - (1.0f - cd * cd)) / cd;
    const float inv_eta = 1.0f / eta;
    const float cos_t = std::sqrt(1.0f - (1.0f - cd * cd) * (inv_eta * inv_eta));
    std::array<float, 3> sp{};
    for (int c = 0; c < 3; ++c) sp[static_cast<std::size_t>(c)] = m.sigma_a[static_cast<std::size_t>(c)] / cos_t;
    for (std::size_t i = 0; i < kM; ++i) {
      gt[i] = std::asin(std::clamp(rule.x[i] / ior_prime, -1.0f, 1.0f));
      fr[i] = fresnel(1.0f / eta, cd * std::cos(gi[i]));
      const float cg = std::cos(gt[i]);
      for (std::size_t c = 0; c < 3; ++c) T[i][c] = std::exp(-sp[c] * 2.0f * cg);
    }
    for (int x = 0; x < kRes; ++x) {
      const float phi = kTwoPiF * static_cast<float>(x) / (kRes - 1.0f);
      float iR = 0.0f;
      float iTT[3] = {0.0f, 0.0f, 0.0f}, iTRT[3] = {0.0f, 0.0f, 0.0f};
      for (std::size_t i = 0; i < kM; ++i) {
        const float f = fr[i];
        const float aR = f;
        float aTT[3], aTRT[3];
        for (std::size_t c = 0; c < 3; ++c) aTT[c] = (1.0f - f) * (1.0f - f) * T[i][c];
        for (std::size_t c = 0; c < 3; ++c) aTRT[c] = aTT[c] * f * T[i][c];
        const float w = rule.w[i];
        iR += w * lookup(0, phi - exit_phi(gi[i], gt[i], 0)) * aR;
        const float dTT = w * lookup(1, phi - exit_phi(gi[i], gt[i], 1));
        for (std::size_t c = 0; c < 3; ++c) iTT[c] += dTT * aTT[c];
        const float dTRT = w * lookup(2, phi - exit_phi(gi[i], gt[i], 2));
        for (std::size_t c = 0; c < 3; ++c) iTRT[c] += dTRT * aTRT[c];
      }
      const std::size_t o = static_cast<std::size_t>(x + y * kRes) * 3;
      for (std::size_t c = 0; c < 3; ++c) {
        out.lobe[0].value[o + c] = 0.5f * iR;
        out.lobe[1].value[o + c] = 0.5f * iTT[c];
        out.lobe[2].value[o + c] = 0.5f * iTRT[c];
      }
    }
  }
  for (TungstenLobe& l : out.lobe) build_sampler(l);
}

TungstenCounts tungsten_counts(const TungstenMaterial& m) {
  TungstenCounts n;
  Rule rule;
  build_rule(rule);
  n.rule_newton_steps = rule.newton_steps;
  for (int p = 0; p < 3; ++p)
    for (int i = 0; i < kDet; ++i) wrapped_detector(m.beta, static_cast<float>(i) / (kDet - 1.0f) * kTwoPiF, &n.detector_gaussians);
  n.row_asin = static_cast<std::int64_t>(kRes) * kM;
  n.row_cos = 2 * n.row_asin;  // cos γi (recomputed per row) and cos γt
  n.row_exp = 3 * n.row_asin;
  n.row_fresnel = n.row_asin;
  n.node_visits = static_cast<std::int64_t>(kRes) * kRes * kM;
  n.detector_lookups = 3 * n.node_visits;
  n.colour_multiply_adds = n.node_visits * (1 + 3 + 3 + 3 + 3);  // R; ATT, ATRT; TT and TRT accumulations
  n.table_entries = 3 * kRes * kRes * 3;
  return n;
}

}  // namespace bench
