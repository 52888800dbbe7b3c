// The unity-hdrp-hair textures against HDRP's own kernels, texel for texel.
//
// The kernels are ported here a second time, independently of lib/src/bake/hdrp_kernels.cpp (written
// from the engine files, with different algebra and different quadrature), from
// Unity-Technologies/Graphics, Packages/com.unity.render-pipelines.high-definition/Runtime/Material/Hair/:
//   [C]  MultipleScattering/HairMultipleScatteringPreIntegration.compute   (blob at commit e3089c7ac636)
//   [RC] Reference/HairReferenceCommon.hlsl                                (blob at commit bfe38f41d518)
//   [R]  Reference/HairReference.hlsl                                      (blob at commit e2f5fc684f11)
//   [H]  Hair.hlsl (ConvertSurfaceDataToBSDFData, AbsorptionFromReflectance, ModifiedRefractionIndex)
// Each formula below names its file and line. The baked EXR is read back and every texel of every
// channel is compared with the reference: |texel − ref| ≤ ½ ulp_half(ref) + (2^-24 + ε)|ref|: the
// writer's rounding (double → float → half) plus ε covering the preset's quadrature (relative 1e-10)
// and the reference's (bounded per test below).
#include <Imath/half.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/outputs.hpp>
#include <hairlut/io/engine_exr.hpp>
#include <hairlut/bake/hdrp_kernels.hpp>
#include <hairlut/util/quadrature.hpp>
#include <hairlut/io/table_io.hpp>
#include <hairlut/report/validate_engine.hpp>
#include <numbers>
#include <unistd.h>

#include "catch.hpp"

using namespace hairlut;
namespace fs = std::filesystem;

