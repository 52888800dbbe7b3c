// The GLSL runtime for generic tables (lib/shaders/hairlut_generic.glsl) through Vulkan against the
// C++ runtime: loads a generic d'Eon set (the shipped default tables), lays it out as buffers
// (lib/include/hairlut/sampler/gpu_buffers.hpp), evaluates S in a compute shader at random fibers and
// directions, and compares with HairScattering<float>::eval (double arithmetic over the same float
// tables) at the same float arguments.
//
// Checked (exit 1 when not met), per point and channel, through the angle and the direction
// interface: |S_gpu − S_cpp| ≤ 1e-3 · max(S_cpp, 1e-4 · the channel's largest S of the batch), a
// tenth of the 1e-2 the shipped default tables are validated to, so that the shader's float
// arithmetic stays a small part of what a renderer reads. The same check must reject the shader's
// values against the C++ runtime at θi half an M_p node off (a mapping error it has to see).
// Points: θo, θi uniform in (−90°, 90°), φ in (−360°, 360°), every eighth pair at opposite grazing
// (θo and −θi within 1.5° of one pole); σa per channel 16 u² (u uniform: the low σa where hair
// colours are dense); β_m, β_n log-uniform over [4°, 45°] (the tables' range); every fourth fiber
// with a tilt of up to ±3°.
// The buffers go through the files an engine loads (write_gpu_export, read_gpu_export), checked
// byte for byte against the layout built in memory.
// Measured and reported, not checked: the same with every value rounded to half precision, the
// error that storing the tables as 16-bit floats would add.
//
//   test-gpu-generic --tables FILE.h5 --spirv DIR --out DIR [--points N] [--device NAME]
// Exit 0 pass, 1 a check failed, 2 bad input, 77 no Vulkan device (skipped).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "hairlut/sampler/gpu_buffers.hpp"
#include "hairlut/sampler/gpu_textures.hpp"  // to_half
#include "hairlut/io/gpu_export.hpp"
#include "hairlut/io/table_io.hpp"
#include "hairlut/tables/hair_views.hpp"
#include "vk_compute.hpp"

