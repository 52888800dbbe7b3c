// The GLSL runtime (lib/shaders/hairlut.glsl, hairlut_sampling.glsl) through Vulkan against the C++
// runtime: loads a per-material table set, lays its materials out as textures and sampling rows
// (lib/include/hairlut/sampler/gpu_textures.hpp, float32 and half), evaluates S, the pdf and samples at random
// points in compute shaders and compares them with HairScattering's eval, pdf and sample at the
// same (float) arguments.
//
// Checked (exit 1 when not met): float32 textures with the explicit filter, through the direction
// and the angle interface, agree at every point within the bound float arithmetic allows,
//   |S_gpu − S_cpp| ≤ K u (S + π Σ_x |∂S/∂x|),  u = 2⁻²⁴, K = 32, x ∈ {θo, θi, φ}:
// S is a sum of products of nonnegative bilinear interpolants (about 20 rounded operations per
// value, no cancellation: ≤ 20 u S), and each node coordinate comes from an angle through a few
// rounded operations and one sin, cos or atan (a few ulp each), so each argument is located
// to within about 8 u π [rad]; K = 32 leaves a factor of 1.5 to 4 on both. ∂S/∂x is the C++
// runtime's one-sided difference quotient (the larger side); plus K · 2⁻¹²⁶ for products a shader
// may flush below float's normal range. The same check must reject the reconstruction with θi
// located half a node off (the bound is tight enough to see a mapping bug). Likewise checked: the
// pdf at the same (wo, wi), and the pdf hairlut_sample returns against the C++ pdf at the direction
// it drew (pdf_tolerance below says how the bound extends to the pdf).
// The textures, blocks and rows also go through the files an engine loads (write_gpu_export,
// float32 and half, read back): checked to hold the same values as the layout built in memory.
// Measured and reported, not checked: half textures (storage rounding), the hardware bilinear
// filter of this device at texel centres (float32 and half), and explicit taps with weights rounded
// to 8 fractional bits (an emulation of common GPU filter units; lavapipe's own filter is the
// hardware row); and how far hairlut_sample's directions and weights fall from the C++ runtime's
// draws from the same u.
//
//   test-gpu-material --tables FILE.h5 --spirv DIR --out DIR [--points N] [--device NAME]
// Exit 0 pass, 1 a check failed, 2 bad input, 77 no Vulkan device (skipped).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "hairlut/io/gpu_export.hpp"
#include "hairlut/io/table_io.hpp"
#include "hairlut/tables/hair_views.hpp"
#include "hairlut/sampler/gpu_textures.hpp"
#include "vk_compute.hpp"