namespace {

constexpr double pi = std::numbers::pi;

// ---- the ported formulas ------------------------------------------------------------------------

double sq(double x) { return x * x; }

// [RC] 209-210, [C] 226-227: cos θ = SafeSqrt(1 − (sin²θ + 1e−5)).
double cos_guarded(double s) { return std::sqrt(std::max(0.0, 1.0 - s * s - 1e-5)); }

// [RC] 118-123: v_R = (0.726β + 0.812β² + 3.7β²⁰)², v_TT = v_R/4, v_TRT = v_residual = 4v_R.
double variance(double beta, int p) {
  const double v = sq(0.726 * beta + 0.812 * sq(beta) + 3.7 * std::pow(beta, 20));
  return p == 0 ? v : p == 1 ? v / 4 : 4 * v;
}

// [RC] 127-130 (4 SQRT_PI_OVER_8): s = √(π/8)(0.265β + 1.194β² + 5.372β²²).
double scale_of(double beta) { return std::sqrt(pi / 8) * (0.265 * beta + 1.194 * sq(beta) + 5.372 * std::pow(beta, 22)); }

// [RC] 83-95: ten terms of I0's series, here by the term ratio (x²/4)/i².
double i0_ten_terms(double x) {
  double term = 1.0, sum = 1.0;
  for (int i = 1; i < 10; ++i) sum += (term *= x * x / 4 / (i * i));
  return sum;
}

// [RC] 97-113: ln I0 with its own large-argument form past 12.
double ln_i0(double x) { return x > 12 ? x - 0.5 * std::log(2 * pi) - 0.5 * std::log(x) + 1 / (16 * x) : std::log(i0_ten_terms(x)); }

// [R] 65-84: M(θi, θo; v), two branches at v = 0.1.
double M_hdrp(double ci, double co, double si, double so, double v) {
  const double a = ci * co / v, b = si * so / v;
  if (v < 0.1) return std::exp(ln_i0(a) - b - 1 / v + 0.6931 - std::log(2 * v));
  return std::exp(-b) * i0_ten_terms(a) / (2 * v * std::sinh(1 / v));
}

// [RC] 132-157 with 159-170 (the double-angle identities give sin/cos of 2α and 4α): θo turned by
// −2α (R), +α (TT), +4α (TRT), none (residual); the cosine taken absolute.
void turn(int p, double so, double co, double alpha, double& s, double& c) {
  const double k = p == 0 ? -2 : p == 1 ? 1 : p == 2 ? 4 : 0;
  s = so * std::cos(k * alpha) + co * std::sin(k * alpha);
  c = std::abs(co * std::cos(k * alpha) - so * std::sin(k * alpha));
}

// [RC] 51-54: Φ = 2pγt − 2γo + pπ.
double Phi(int p, double go, double gt) { return 2 * p * gt - 2 * go + p * pi; }

// [RC] 56-72 with [R] 86-95: the logistic on [−π, π] of the wrapped difference.
double TL(double x, double s) {
  x = std::remainder(x, 2 * pi);
  const double e = std::exp(-std::abs(x) / s);
  const double mass = 1 / (1 + std::exp(-pi / s)) - 1 / (1 + std::exp(pi / s));
  return e / (s * sq(1 + e)) / mass;
}

// ---- helpers --------------------------------------------------------------------------------------

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hairlut-hdrp-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

struct Baked {
  TableSet set;
  EngineOutput out;
  EngineImage img;
};

Baked bake_texture(const std::string& texture, const fs::path& dir) {
  BakeConfig c = load_config(fs::path(HAIRLUT_SOURCE_DIR) / "tables" / "configs" / "unity-hdrp-hair.json");
  c.output.directory = dir;
  c.engine->textures = {texture};
  BakeReport report;
  TableSet set = bake(c, {}, &report);
  write_outputs(set, c, report);
  const auto outs = engine_outputs(c);
  REQUIRE(outs.size() == 1);
  return {std::move(set), outs[0], read_engine_texture(outs[0].path)};
}

// Half of the spacing of half floats at |v| (subnormals: 2^-24).
double half_ulp(double v) {
  const double a = std::abs(v);
  if (a < std::ldexp(1.0, -14)) return std::ldexp(1.0, -25);
  return std::ldexp(1.0, std::ilogb(a) - 11);
}

double u_of(int i) { return (i + 0.5) / 64; }  // [C] 79, 176, 216: UVW = (id + 0.5) / DIM

struct Tally {
  long bad = 0, count = 0;
  double worst = 0;  // in units of the allowance
  void check(double texel, double ref, double eps) {
    // The writer rounds double → float → half: besides half's ½ ulp, float's 2^-24 relative.
    const double allowed = half_ulp(ref) + (eps + std::ldexp(1.0, -24)) * std::abs(ref) + 1e-300;
    const double r = std::abs(texel - ref) / allowed;
    worst = std::max(worst, r);
    ++count;
    if (r > 1) ++bad;
  }
};

}  // namespace