namespace {

using hairlut::sampler::Fiber;
using hairlut::sampler::HairScattering;
constexpr double kPi = 3.14159265358979323846;
constexpr double kRel = 1e-3, kFloor = 1e-4;

double uniform(std::mt19937_64& g) { return static_cast<double>(g() >> 11) * 0x1p-53; }

// The points as the shader reads them (four vec4 each).
std::vector<float> make_points(std::size_t n, bool angles) {
  std::mt19937_64 g(angles ? 20261207u : 1207u);
  std::vector<float> p;
  const double lo = std::log(4.0 * kPi / 180.0), hi = std::log(45.0 * kPi / 180.0);
  for (std::size_t i = 0; i < n; ++i) {
    float v[16] = {};
    const bool grazing = i % 8 == 7;
    const double pole = uniform(g) < 0.5 ? -0.5 * kPi : 0.5 * kPi, band = 1.5 * kPi / 180.0;
    double to = (uniform(g) - 0.5) * kPi, ti = (uniform(g) - 0.5) * kPi;
    if (grazing) to = pole - std::copysign(band * uniform(g), pole), ti = -pole + std::copysign(band * uniform(g), pole);
    const double phi = (uniform(g) - 0.5) * 4.0 * kPi;
    if (angles) {
      v[0] = static_cast<float>(to), v[1] = static_cast<float>(ti), v[2] = static_cast<float>(phi);
    } else {
      // wo at azimuth 0, wi at −φ (φ = φo − φi).
      v[0] = static_cast<float>(std::sin(to)), v[1] = static_cast<float>(std::cos(to)), v[2] = 0.0f;
      v[4] = static_cast<float>(std::sin(ti)), v[5] = static_cast<float>(std::cos(ti) * std::cos(-phi));
      v[6] = static_cast<float>(std::cos(ti) * std::sin(-phi));
    }
    for (int c = 0; c < 3; ++c) {
      const double u = uniform(g);
      v[8 + c] = static_cast<float>(16.0 * u * u);
    }
    v[11] = static_cast<float>(std::exp(lo + (hi - lo) * uniform(g)));
    v[12] = static_cast<float>(std::exp(lo + (hi - lo) * uniform(g)));
    v[13] = i % 4 == 3 ? static_cast<float>((uniform(g) - 0.5) * 6.0 * kPi / 180.0) : 0.0f;
    p.insert(p.end(), v, v + 16);
  }
  return p;
}

Fiber fiber_of(const float* q) {
  Fiber f;
  for (int c = 0; c < 3; ++c) f.sigma_a[c] = q[8 + c];
  f.beta_m = q[11], f.beta_n = q[12], f.tilt = q[13];
  return f;
}

// The C++ runtime at point q (read back from the buffer: the floats the shader reads), θi moved by
// shift [rad] (the control).
void reference(const HairScattering<float>& rt, const float* q, bool angles, double shift, double* s) {
  const Fiber f = fiber_of(q);
  if (angles || shift != 0.0) {
    double to = q[0], ti = q[1], phi = q[2];
    if (!angles) {
      to = std::atan2(double(q[0]), std::hypot(double(q[1]), double(q[2]))), ti = std::atan2(double(q[4]), std::hypot(double(q[5]), double(q[6])));
      const double cr = double(q[1]) * q[6] - double(q[2]) * q[5], dt = double(q[1]) * q[5] + double(q[2]) * q[6];
      phi = std::atan2(std::fabs(cr), dt + 0.0);
    }
    rt.eval(f, to, ti + shift, phi, s);
    return;
  }
  double wo[3], wi[3];
  for (int w = 0; w < 2; ++w) {
    const float* v = q + 4 * w;
    const double r = std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
    double* o = w == 0 ? wo : wi;
    for (int k = 0; k < 3; ++k) o[k] = v[k] / r;
  }
  rt.eval(f, wo, wi, s);
}

struct Stats {
  std::size_t values = 0, over = 0;
  double max_rel = 0.0, p99_rel = 0.0, median_rel = 0.0;
  std::string worst;
};

Stats compare(const HairScattering<float>& rt, const std::vector<float>& pts, const std::vector<float>& out, bool angles, double shift) {
  const std::size_t n = pts.size() / 16;
  std::vector<double> want(n * 3);
  double peak[3] = {0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < n; ++i) {
    reference(rt, &pts[i * 16], angles, shift, &want[i * 3]);
    for (int c = 0; c < 3; ++c) peak[c] = std::max(peak[c], want[i * 3 + c]);
  }
  Stats st;
  std::vector<double> rel;
  double worst = -1.0;
  for (std::size_t i = 0; i < n * 3; ++i) {
    const double w = want[i], g = out[i / 3 * 4 + i % 3], scale = std::max(w, kFloor * peak[i % 3]);
    const double r = scale > 0.0 ? std::fabs(g - w) / scale : (g == w ? 0.0 : HUGE_VAL);
    ++st.values;
    if (!(r <= kRel)) ++st.over;
    rel.push_back(r);
    if (!(r <= worst)) {
      worst = r;
      const float* q = &pts[i / 3 * 16];
      char buf[320];
      std::snprintf(buf, sizeof buf, "point %zu channel %zu: gpu %.7g, C++ %.7g (args %.6g %.6g %.6g %.6g %.6g %.6g; sigma_a %.4g, beta_m %.4g, beta_n %.4g, tilt %.3g)",
                    i / 3, i % 3, g, w, q[0], q[1], q[2], q[4], q[5], q[6], q[8 + i % 3], q[11], q[12], q[13]);
      st.worst = buf;
    }
  }
  std::sort(rel.begin(), rel.end());
  st.max_rel = rel.back(), st.p99_rel = rel[static_cast<std::size_t>(0.99 * static_cast<double>(rel.size() - 1))];
  st.median_rel = rel[rel.size() / 2];
  return st;
}

}  // namespace