namespace {

using hairlut::sampler::HairScattering;
using hairlut::sampler::MaterialTables;
constexpr double kPi = 3.14159265358979323846;
constexpr double kU = 0x1p-24;
constexpr double kK = 32.0;
constexpr double kTiny = 0x1p-126;  // float's smallest normal: a shader may flush anything smaller to 0

// The points, as the shader reads them (two vec4 each), and the C++ runtime's S and bound there.
struct Points {
  std::vector<float> gpu;
  std::vector<double> s, tol;  // per point and channel
  std::size_t count() const { return gpu.size() / 8; }
};

double uniform(std::mt19937_64& g) { return static_cast<double>(g() >> 11) * 0x1p-53; }

// Σ_x |∂S/∂x| per channel at the angles (the C++ angle interface), x ∈ {θo, θi, φ}.
void slopes(const HairScattering<float>& rt, double to, double ti, double phi, double* slope) {
  const hairlut::sampler::Fiber f{};
  const double h = 1e-5;
  double s0[3];
  rt.eval(f, to, ti, phi, s0);
  for (int c = 0; c < 3; ++c) slope[c] = 0.0;
  for (int x = 0; x < 3; ++x) {
    double side_max[3] = {0.0, 0.0, 0.0};
    for (int side = -1; side <= 1; side += 2) {
      double a[3] = {to, ti, phi}, s1[3];
      a[x] += side * h;
      rt.eval(f, a[0], a[1], a[2], s1);
      for (int c = 0; c < 3; ++c) side_max[c] = std::max(side_max[c], std::fabs(s1[c] - s0[c]) / h);
    }
    for (int c = 0; c < 3; ++c) slope[c] += side_max[c];
  }
}

// A float direction as the double unit vector it points along: the shader reads a direction's
// inclination as atan2(w.x, |w.yz|), which does not depend on its length, and the C++ runtime takes
// unit vectors.
void unit(const float* w, double* out) {
  const double x = w[0], y = w[1], z = w[2], r = std::sqrt(x * x + y * y + z * z);
  out[0] = x / r, out[1] = y / r, out[2] = z / r;
}

// θo, θi and φ = φo − φi of float directions, in double (as the shader reads them).
void angles_of(const float* wo, const float* wi, double& to, double& ti, double& phi) {
  to = std::atan2(double(wo[0]), std::hypot(double(wo[1]), double(wo[2]))), ti = std::atan2(double(wi[0]), std::hypot(double(wi[1]), double(wi[2])));
  const double cr = double(wo[1]) * wi[2] - double(wo[2]) * wi[1], dt = double(wo[1]) * wi[1] + double(wo[2]) * wi[2];
  phi = std::atan2(std::fabs(cr), dt + 0.0);
}

Points make_points(const std::vector<HairScattering<float>>& rts, std::size_t n, bool angles) {
  std::mt19937_64 g(angles ? 20261206u : 1206u);
  Points p;
  const std::size_t materials = rts.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t mat = i % materials;
    float a[4], b[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    if (angles) {
      a[0] = static_cast<float>((uniform(g) - 0.5) * kPi), a[1] = static_cast<float>((uniform(g) - 0.5) * kPi);
      a[2] = static_cast<float>((uniform(g) - 0.5) * 4.0 * kPi);
      if (i % 8 == 7) {
        // Every eighth point at opposite grazing: θo and −θi within 1.5° of the same pole, where θd
        // nears 90° and the tables' grazing factors cos^n θd vary fastest.
        const double pole = uniform(g) < 0.5 ? -0.5 * kPi : 0.5 * kPi, band = 1.5 * kPi / 180.0;
        a[0] = static_cast<float>(pole - std::copysign(band * uniform(g), pole));
        a[1] = static_cast<float>(-pole + std::copysign(band * uniform(g), pole));
      }
    } else {
      // Uniform on the sphere, plus the frame's special pairs first: wi = wo, wi = −wo, along the fiber.
      double w[2][3];
      for (auto& v : w) {
        const double z = 2.0 * uniform(g) - 1.0, ph = 2.0 * kPi * uniform(g), r = std::sqrt(std::max(0.0, 1.0 - z * z));
        v[0] = z, v[1] = r * std::cos(ph), v[2] = r * std::sin(ph);
      }
      if (i % 8 == 7) {
        // As for the angles: every eighth pair at opposite grazing.
        const double pole = uniform(g) < 0.5 ? -1.0 : 1.0, band = 1.5 * kPi / 180.0;
        for (int k = 0; k < 2; ++k) {
          const double t = (0.5 * kPi - band * uniform(g)) * (k == 0 ? pole : -pole), c = std::cos(t), ph = std::atan2(w[k][2], w[k][1]);
          w[k][0] = std::sin(t), w[k][1] = c * std::cos(ph), w[k][2] = c * std::sin(ph);
        }
      }
      if (i < 2) w[1][0] = w[0][0], w[1][1] = w[0][1], w[1][2] = w[0][2];
      else if (i < 4) w[1][0] = -w[0][0], w[1][1] = -w[0][1], w[1][2] = -w[0][2];
      else if (i < 6) w[1][0] = 1.0, w[1][1] = w[1][2] = 0.0;
      for (int k = 0; k < 3; ++k) a[k] = static_cast<float>(w[0][k]), b[k] = static_cast<float>(w[1][k]);
    }
    a[3] = static_cast<float>(mat);
    p.gpu.insert(p.gpu.end(), a, a + 4);
    p.gpu.insert(p.gpu.end(), b, b + 4);
    // The C++ runtime at the floats the shader reads, read back from the buffer: when this loop
    // converted a[] and b[] to double in place, Debian's GCC 12.2 at -O3 (its SLP vectorizer) used
    // the doubles they were rounded from instead, so the reference was not at the shader's point.
    const float* q = &p.gpu[p.gpu.size() - 8];
    const hairlut::sampler::Fiber f{};
    double s[3], d[3] = {0.0, 0.0, 0.0};
    if (angles) {
      rts[mat].eval(f, q[0], q[1], q[2], s);
      slopes(rts[mat], q[0], q[1], q[2], d);
    } else {
      double wo[3], wi[3];
      unit(q, wo), unit(q + 4, wi);
      rts[mat].eval(f, wo, wi, s);
      double to, ti, phi;
      angles_of(q, q + 4, to, ti, phi);
      slopes(rts[mat], to, ti, phi, d);
    }
    for (int c = 0; c < 3; ++c) {
      p.s.push_back(s[c]);
      p.tol.push_back(kK * kU * (s[c] + kPi * d[c]) + kK * kTiny);
    }
  }
  return p;
}

struct Stats {
  double max_rel = 0.0, p99_rel = 0.0, median_rel = 0.0, max_over_bound = 0.0;
  double max_rel_floor = 0.0, p99_rel_floor = 0.0;  // over the values of S ≥ 10⁻⁴ of its largest (per channel)
  std::size_t over_bound = 0, values = 0, zero_mismatch = 0;
  double worst[4] = {0, 0, 0, 0};  // point, channel, gpu, cpp
};

double percentile(std::vector<double>& v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

// want, got and tol hold `channels` values per point; the floor metric is per channel.
Stats compare(const std::vector<double>& want_all, const std::vector<double>& got_all, const std::vector<double>& tol_all, std::size_t channels) {
  Stats st;
  std::vector<double> rel, rel_floor, peak(channels, 0.0);
  for (std::size_t i = 0; i < want_all.size(); ++i) peak[i % channels] = std::max(peak[i % channels], want_all[i]);
  for (std::size_t i = 0; i < want_all.size(); ++i) {
    const double want = want_all[i], got = got_all[i], err = std::fabs(got - want), tol = tol_all[i];
    ++st.values;
    if (!(err <= tol)) ++st.over_bound;
    const double ratio = tol > 0.0 ? err / tol : (err > 0.0 ? HUGE_VAL : 0.0);
    if (!(ratio <= st.max_over_bound)) {
      st.max_over_bound = ratio;
      st.worst[0] = static_cast<double>(i / channels), st.worst[1] = static_cast<double>(i % channels), st.worst[2] = got, st.worst[3] = want;
    }
    if (want > 0.0) rel.push_back(err / want);
    else if (got != 0.0) ++st.zero_mismatch;
    if (want >= 1e-4 * peak[i % channels] && want > 0.0) rel_floor.push_back(err / want);
  }
  st.max_rel = percentile(rel, 1.0), st.p99_rel = percentile(rel, 0.99), st.median_rel = percentile(rel, 0.5);
  st.max_rel_floor = percentile(rel_floor, 1.0), st.p99_rel_floor = percentile(rel_floor, 0.99);
  return st;
}

Stats compare(const Points& p, const std::vector<float>& out) {
  std::vector<double> got(p.s.size());
  for (std::size_t i = 0; i < got.size(); ++i) got[i] = out[i / 3 * 4 + i % 3];
  return compare(p.s, got, p.tol, 3);
}

// The pdf's bound: |pdf_gpu − pdf_cpp| ≤ K u (pdf · ‖q‖ / q + π Σ_x |∂pdf/∂x|). q(θi), step 1's
// density, is a quadratic A + B x + C x² per cell whose terms may cancel, so its rounding is
// relative to ‖q‖ = |A| + |B| x + |C| x² (blended as q is), not to q; the rest are products and
// quotients of nonnegative terms (S̄, S̄_φ, the row masses). Plus K u π pdf |q'| / q: the pdf is
// q(θi) / cos θi, both falling to 0 at a pole, and the shader takes cos θi from the direction's
// normal-plane part but q at θi as located (8 u π), so near a pole, where the pdf itself is flat,
// q's argument error is a relative error of q that ∂pdf/∂θi does not see.
struct MaterialSampling {
  hairlut::sampler::MaterialScattering<float> ms;
  hairlut::sampler::Axis theta_r;
  double theta_i_lo = 0.0;
};

double pdf_tolerance(const HairScattering<float>& rt, const MaterialSampling& m, double to, double ti, double phi, double pdf) {
  const auto rw = m.ms.rows();
  const int last = m.theta_r.count - 1, nc = rw.nq - 1;
  const double s = std::clamp((std::clamp(to, m.theta_r.lo, m.theta_r.hi) - m.theta_r.lo) * last / (m.theta_r.hi - m.theta_r.lo), 0.0, double(last));
  const int r = std::min(static_cast<int>(s), last - 1), k = std::min(static_cast<int>(std::clamp((ti - m.theta_i_lo) / rw.hq, 0.0, double(nc))), nc - 1);
  const double w = s - r, x = std::clamp((ti - m.theta_i_lo) / rw.hq, 0.0, double(nc)) - k;
  const double* g0 = rw.gq + (static_cast<std::size_t>(r) * static_cast<std::size_t>(nc) + static_cast<std::size_t>(k)) * 3;
  const double* g1 = g0 + 3 * nc;
  const double q = (1 - w) * (g0[0] + x * (g0[1] + x * g0[2])) + w * (g1[0] + x * (g1[1] + x * g1[2]));
  const double qa = (1 - w) * (std::fabs(g0[0]) + x * (std::fabs(g0[1]) + x * std::fabs(g0[2]))) +
                    w * (std::fabs(g1[0]) + x * (std::fabs(g1[1]) + x * std::fabs(g1[2])));
  const hairlut::sampler::Fiber f{};
  auto at = [&](double a, double b, double c) {
    const double wo[3] = {std::sin(a), std::cos(a), 0.0};
    return rt.at(f, wo).pdf(b, c);
  };
  const double h = 1e-5, p0 = at(to, ti, phi);
  double slope = 0.0;
  for (int v = 0; v < 3; ++v) {
    double side = 0.0;
    for (int sg = -1; sg <= 1; sg += 2) {
      double a[3] = {to, ti, phi};
      a[v] += sg * h;
      side = std::max(side, std::fabs(at(a[0], a[1], a[2]) - p0) / h);
    }
    slope += side;
  }
  const double dq = ((1 - w) * std::fabs(g0[1] + 2.0 * x * g0[2]) + w * std::fabs(g1[1] + 2.0 * x * g1[2])) / rw.hq;  // |dq/dθi|
  return kK * kU * (pdf * (q > 0.0 ? (qa + kPi * dq) / q : 1.0) + kPi * slope) + kK * kTiny;
}

}  // namespace

int main(int argc, char** argv) {
  const auto start = std::chrono::steady_clock::now();
  gpu_test::Args args;
  hairlut::TableSet set;
  std::vector<std::string> groups;
  std::vector<HairScattering<float>> rts;
  hairlut::gpu::MaterialTextures tex;
  std::map<std::string, std::vector<std::uint32_t>> spirv;
  std::vector<MaterialSampling> sampling;
  try {
    args = gpu_test::parse_args(argc, argv, 20000);
    for (const char* name : {"explicit", "hardware", "explicit-8bit", "explicit-builtin-trig"})
      spirv[name] = gpu_test::read_spirv(args.spirv + "/eval_material-" + name + ".spv");
    spirv["sample"] = gpu_test::read_spirv(args.spirv + "/sample_material-explicit.spv");
    set = hairlut::load_tables(args.tables);
    groups = hairlut::material_groups(set);
    if (groups.empty() || groups.size() > 4) throw std::runtime_error(args.tables + ": 1 to 4 materials needed (has " + std::to_string(groups.size()) + ")");
    for (const std::string& g : groups) {
      rts.push_back(hairlut::hair_scattering<float>(set, g));
      const MaterialTables<float> mt = hairlut::material_tables<float>(set, g);
      tex.add(mt);
      sampling.push_back({hairlut::sampler::MaterialScattering<float>(mt), mt.theta_r, mt.theta_i.lo});
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "test-gpu-material: error: %s\n", e.what());
    return 2;
  }
  try {
    // The textures as an engine gets them: exported to files (export-hair-luts), read back, and the
    // same values as the layout built in memory (half: the same values rounded as to_half rounds).
    std::filesystem::create_directories(args.out);
    const std::filesystem::path base = std::filesystem::path(args.out) / "export";
    hairlut::GpuExportOptions half_files;
    half_files.half = true;
    hairlut::write_gpu_export(set, base.string() + "-half", half_files);
    const hairlut::GpuLayout half_read = hairlut::read_gpu_export(base.string() + "-half.gpu.json");
    hairlut::write_gpu_export(set, base);
    const hairlut::GpuLayout read = hairlut::read_gpu_export(base.string() + ".gpu.json");
    const hairlut::gpu::MaterialTextures& r = read.textures;
    bool same = read.materials == groups && r.np == tex.np && r.mp == tex.mp && r.rows == tex.rows && r.materials.size() == tex.materials.size() &&
                std::memcmp(r.materials.data(), tex.materials.data(), tex.materials.size() * sizeof tex.materials[0]) == 0;
    for (std::size_t i = 0; same && i < tex.np.size(); ++i) same = half_read.textures.np[i] == hairlut::gpu::from_half(hairlut::gpu::to_half(tex.np[i]));
    for (std::size_t i = 0; same && i < tex.mp.size(); ++i) same = half_read.textures.mp[i] == hairlut::gpu::from_half(hairlut::gpu::to_half(tex.mp[i]));
    if (!same) {
      std::printf("FAIL: the exported textures, blocks or rows differ from the layout built in memory\n");
      return 1;
    }
    std::printf("textures, blocks and rows read back from %s.gpu.json (and the half export), identical to the layout built in memory\n", base.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "test-gpu-material: error: %s\n", e.what());
    return 1;
  }
  try {
    gpu_test::Vk vk(args.device);
    std::printf("device: %s (%s)%s\n", vk.device_name().c_str(), vk.driver_info().c_str(), vk.is_cpu() ? ", a CPU implementation" : "");
    const auto half_np = hairlut::gpu::to_half(tex.np), half_mp = hairlut::gpu::to_half(tex.mp);
    const VkFormat f32 = VK_FORMAT_R32G32B32A32_SFLOAT, f16 = VK_FORMAT_R16G16B16A16_SFLOAT;
    const gpu_test::Vk::Image np32 = vk.texture(f32, tex.np_width, tex.np_height, tex.np_layers, tex.np.data(), tex.np.size() * 4);
    const gpu_test::Vk::Image mp32 = vk.texture(f32, tex.mp_width, tex.mp_height, tex.mp_layers, tex.mp.data(), tex.mp.size() * 4);
    const gpu_test::Vk::Image np16 = vk.texture(f16, tex.np_width, tex.np_height, tex.np_layers, half_np.data(), half_np.size() * 2);
    const gpu_test::Vk::Image mp16 = vk.texture(f16, tex.mp_width, tex.mp_height, tex.mp_layers, half_mp.data(), half_mp.size() * 2);
    const VkSampler linear = vk.sampler(VK_FILTER_LINEAR);
    const bool f32_filter = vk.filters_linearly(f32);

    std::map<std::string, VkPipeline> pipelines;
    for (const auto& [name, words] : spirv) pipelines[name] = vk.pipeline(words);

    const Points dirs = make_points(rts, args.points, false), angs = make_points(rts, args.points, true);
    const std::size_t n = args.points;
    gpu_test::Vk::Buffer ubo = vk.buffer(4 * sizeof(hairlut::gpu::GpuMaterial), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    gpu_test::Vk::Buffer in = vk.buffer(n * 32, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    gpu_test::Vk::Buffer out = vk.buffer(n * 32, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    gpu_test::Vk::Buffer rows = vk.buffer(tex.rows.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memcpy(rows.map, tex.rows.data(), tex.rows.size() * 4);
    auto set_materials = [&](const std::vector<hairlut::gpu::GpuMaterial>& m) { std::memcpy(ubo.map, m.data(), m.size() * sizeof m[0]); };

    struct Run {
      std::string name, filter, texture, interface;
      bool checked;
      Stats st;
      const Points* points = nullptr;  // whose point i is the runs' point i (none for the sampled directions)
    };
    std::vector<Run> runs;
    auto run = [&](const std::string& name, const std::string& filter, bool half, bool angles, bool checked) {
      const Points& p = angles ? angs : dirs;
      std::memcpy(in.map, p.gpu.data(), p.gpu.size() * 4);
      vk.run(pipelines.at(filter), half ? np16 : np32, half ? mp16 : mp32, linear, ubo, in, out, rows, static_cast<std::uint32_t>(n), angles ? 1u : 0u);
      std::vector<float> values(n * 4);
      std::memcpy(values.data(), out.map, values.size() * 4);
      runs.push_back({name, filter, half ? "half" : "float32", angles ? "angles" : "directions", checked, compare(p, values), &p});
      return runs.back().st;
    };
    set_materials(tex.materials);
    run("float32, explicit filter", "explicit", false, false, true);
    run("float32, explicit filter, angle interface", "explicit", false, true, true);
    run("half, explicit filter (storage)", "explicit", true, false, false);
    if (f32_filter) run("float32, hardware filter", "hardware", false, false, false);
    run("half, hardware filter", "hardware", true, false, false);
    run("float32, 8-bit weights (emulated)", "explicit-8bit", false, false, false);
    run("float32, explicit filter, GLSL's atan", "explicit-builtin-trig", false, false, false);
    // The bound must see a mapping error: θi located half a node off.
    std::vector<hairlut::gpu::GpuMaterial> shifted = tex.materials;
    for (auto& m : shifted) m.theta_i[0] -= 0.5f / m.theta_i[1];
    set_materials(shifted);
    const Stats wrong = run("float32, explicit filter, theta_i half a node off (must fail the bound)", "explicit", false, false, false);
    set_materials(tex.materials);

    // hairlut_pdf at the same (wo, wi) as the C++ runtime's pdf, then hairlut_sample: its pdf
    // against the C++ pdf at the direction it drew, and its direction against the C++ runtime's
    // draw from the same u (reported: float prefix masses may pick a neighbouring cell).
    const hairlut::sampler::Fiber fiber{};
    std::memcpy(in.map, dirs.gpu.data(), dirs.gpu.size() * 4);
    vk.run(pipelines.at("sample"), np32, mp32, linear, ubo, in, out, rows, static_cast<std::uint32_t>(n), 0u);
    std::vector<float> res(n * 8);
    std::memcpy(res.data(), out.map, res.size() * 4);
    std::vector<double> want, got, tol;
    for (std::size_t i = 0; i < n; ++i) {
      const float* p = &dirs.gpu[i * 8];
      const std::size_t mat = static_cast<std::size_t>(p[3]);
      double wo[3], wi[3];
      unit(p, wo), unit(p + 4, wi);
      double to, ti, phi;
      angles_of(p, p + 4, to, ti, phi);
      want.push_back(rts[mat].pdf(fiber, wo, wi)), got.push_back(res[i * 8]);
      tol.push_back(pdf_tolerance(rts[mat], sampling[mat], to, ti, phi, want.back()));
    }
    runs.push_back({"pdf, float32, explicit filter", "explicit", "float32", "directions", true, compare(want, got, tol, 1), &dirs});
    std::vector<float> us(n * 8, 0.0f);
    std::mt19937_64 gu(77);
    for (std::size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 4; ++k) us[i * 8 + static_cast<std::size_t>(k)] = dirs.gpu[i * 8 + static_cast<std::size_t>(k)];
      for (std::size_t k = 4; k < 7; ++k) us[i * 8 + k] = static_cast<float>(uniform(gu));
    }
    std::memcpy(in.map, us.data(), us.size() * 4);
    vk.run(pipelines.at("sample"), np32, mp32, linear, ubo, in, out, rows, static_cast<std::uint32_t>(n), 1u);
    std::memcpy(res.data(), out.map, res.size() * 4);
    want.clear(), got.clear(), tol.clear();
    std::vector<double> angle, weight_rel;
    std::size_t drawn_mismatch = 0, lobe_same = 0, drawn = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const float* p = &us[i * 8];
      const float* r = &res[i * 8];
      const std::size_t mat = static_cast<std::size_t>(p[3]);
      const double u[3] = {p[4], p[5], p[6]};
      double wo[3], wi[3];
      unit(p, wo), unit(r, wi);
      const auto sp = rts[mat].at(fiber, wo);
      const hairlut::sampler::ScatteringSample cs = sp.sample(u);
      if ((r[3] > 0.0f) != (cs.pdf > 0.0)) ++drawn_mismatch;
      if (!(r[3] > 0.0f)) continue;
      ++drawn;
      double to, ti, phi;
      angles_of(p, r, to, ti, phi);
      want.push_back(sp.pdf(wi)), got.push_back(r[3]), tol.push_back(pdf_tolerance(rts[mat], sampling[mat], to, ti, phi, want.back()));
      if (cs.pdf > 0.0) {
        const double d[3] = {wi[0] - cs.wi[0], wi[1] - cs.wi[1], wi[2] - cs.wi[2]};
        angle.push_back(2.0 * std::asin(std::min(1.0, 0.5 * std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]))));
        lobe_same += static_cast<int>(r[7]) == cs.lobe ? 1 : 0;
      }
      double rgb[3];
      sp.eval(wi, rgb);
      for (int c = 0; c < 3; ++c)
        if (rgb[c] > 0.0) weight_rel.push_back(std::fabs(r[4 + c] - rgb[c] / want.back()) / (rgb[c] / want.back()));
    }
    runs.push_back({"sample's pdf against the C++ pdf at its direction, float32, explicit filter", "explicit", "float32", "directions", true,
                    compare(want, got, tol, 1)});
    const double angle_p50 = percentile(angle, 0.5), angle_p99 = percentile(angle, 0.99), angle_max = percentile(angle, 1.0);
    const double weight_p99 = percentile(weight_rel, 0.99), weight_max = percentile(weight_rel, 1.0);
    const std::size_t far = static_cast<std::size_t>(std::count_if(angle.begin(), angle.end(), [](double a) { return a > 1e-3; }));
    char sampled[600];
    std::snprintf(sampled, sizeof sampled,
                  "hairlut_sample against HairScattering's sample at the same u (%zu draws): angle between the directions median %.2e, p99 %.2e, "
                  "max %.2e rad, %zu beyond 1e-3 rad; same lobe %zu; drawn by one and not the other %zu; weight S / pdf against the C++ S / pdf "
                  "at the drawn direction p99 %.2e, max %.2e relative\n",
                  drawn, angle_p50, angle_p99, angle_max, far, lobe_same, drawn_mismatch, weight_p99, weight_max);

    bool ok = true;
    std::vector<std::string> failures;
    for (const Run& r : runs)
      if (r.checked && r.st.over_bound > 0) {
        ok = false;
        char line[640];
        int len = std::snprintf(line, sizeof line, "%s: %zu of %zu values beyond the float32 bound (worst: point %.0f channel %.0f, GPU %.9g, C++ %.9g, %.3g x the bound",
                                r.name.c_str(), r.st.over_bound, r.st.values, r.st.worst[0], r.st.worst[1], r.st.worst[2], r.st.worst[3], r.st.max_over_bound);
        if (r.points && static_cast<std::size_t>(r.st.worst[0]) < r.points->count()) {
          // The point as the shader read it, exactly (hexadecimal floats).
          const float* q = &r.points->gpu[8 * static_cast<std::size_t>(r.st.worst[0])];
          len += std::snprintf(line + len, sizeof line - static_cast<std::size_t>(len), "; point %a %a %a, %a %a %a", double(q[0]), double(q[1]), double(q[2]),
                               double(q[4]), double(q[5]), double(q[6]));
        }
        std::snprintf(line + len, sizeof line - static_cast<std::size_t>(len), ")");
        failures.push_back(line);
      }
    if (wrong.over_bound == 0) {
      ok = false;
      failures.push_back("the bound did not reject theta_i located half a node off");
    }

    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nlohmann::ordered_json j;
    j["device"] = vk.device_name(), j["driver"] = vk.driver_info(), j["tables"] = std::filesystem::path(args.tables).filename().string();
    j["materials"] = groups, j["points"] = n, j["seconds"] = seconds;
    j["bound"] = "|S_gpu - S_cpp| <= 32 u (S + pi sum_x |dS/dx|), u = 2^-24";
    j["float32_filter_linear"] = f32_filter;
    std::string md =
        "| run | texture | filter | interface | max rel | p99 rel | median rel | max rel, S ≥ 1e-4 max | p99 rel, S ≥ 1e-4 max | max err / bound | beyond bound |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Run& r : runs) {
      j["runs"].push_back({{"name", r.name}, {"texture", r.texture}, {"filter", r.filter}, {"interface", r.interface}, {"checked", r.checked},
                           {"max_rel", r.st.max_rel}, {"p99_rel", r.st.p99_rel}, {"median_rel", r.st.median_rel},
                           {"max_rel_above_1e-4_peak", r.st.max_rel_floor}, {"p99_rel_above_1e-4_peak", r.st.p99_rel_floor},
                           {"max_over_bound", r.st.max_over_bound}, {"over_bound", r.st.over_bound}, {"values", r.st.values},
                           {"zero_mismatch", r.st.zero_mismatch}});
      char row[512];
      std::snprintf(row, sizeof row, "| %s%s | %s | %s | %s | %.2e | %.2e | %.2e | %.2e | %.2e | %.3g | %zu of %zu |\n", r.name.c_str(),
                    r.checked ? " (checked)" : "", r.texture.c_str(), r.filter.c_str(), r.interface.c_str(), r.st.max_rel, r.st.p99_rel, r.st.median_rel,
                    r.st.max_rel_floor, r.st.p99_rel_floor, r.st.max_over_bound, r.st.over_bound, r.st.values);
      md += row;
    }
    j["failures"] = failures, j["pass"] = ok;
    std::filesystem::create_directories(args.out);
    char head[512];
    std::snprintf(head, sizeof head, "GLSL runtime on %s, %zu points per run over %zu materials of %s, %.1f s; relative error of S per channel (of the pdf in the pdf rows) against the C++ runtime:\n\n",
                  vk.device_name().c_str(), n, groups.size(), j["tables"].get<std::string>().c_str(), seconds);
    j["sampling"] = {{"draws", drawn}, {"angle_median", angle_p50}, {"angle_p99", angle_p99}, {"angle_max", angle_max}, {"beyond_1e-3_rad", far},
                     {"same_lobe", lobe_same}, {"drawn_mismatch", drawn_mismatch}, {"weight_p99_rel", weight_p99}, {"weight_max_rel", weight_max}};
    std::ofstream(std::filesystem::path(args.out) / "gpu-material.json") << j.dump(2) << "\n";
    std::ofstream(std::filesystem::path(args.out) / "gpu-material.md") << head << md << "\n" << sampled;
    std::printf("%s%s\n%s", head, md.c_str(), sampled);
    for (const std::string& f : failures) std::printf("FAIL: %s\n", f.c_str());
    std::printf(ok ? "gpu material ok\n" : "gpu material FAILED\n");
    return ok ? 0 : 1;
  } catch (const gpu_test::Unavailable& e) {
    std::printf("SKIP: %s\n", e.what());
    return 77;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "test-gpu-material: error: %s\n", e.what());
    return 1;
  }
}