TEST_CASE("HDRP longitudinal texture: every texel is ComputeLongitudinalScattering's value", "[hdrp][presets]") {
  const fs::path dir = temp_dir("long");
  const Baked b = bake_texture("longitudinal", dir);
  CHECK(b.img.width == 512);
  CHECK(b.img.height == 512);
  CHECK(b.img.channel_count == 4);
  const double alpha = 3 * pi / 180;  // [C] 236: radians(3)
  // No integral here: the only differences are the rounding to half and double rounding (< 1e-9
  // relative: exp of differences of terms up to 1/v ≈ 2e5).
  Tally t;
  double worst_table = 0;
  for (int z = 0; z < 64; ++z)
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) {
        const double si = -1 + 2 * u_of(x), so = -1 + 2 * u_of(y);  // [C] 224-225
        const double ci = cos_guarded(si), co = cos_guarded(so);
        for (int p = 0; p < 3; ++p) {
          double s, c;
          turn(p, so, co, alpha, s, c);
          const double ref = M_hdrp(ci, c, si, s, variance(u_of(z), p));  // [C] 250
          t.check(b.img.texel(b.out.texture, 64, 64, x, y, z, p), ref, 1e-9);
          const Table* tb = b.set.find("unity/longitudinal/M_" + std::string(p == 0 ? "R" : p == 1 ? "TT" : "TRT"));
          const double v = tb->get((static_cast<std::size_t>(z) * 64 + static_cast<std::size_t>(y)) * 64 + static_cast<std::size_t>(x));
          if (ref > 1e-30) worst_table = std::max(worst_table, std::abs(v - ref) / ref);
        }
        t.check(b.img.texel(b.out.texture, 64, 64, x, y, z, 3), 1.0, 0.0);  // [C] 253: alpha 1
      }
  WARN("longitudinal: table (float32) against the reference: max relative difference " << worst_table);
  CHECK(worst_table < 1e-7);
  WARN("longitudinal: " << t.count << " texels, worst |texel - ref| / allowance " << t.worst);
  CHECK(t.bad == 0);
  // A worked example: roughness 0.10 (nearest texel z = 6, beta = 0.1016), sin θi = sin 31° (x = 48):
  // HDRP's R peak is near θo = −25°, not at −37.5°.
  int best = 0;
  for (int y = 1; y < 64; ++y)
    if (b.img.texel(b.out.texture, 64, 64, 48, y, 6, 0) > b.img.texel(b.out.texture, 64, 64, 48, best, 6, 0)) best = y;
  const double peak_deg = std::asin(-1 + 2 * u_of(best)) * 180 / pi;
  WARN("R peak at theta_o = " << peak_deg << " deg for sin theta_i = " << (-1 + 2 * u_of(48)));
  CHECK(std::abs(peak_deg - (-25.0)) < 3.0);
  fs::remove_all(dir);
}