int main(int argc, char** argv) {
  gpu_test::Args args;
  hairlut::TableSet set;
  std::vector<std::uint32_t> spirv;
  try {
    args = gpu_test::parse_args(argc, argv, 8192);
    spirv = gpu_test::read_spirv(args.spirv + "/eval_generic.spv");
    set = hairlut::load_tables(args.tables);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "test-gpu-generic: error: %s\n", e.what());
    return 2;
  }
  try {
    const HairScattering<float> rt = hairlut::hair_scattering<float>(set);
    // The buffers as an engine gets them: exported to files (export-hair-luts), read back, and
    // the same bytes as the layout built in memory.
    std::filesystem::create_directories(args.out);
    const hairlut::gpu::GenericBuffers built(hairlut::hair_tables<float, double>(set));
    hairlut::write_gpu_export(set, std::filesystem::path(args.out) / "export");
    const hairlut::GpuLayout exported = hairlut::read_gpu_export(std::filesystem::path(args.out) / "export.gpu.json");
    if (!exported.generic || std::memcmp(&exported.generic->set, &built.set, sizeof built.set) != 0 || exported.generic->data != built.data) {
      std::printf("FAIL: the exported buffers differ from the layout built in memory\n");
      return 1;
    }
    const hairlut::gpu::GenericBuffers& buffers = *exported.generic;
    std::printf("buffers read back from %s/export.gpu.json, identical to the layout built in memory\n", args.out.c_str());
    gpu_test::Vk vk(args.device);
    std::printf("device: %s (%s)%s\n", vk.device_name().c_str(), vk.driver_info().c_str(), vk.is_cpu() ? ", a CPU implementation" : "");
    const float texel[4] = {0.0f, 0.0f, 0.0f, 0.0f};  // the harness's layout binds two textures this shader does not read
    const gpu_test::Vk::Image none = vk.texture(VK_FORMAT_R32G32B32A32_SFLOAT, 1, 1, 1, texel, sizeof texel);
    const VkSampler nearest = vk.sampler(VK_FILTER_NEAREST);
    const VkPipeline pipeline = vk.pipeline(spirv);
    const std::size_t n = args.points;
    gpu_test::Vk::Buffer ubo = vk.buffer(sizeof buffers.set, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    std::memcpy(ubo.map, &buffers.set, sizeof buffers.set);
    gpu_test::Vk::Buffer data = vk.buffer(buffers.data.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memcpy(data.map, buffers.data.data(), buffers.data.size() * 4);
    gpu_test::Vk::Buffer in = vk.buffer(n * 64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    gpu_test::Vk::Buffer out = vk.buffer(n * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

    nlohmann::ordered_json report = {{"device", vk.device_name()}, {"driver", vk.driver_info()}, {"tables", args.tables},
                                     {"points", n}, {"values_bytes", buffers.data.size() * 4}, {"tables_laid_out", built.tables},
                                     {"check", "|S_gpu - S_cpp| <= 1e-3 max(S_cpp, 1e-4 x the channel's largest S of the batch)"}};
    bool pass = true;
    // θi half a node of the first lobe's M_p θi axis off: the control the check must reject.
    const hairlut::sampler::Axis ti_axis = hairlut::hair_tables<float, double>(set).mp[0].table().axis(1).axis();
    const double half_node = 0.5 * (ti_axis.hi - ti_axis.lo) / (ti_axis.count - 1);
    for (const bool angles : {true, false}) {
      const std::vector<float> pts = make_points(n, angles);
      std::memcpy(in.map, pts.data(), pts.size() * 4);
      const auto t0 = std::chrono::steady_clock::now();
      vk.run(pipeline, none, none, nearest, ubo, in, out, data, static_cast<std::uint32_t>(n), angles ? 0u : 1u);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::vector<float> values(n * 4);
      std::memcpy(values.data(), out.map, values.size() * 4);
      const Stats st = compare(rt, pts, values, angles, 0.0);
      const Stats control = compare(rt, pts, values, angles, half_node);
      const bool ok = st.over == 0 && control.over > 0;
      pass = pass && ok;
      const char* name = angles ? "angles" : "directions";
      std::printf("%-10s %s: max rel %.3g, p99 %.3g, median %.3g, %zu of %zu values over the bound; %.2f s on the device\n", name,
                  ok ? "pass" : "FAIL", st.max_rel, st.p99_rel, st.median_rel, st.over, st.values, seconds);
      std::printf("           worst: %s\n", st.worst.c_str());
      std::printf("           control (C++ at theta_i + %.3g deg): %zu of %zu values over the bound (must be > 0)\n", half_node * 180.0 / kPi,
                  control.over, control.values);
      report["runs"].push_back({{"interface", name}, {"pass", ok}, {"max_rel", st.max_rel}, {"p99_rel", st.p99_rel}, {"median_rel", st.median_rel},
                                {"over_bound", st.over}, {"values", st.values}, {"worst", st.worst}, {"device_seconds", seconds},
                                {"control_over_bound", control.over}});
    }
    // Half storage: the values rounded to binary16, through the direction interface.
    {
      std::vector<float> half(buffers.data.size());
      for (std::size_t i = 0; i < half.size(); ++i) half[i] = hairlut::gpu::from_half(hairlut::gpu::to_half(buffers.data[i]));
      std::memcpy(data.map, half.data(), half.size() * 4);
      const std::vector<float> pts = make_points(n, false);
      std::memcpy(in.map, pts.data(), pts.size() * 4);
      vk.run(pipeline, none, none, nearest, ubo, in, out, data, static_cast<std::uint32_t>(n), 1u);
      std::vector<float> values(n * 4);
      std::memcpy(values.data(), out.map, values.size() * 4);
      const Stats st = compare(rt, pts, values, false, 0.0);
      std::printf("half values (measured, not checked): max rel %.3g, p99 %.3g, median %.3g, %zu of %zu values over 1e-3\n", st.max_rel, st.p99_rel,
                  st.median_rel, st.over, st.values);
      std::printf("           worst: %s\n", st.worst.c_str());
      report["half_storage"] = {{"max_rel", st.max_rel}, {"p99_rel", st.p99_rel}, {"median_rel", st.median_rel}, {"over_1e-3", st.over},
                                {"values", st.values}, {"worst", st.worst}};
    }
    std::filesystem::create_directories(args.out);
    std::ofstream(std::filesystem::path(args.out) / "report.json") << report.dump(2) << "\n";
    return pass ? 0 : 1;
  } catch (const gpu_test::Unavailable& e) {
    std::printf("SKIP: %s\n", e.what());
    return 77;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "test-gpu-generic: error: %s\n", e.what());
    return 2;
  }
}