TEST_CASE("HDRP azimuthal texture: every texel is ComputeAzimuthalScattering's integral over h", "[hdrp][presets]") {
  const fs::path dir = temp_dir("azi");
  const Baked b = bake_texture("azimuthal", dir);
  CHECK(b.img.width == 512);
  CHECK(b.img.channel_count == 4);
  // Reference: N = ½ ∫_{−1}^{1} TL(φ − Φ) dh ([C] 186-201) = ½ ∫ TL(φ − Φ(γ)) cos γ dγ (h = sin γ), by
  // 8-point Gauss–Legendre on equal panels of width ≤ min(π/32, s/3), each panel that contains a kink
  // of the wrapped logistic (φ − Φ ≡ π mod 2π) split there. The logistic's poles lie iπs/|Φ'| ≥ 0.5s
  // off the real axis, three half-panel widths away, so each panel's error is below 6^-16 ≈ 4e-13
  // relative; the test checks this bound on a sample by halving the panels.
  const GaussLegendreRule gl(8);
  // The reference at every φ of a list for one (p, cos θd, β): the phases at the nodes are shared.
  auto reference = [&](int p, const std::vector<double>& phis, double c, double beta, int refine) {
    const double eta = 1.19 / c + 0.36 * c;  // [H] ModifiedRefractionIndex, [C] 180
    const double s = scale_of(beta);         // [C] 181
    auto phase = [&](double g) {             // [C] 188-189 (exact asin for FastASin)
      return Phi(p, g, std::clamp(std::asin(std::sin(g) / eta), -1.0, 1.0));
    };
    const int panels = refine * static_cast<int>(std::ceil(pi / std::min(pi / 32, s / 3)));
    const std::size_t n = static_cast<std::size_t>(gl.order());
    std::vector<double> node_phase(static_cast<std::size_t>(panels) * n), node_weight(node_phase.size()), end_phase(static_cast<std::size_t>(panels) + 1);
    for (int k = 0; k <= panels; ++k) end_phase[static_cast<std::size_t>(k)] = phase(-pi / 2 + pi * k / panels);
    for (int k = 0; k < panels; ++k)
      for (std::size_t i = 0; i < n; ++i) {
        const double hw = pi / (2 * panels), g = -pi / 2 + pi * (k + 0.5) / panels + hw * gl.nodes()[i];
        node_phase[static_cast<std::size_t>(k) * n + i] = phase(g);
        node_weight[static_cast<std::size_t>(k) * n + i] = hw * gl.weights()[i] * 0.5 * std::cos(g);
      }
    std::vector<double> out;
    for (double phi : phis) {
      auto f = [&](double g) { return 0.5 * TL(phi - phase(g), s) * std::cos(g); };
      double sum = 0;
      for (int k = 0; k < panels; ++k) {
        // Odd multiples of π between the ends: a kink (a panel spans less than 2π of phase).
        const double da = phi - end_phase[static_cast<std::size_t>(k)], db = phi - end_phase[static_cast<std::size_t>(k) + 1];
        const double ka = std::floor((da + pi) / (2 * pi)), kb = std::floor((db + pi) / (2 * pi));
        if (ka != kb) {
          const double a = -pi / 2 + pi * k / panels, bb = -pi / 2 + pi * (k + 1) / panels;
          const double target = pi + 2 * pi * std::min(ka, kb);
          double lo = a, hi = bb;
          for (int i = 0; i < 100; ++i) {
            const double m = 0.5 * (lo + hi);
            ((phi - phase(m) < target) == (da < target) ? lo : hi) = m;
          }
          sum += gl.integrate(f, a, lo) + gl.integrate(f, lo, bb);
        } else {
          for (std::size_t i = 0; i < n; ++i)
            sum += node_weight[static_cast<std::size_t>(k) * n + i] * TL(phi - node_phase[static_cast<std::size_t>(k) * n + i], s);
        }
      }
      out.push_back(sum);
    }
    return out;
  };
  // The reference's own error, by halving its panels at a few texels of each roughness.
  double worst_self = 0;
  const std::vector<double> probe = {4 * pi * u_of(37) - 2 * pi};
  for (int z : {0, 1, 8, 40, 63})
    for (int p = 0; p < 3; ++p) {
      const double r1 = reference(p, probe, u_of(50), u_of(z), 1)[0], r2 = reference(p, probe, u_of(50), u_of(z), 2)[0];
      worst_self = std::max(worst_self, std::abs(r1 - r2) / std::max(std::abs(r2), 1e-300));
    }
  WARN("azimuthal reference: relative change on halving the panels " << worst_self);
  CHECK(worst_self < 1e-9);
  // Every texel. N(−φ) = N(φ) (Φ(−γ) = 2pπ − Φ(γ)), so texels x and 63 − x share one reference value.
  std::vector<double> phis;
  for (int x = 32; x < 64; ++x) phis.push_back(4 * pi * u_of(x) - 2 * pi);  // [C] 179
  Tally t;
  double worst_table = 0;
  for (int y = 0; y < 64; ++y)
    for (int z = 0; z < 64; ++z)
      for (int p = 0; p < 3; ++p) {
        const auto ref = reference(p, phis, u_of(y), u_of(z), 1);
        const Table* tb = b.set.find("unity/azimuthal/N_" + std::string(p == 0 ? "R" : p == 1 ? "TT" : "TRT"));
        for (int x = 32; x < 64; ++x) {
          const double r = ref[static_cast<std::size_t>(x - 32)];
          t.check(b.img.texel(b.out.texture, 64, 64, x, y, z, p), r, 1e-8);
          t.check(b.img.texel(b.out.texture, 64, 64, 63 - x, y, z, p), r, 1e-8);
          if (r > 1e-6) worst_table = std::max(worst_table, std::abs(tb->get((static_cast<std::size_t>(z) * 64 + static_cast<std::size_t>(y)) * 64 + static_cast<std::size_t>(x)) - r) / r);
          if (p == 0) t.check(b.img.texel(b.out.texture, 64, 64, x, y, z, 3), 1.0, 0.0);  // [C] 201: alpha 1
        }
      }
  WARN("azimuthal: table (float32) against the reference where N > 1e-6: max relative difference " << worst_table);
  CHECK(worst_table < 1e-7);
  WARN("azimuthal: " << t.count << " texels, worst |texel - ref| / allowance " << t.worst);
  CHECK(t.bad == 0);
  fs::remove_all(dir);
}

namespace {

// The attenuation kernel [C] 76-160 at one texel, in the separated form (see hdrp_kernels.hpp):
// (1/π) Σ_p L_p · Q_p, computed here with fixed rules and a Fourier series for the azimuthal weight.
struct AttenuationReference {
  double s = scale_of(1.0 - 0.7);  // [C] 51 perceptualRadialSmoothness 0.7 → [H] radial roughness 0.3 → [RC] 184
  std::vector<double> tk;           // T_k = ∫_{−π}^{π} cos(kΔ) TL(Δ) dΔ, k = 0..K
  GaussLegendreRule gl8{8}, gl64{64};
  AttenuationReference() {
    const GaussLegendreRule g(64);
    for (int k = 0; k <= 200; ++k) {
      double sum = 0;
      for (int j = 0; j < 64; ++j) {  // 64 panels on [−π, π]
        const double a = -pi + 2 * pi * j / 64, b = a + 2 * pi / 64;
        sum += g.integrate([&](double d) { return std::cos(k * d) * TL(d, s); }, a, b);
      }
      tk.push_back(sum);
    }
  }
  // ∫_{−π}^{π} (π − |Δ|) TL(Δ − c) dΔ by the Fourier series of the triangle wave π/2 + Σ_{k odd} 4/(πk²) cos kΔ.
  double back(double c) const {
    double sum = pi / 2;
    for (int k = 1; k < static_cast<int>(tk.size()); k += 2) sum += 4 / (pi * k * k) * std::cos(k * c) * tk[static_cast<std::size_t>(k)];
    return sum;
  }
  static constexpr double alpha = 3 * pi / 180;  // [C] 54 cuticleAngle −3, negated by [H] ConvertSurfaceDataToBSDFData, [RC] 183
  // L_p = ∫ M_p cos θi dθi over the sphere = ∫_{−1}^{1} M_p d(sin θi) at (smoothness, sin θo): 8-point
  // Gauss–Legendre on panels of width ≤ min(1/16, √v cos θo'/4) (the lobe's width in sin θi is about √v cos θo'),
  // split where [RC] 102 changes formula (a = 12) and where the guarded cosine reaches 0.
  std::array<double, 4> L(double sm, double so) const {
    const double beta = 1 - std::min(sm, 0.99);  // [H] PerceptualSmoothnessToPerceptualRoughness(min(s, 1 − 1e−2)), [RC] 181
    const double co = cos_guarded(so);
    std::array<double, 4> out{};
    for (int p = 0; p < 4; ++p) {
      const double v = variance(beta, p);
      double s2, c2;
      turn(p, so, co, alpha, s2, c2);
      std::vector<double> cuts = {-1, -std::sqrt(1 - 1e-5), std::sqrt(1 - 1e-5), 1};
      if (v < 0.1 && 12 * v < c2) {
        const double ci = 12 * v / c2;
        if (1 - 1e-5 - ci * ci > 0) cuts.push_back(std::sqrt(1 - 1e-5 - ci * ci)), cuts.push_back(-std::sqrt(1 - 1e-5 - ci * ci));
      }
      std::sort(cuts.begin(), cuts.end());
      const double width = std::min(1.0 / 16, std::sqrt(v) * std::max(c2, 0.01) / 4);
      double sum = 0;
      for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
        const int n = std::max(1, static_cast<int>(std::ceil((cuts[i + 1] - cuts[i]) / width)));
        for (int k = 0; k < n; ++k) {
          const double a = cuts[i] + (cuts[i + 1] - cuts[i]) * k / n, e = cuts[i] + (cuts[i + 1] - cuts[i]) * (k + 1) / n;
          sum += gl8.integrate([&](double u) { return M_hdrp(cos_guarded(u), c2, u, s2, v); }, a, e);  // [R] 129, 134
        }
      }
      out[static_cast<std::size_t>(p)] = sum;
    }
    return out;
  }
  // Q at sin θo for every diffuse colour of the list: {½∫A_p dh (p = 0..3), ½∫A_p w_back(Φ_p) dh (p = 0..2)},
  // over γ = asin h with 4 × 64-point Gauss–Legendre (the integrand is analytic in γ).
  std::vector<std::array<double, 7>> Q(double so, const std::vector<double>& colours) const {
    const double F0 = sq((1.55 - 1) / (1.55 + 1));
    const double co = cos_guarded(so);
    const double cos_t = std::sqrt(1 - sq(so / 1.55));           // [R] 104-105
    const double eta_p = std::sqrt(1.55 * 1.55 - so * so) / co;  // [R] 108
    struct Node {
      double w, cgt, F, back[3];
    };
    std::vector<Node> nodes;
    for (int panel = 0; panel < 4; ++panel) {
      const double a = -pi / 2 + pi * panel / 4, half = pi / 8, mid = a + half;
      for (int i = 0; i < gl64.order(); ++i) {
        const double g = mid + half * gl64.nodes()[static_cast<std::size_t>(i)];
        const double h = std::sin(g);
        const double sgt = h / eta_p, gt = std::clamp(std::asin(sgt), -1.0, 1.0);  // [R] 111-113
        Node n{};
        n.w = half * gl64.weights()[static_cast<std::size_t>(i)] * 0.5 * std::cos(g);  // ½ dh = ½ cos γ dγ
        n.cgt = std::sqrt(1 - sgt * sgt);
        n.F = F0 + (1 - F0) * std::pow(1 - co * std::cos(g), 5);  // [R] 13-17 (F_Schlick)
        for (int p = 0; p < 3; ++p) n.back[p] = back(Phi(p, g, gt));  // [R] 130 with the Δ weights
        nodes.push_back(n);
      }
    }
    std::vector<std::array<double, 7>> out;
    const double b = 0.3;  // [H] radial roughness
    const double D = 5.969 - 0.215 * b + 2.532 * b * b - 10.73 * b * b * b + 5.574 * std::pow(b, 4) + 0.245 * std::pow(b, 5);
    for (double d : colours) {
      const double sigma = std::max(sq(std::log(std::max(d, 1e-3)) / D), 1e-5);  // [H] AbsorptionFromReflectance, [RC] 187
      std::array<double, 7> q{};
      for (const Node& n : nodes) {
        const double T = std::exp(-sigma * 2 * n.cgt / cos_t);  // [R] 116
        const double F = n.F;
        const double A[4] = {F, sq(1 - F) * T, sq(1 - F) * T * T * F, sq(1 - F) * T * T * F * F * T / (1 - T * F)};  // [R] 20-31
        for (int p = 0; p < 4; ++p) q[static_cast<std::size_t>(p)] += n.w * A[p];
        for (int p = 0; p < 3; ++p) q[static_cast<std::size_t>(4 + p)] += n.w * A[p] * n.back[p];
      }
      out.push_back(q);
    }
    return out;
  }
  // Light azimuth φo ∈ [0, π) ([C] 126) and view azimuth φi over the half circle ([C] 110-123): for
  // the back half (wi.z ≥ 0) Δ = φi − φo has weight π − |Δ|, for the front half |Δ|; the residual
  // ([R] 134) is uniform in Δ, π²/2π = π/2 for either. Luminance of a grey value ([C] 142) is the sum
  // of Color.hlsl's weights 0.2126729 + 0.7151522 + 0.0721750; [C] 147 divides by π.
  static std::array<double, 2> combine(const std::array<double, 4>& L, const std::array<double, 7>& q) {
    const double lum = 0.2126729 + 0.7151522 + 0.0721750;
    double front = L[3] * q[3] * pi / 2, backv = front;
    for (std::size_t p = 0; p < 3; ++p) front += L[p] * (pi * q[p] - q[4 + p]), backv += L[p] * q[4 + p];
    return {lum * front / pi, lum * backv / pi};
  }
};

}  // namespace

TEST_CASE("HDRP attenuation texture: every texel is ComputeAttenuationForward/Backward's integral", "[hdrp][presets]") {
  const fs::path dir = temp_dir("att");
  const Baked b = bake_texture("attenuation", dir);
  CHECK(b.img.width == 512);
  CHECK(b.img.height == 512);
  CHECK(b.img.channel_count == 2);  // R16G16_SFloat: .x front, .y back
  const AttenuationReference ref;
  std::vector<double> colours;
  for (int z = 0; z < 64; ++z) colours.push_back(u_of(z));  // [C] 82: Z diffuse colour
  Tally t;
  double worst_table = 0;
  std::array<int, 3> worst_at{};
  const Table* front = b.set.find("unity/attenuation/front");
  const Table* backt = b.set.find("unity/attenuation/back");
  REQUIRE(front);
  REQUIRE(backt);
  for (int y = 0; y < 64; ++y) {
    const auto q = ref.Q(u_of(y), colours);  // [C] 96: Y sin θ
    for (int x = 0; x < 64; ++x) {
      const auto L = ref.L(u_of(x), u_of(y));  // [C] 82: X smoothness
      for (int z = 0; z < 64; ++z) {
        const auto r = AttenuationReference::combine(L, q[static_cast<std::size_t>(z)]);
        t.check(b.img.texel(b.out.texture, 64, 64, x, y, z, 0), r[0], 1e-7);
        t.check(b.img.texel(b.out.texture, 64, 64, x, y, z, 1), r[1], 1e-7);
        const std::size_t i = (static_cast<std::size_t>(z) * 64 + static_cast<std::size_t>(y)) * 64 + static_cast<std::size_t>(x);
        const double e = std::max(std::abs(front->get(i) - r[0]) / r[0], std::abs(backt->get(i) - r[1]) / r[1]);
        if (e > worst_table) worst_table = e, worst_at = {x, y, z};
      }
    }
  }
  // The tables (float32) against the reference: float's rounding and the two quadratures.
  WARN("attenuation: table (float32) against the reference: max relative difference " << worst_table << " at texel (" << worst_at[0]
                                                                                         << ", " << worst_at[1] << ", " << worst_at[2] << ")");
  CHECK(worst_table < 1e-7);
  WARN("attenuation: " << t.count << " texels, worst |texel - ref| / allowance " << t.worst);
  CHECK(t.bad == 0);
  fs::remove_all(dir);
}

TEST_CASE("validate-hair-luts checks an HDRP texture against its definition and finds one altered texel", "[hdrp][presets][validate]") {
  const fs::path dir = temp_dir("validate");
  Baked b = bake_texture("longitudinal", dir);
  CHECK(is_engine_texture(b.out.path));
  const auto good = validate_engine_texture(b.out.path);
  CHECK(good["summary"]["status"] == "pass");
  CHECK(good["summary"]["failed"] == 0);
  // One texel raised by 1% (far above the half rounding): the value check fails, the layout checks pass.
  Table* m = nullptr;
  for (Table& t : b.set.tables)
    if (t.path() == "unity/longitudinal/M_TT") m = &t;
  REQUIRE(m);
  const std::size_t i = (static_cast<std::size_t>(20) * 64 + 31) * 64 + 30;
  m->set(i, m->get(i) * 1.01);
  const fs::path bad = dir / "altered.exr";
  write_engine_texture(b.set, b.out.texture, bad);
  const auto r = validate_engine_texture(bad);
  CHECK(r["summary"]["status"] == "fail");
  std::string failed;
  for (const auto& c : r["checks"])
    if (c["status"] == "fail") failed += c["id"].get<std::string>() + " ";
  CHECK(failed == "engine_values ");
  // Not an engine texture: the generic route.
  CHECK_FALSE(is_engine_texture(dir / "hairlut.h5"));
  fs::remove_all(dir);
}

TEST_CASE("Variant unity-hdrp-hair-deon: HDRP's textures with exact functions conserve energy where HDRP's series does not",
          "[hdrp][presets][variant]") {
  const fs::path dir = temp_dir("deon");
  BakeConfig c = load_config(fs::path(HAIRLUT_SOURCE_DIR) / "tables" / "configs" / "unity-hdrp-hair-deon.json");
  c.output.directory = dir;
  c.engine->textures = {"longitudinal", "attenuation"};
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  write_outputs(set, c, report);
  const auto outs = engine_outputs(c);
  REQUIRE(outs.size() == 2);
  CHECK(outs[0].path.filename() == "hairlut-unity-deon-attenuation.exr");
  // Longitudinal: d'Eon's eq. 7 from the standard library's I0 at every texel where it does not
  // overflow (1/v, a < 700), against the table.
  const Table* mt = set.find("unity/longitudinal/M_TT");
  REQUIRE(mt);
  double worst = 0;
  long n = 0;
  const double alpha = 3 * pi / 180;
  for (int z = 0; z < 64; ++z)
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) {
        const double v = variance(u_of(z), 1), si = -1 + 2 * u_of(x), so = -1 + 2 * u_of(y);
        const double ci = std::sqrt(1 - si * si), co = std::sqrt(1 - so * so);
        double s, cc;
        turn(1, so, co, alpha, s, cc);
        const double a = ci * cc / v;
        if (1 / v > 700 || a > 700) continue;
        const double ref = std::exp(-si * s / v) * std::cyl_bessel_i(0.0, a) / (2 * v * std::sinh(1 / v));
        const double got = mt->get((static_cast<std::size_t>(z) * 64 + static_cast<std::size_t>(y)) * 64 + static_cast<std::size_t>(x));
        if (ref > 1e-6) worst = std::max(worst, std::abs(got - ref) / ref), ++n;
      }
  WARN("variant M_TT against std::cyl_bessel_i at " << n << " texels: max relative difference " << worst);
  CHECK(n > 10000);
  CHECK(worst < 1e-6);  // float32 storage (6e-8) and the library's I0 (relative ~1e-15)
  // Energy: ∫ M_p(θi, θo') cos θi dθi = 1 for d'Eon's M_p whatever θo'; HDRP's ten-term series and its
  // large-argument form lose it where cos θi cos θo / v reaches about 10 (here β = 0.5, TT: v = 0.08).
  const GaussLegendreRule g(64);
  auto energy = [&](hdrp::Functions f, double beta, double so) {
    double sum = 0;
    for (int k = 0; k < 256; ++k)
      sum += g.integrate([&](double u) { return hdrp::longitudinal_texel(u, so, beta, f)[1]; }, -1 + 2.0 * k / 256, -1 + 2.0 * (k + 1) / 256);
    return sum;
  };
  const double e_exact = energy(hdrp::Functions::exact, 0.5, 0.2), e_hdrp = energy(hdrp::Functions::hdrp, 0.5, 0.2);
  WARN("TT energy at beta 0.5, sin theta_o 0.2: exact functions " << e_exact << ", HDRP's " << e_hdrp);
  CHECK(std::abs(e_exact - 1) < 1e-9);
  CHECK(std::abs(e_hdrp - 1) > 1e-3);
  // Attenuation of a nearly white fiber (d = 63.5/64: σa = 1.9e-6): with exact functions front + back
  // is the luminance weight sum times ½∫ Σ_p A_p dh = 1 up to that absorption (|ΔE| < 1e-4).
  const Table* f = set.find("unity/attenuation/front");
  const Table* b = set.find("unity/attenuation/back");
  REQUIRE(f);
  REQUIRE(b);
  double worst_furnace = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const std::size_t i = (static_cast<std::size_t>(63) * 64 + static_cast<std::size_t>(y)) * 64 + static_cast<std::size_t>(x);
      worst_furnace = std::max(worst_furnace, std::abs(f->get(i) + b->get(i) - 1.0));
    }
  WARN("variant attenuation, white fiber: max |front + back - 1| " << worst_furnace);
  CHECK(worst_furnace < 1e-4);
  fs::remove_all(dir);
}
