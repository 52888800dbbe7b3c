// render-gpu-patch: the hair patch of render-hair-luts (tools/render-hair-luts/patch.hpp) with each
// material's scattering computed by the GLSL runtime through Vulkan: hairlut_eval for the sun and
// hairlut_sample's weights for the environment, from the same uniform numbers as the C++ runtime.
// Writes, per material, the C++ runtime's image (render-hair-luts's left panel) | the GPU's | their
// difference × gain, and gpu-render.json with the differences.
//
// The shaders do all of the scattering; the host only sums each pixel's samples. Textures are
// float32 with explicit taps (the configuration test_gpu_material checks to float rounding).
//
//   render-gpu-patch (--tables FILE.h5 | --config FILE.json) --spirv DIR --out DIR
//                    [--size N] [--fibers N] [--env-samples N] [--diff-gain G] [--check]
// --check: exit 1 when a pixel value of the GPU image differs from the C++ runtime's by more than
// the tables' validated accuracy (validate.thresholds.accuracy_max_rel of their config) times the
// C++ value, or when one drew a direction where the other did not. Pixel values where a draw chose
// another lobe than the C++ runtime's from the same u are counted apart (see below), not checked.
// Exit 0 done, 1 a check failed, 2 bad input, 77 no Vulkan device (skipped).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "hairlut/bake/bake.hpp"
#include "hairlut/bake/config.hpp"
#include "hairlut/io/table_io.hpp"
#include "hairlut/report/validate.hpp"
#include "hairlut/tables/hair_views.hpp"
#include "hairlut/sampler/gpu_textures.hpp"
#include "patch.hpp"
#include "vk_compute.hpp"

namespace {

struct Args {
  std::string tables, config, spirv, out;
  int size = 96, fibers = 12, env_samples = 8;
  double gain = 20.0;
  bool check = false;
};

int integer(const std::string& k, const std::string& v, int lo, int hi) {
  char* end = nullptr;
  const long n = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end || n < lo || n > hi) throw std::invalid_argument(k + ": an integer from " + std::to_string(lo) + " to " + std::to_string(hi) + " (got " + v + ")");
  return static_cast<int>(n);
}

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (k == "--check") {
      a.check = true;
      continue;
    }
    if (i + 1 >= argc) throw std::invalid_argument(k + ": needs a value");
    const std::string v = argv[++i];
    if (k == "--tables") a.tables = v;
    else if (k == "--config") a.config = v;
    else if (k == "--spirv") a.spirv = v;
    else if (k == "--out") a.out = v;
    else if (k == "--size") a.size = integer(k, v, 8, 1024);
    else if (k == "--fibers") a.fibers = integer(k, v, 1, 256);
    else if (k == "--env-samples") a.env_samples = integer(k, v, 1, 4096);
    else if (k == "--diff-gain") {
      char* end = nullptr;
      a.gain = std::strtod(v.c_str(), &end);
      if (v.empty() || *end || !(a.gain > 0.0) || !(a.gain < 1e9)) throw std::invalid_argument("--diff-gain: a number in (0, 1e9) (got " + v + ")");
    } else {
      throw std::invalid_argument("unknown option " + k);
    }
  }
  if (a.tables.empty() == a.config.empty()) throw std::invalid_argument("give exactly one of --tables and --config");
  if (a.spirv.empty() || a.out.empty()) throw std::invalid_argument("--spirv and --out are required");
  return a;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  hairlut::TableSet set;
  std::vector<std::string> groups;
  std::vector<hairlut::sampler::HairScattering<float>> rts;
  hairlut::gpu::MaterialTextures tex;
  std::vector<std::uint32_t> eval_spv, sample_spv;
  double eps = 0.0;
  try {
    args = parse(argc, argv);
    eval_spv = gpu_test::read_spirv(args.spirv + "/eval_material-explicit.spv");
    sample_spv = gpu_test::read_spirv(args.spirv + "/sample_material-explicit.spv");
    if (!args.tables.empty()) {
      set = hairlut::load_tables(args.tables);
    } else {
      hairlut::BakeOptions opt;
      set = hairlut::bake(hairlut::load_config(args.config), opt);
    }
    groups = hairlut::material_groups(set);
    if (groups.empty() || groups.size() > 4) throw std::runtime_error("1 to 4 materials needed (the set has " + std::to_string(groups.size()) + ")");
    for (const std::string& g : groups) {
      rts.push_back(hairlut::hair_scattering<float>(set, g));
      if (!rts.back().valid()) throw std::runtime_error(g + ": the runtime cannot read it");
      tex.add(hairlut::material_tables<float>(set, g));
    }
    eps = hairlut::ValidationThresholds{}.accuracy_max_rel;  // unless the config says otherwise
    const auto& cfg = set.metadata.contains("config") ? set.metadata["config"] : nlohmann::ordered_json::object();
    if (cfg.contains("validate") && cfg["validate"].contains("thresholds")) eps = cfg["validate"]["thresholds"].value("accuracy_max_rel", eps);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render-gpu-patch: error: %s\n", e.what());
    return 2;
  }
  try {
    gpu_test::Vk vk("");
    const int width = args.size, height = args.size, fibers = args.fibers, k_env = args.env_samples;
    const render::Lighting lit;
    const VkFormat f32 = VK_FORMAT_R32G32B32A32_SFLOAT;
    const gpu_test::Vk::Image np = vk.texture(f32, tex.np_width, tex.np_height, tex.np_layers, tex.np.data(), tex.np.size() * 4);
    const gpu_test::Vk::Image mp = vk.texture(f32, tex.mp_width, tex.mp_height, tex.mp_layers, tex.mp.data(), tex.mp.size() * 4);
    const VkSampler linear = vk.sampler(VK_FILTER_LINEAR);
    const VkPipeline eval_pipe = vk.pipeline(eval_spv), sample_pipe = vk.pipeline(sample_spv);
    gpu_test::Vk::Buffer ubo = vk.buffer(4 * sizeof(hairlut::gpu::GpuMaterial), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    std::memcpy(ubo.map, tex.materials.data(), tex.materials.size() * sizeof tex.materials[0]);
    gpu_test::Vk::Buffer rows = vk.buffer(tex.rows.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memcpy(rows.map, tex.rows.data(), tex.rows.size() * 4);

    const std::size_t pixels = static_cast<std::size_t>(fibers) * static_cast<std::size_t>(height);
    const std::size_t draws = 3 * pixels * static_cast<std::size_t>(k_env);
    gpu_test::Vk::Buffer in = vk.buffer(std::max(pixels, draws) * 32, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    gpu_test::Vk::Buffer out = vk.buffer(std::max(pixels, draws) * 32, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::filesystem::create_directories(args.out);
    nlohmann::ordered_json summary = {{"tables", args.tables.empty() ? args.config : args.tables}, {"device", vk.device_name()},
                                      {"driver", vk.driver_info()}, {"size", width}, {"fibers", fibers}, {"env_samples", k_env},
                                      {"textures", "float32, explicit taps"}, {"accuracy_max_rel", eps}, {"images", nlohmann::ordered_json::array()}};
    bool ok = true;
    const hairlut::sampler::Fiber fiber{};  // a material's runtime reads its own σa and β
    for (std::size_t m = 0; m < groups.size(); ++m) {
      // The sun: S at each (fiber, row), by angles (θo = view, θi = light).
      std::vector<render::PatchAngles> at(pixels);
      std::vector<float> pts(pixels * 8, 0.0f);
      for (int i = 0; i < fibers; ++i)
        for (int y = 0; y < height; ++y) {
          const std::size_t p = static_cast<std::size_t>(i * height + y);
          at[p] = render::patch_angles(lit, i, y, height);
          const float q[4] = {static_cast<float>(at[p].theta_view), static_cast<float>(at[p].theta_light), static_cast<float>(at[p].phi),
                              static_cast<float>(m)};
          std::copy(q, q + 4, &pts[p * 8]);
        }
      std::memcpy(in.map, pts.data(), pts.size() * 4);
      vk.run(eval_pipe, np, mp, linear, ubo, in, out, rows, static_cast<std::uint32_t>(pixels), 1u);
      std::vector<float> sun(pixels * 4);
      std::memcpy(sun.data(), out.map, sun.size() * 4);
      // The environment: per channel its own stream of u, as render-hair-luts draws them.
      std::vector<float> spts(draws * 8, 0.0f);
      for (int c = 0; c < 3; ++c) {
        std::mt19937_64 rng(12345u + static_cast<unsigned>(c));
        std::uniform_real_distribution<double> u(0.0, 1.0);
        for (std::size_t p = 0; p < pixels; ++p)
          for (int k = 0; k < k_env; ++k) {
            const std::size_t d = (static_cast<std::size_t>(c) * pixels + p) * static_cast<std::size_t>(k_env) + static_cast<std::size_t>(k);
            const double tv = at[p].theta_view, u0 = u(rng), u1 = u(rng), u2 = u(rng);
            const float q[8] = {static_cast<float>(std::sin(tv)), static_cast<float>(std::cos(tv)), 0.0f, static_cast<float>(m),
                                static_cast<float>(u0), static_cast<float>(u1), static_cast<float>(u2), 0.0f};
            std::copy(q, q + 8, &spts[d * 8]);
          }
      }
      std::memcpy(in.map, spts.data(), spts.size() * 4);
      vk.run(sample_pipe, np, mp, linear, ubo, in, out, rows, static_cast<std::uint32_t>(draws), 1u);
      std::vector<float> env(draws * 8);
      std::memcpy(env.data(), out.map, env.size() * 4);

      // The C++ runtime at the float arguments the shaders read, so that the difference is the
      // shaders' arithmetic alone: S at each pixel once (all channels), then each channel's draws.
      std::vector<double> cpu(pixels * 3), gpu(pixels * 3), sun_cpp(pixels * 3);
      for (std::size_t p = 0; p < pixels; ++p) rts[m].eval(fiber, pts[p * 8], pts[p * 8 + 1], pts[p * 8 + 2], &sun_cpp[p * 3]);
      std::size_t drawn_mismatch = 0, nonfinite = 0, over = 0, other_lobe = 0, pixels_other_lobe = 0;
      double max_diff = 0.0, brightest = 0.0, sum2 = 0.0, max_rel = 0.0, max_rel_same = 0.0;
      for (int c = 0; c < 3; ++c)
        for (std::size_t p = 0; p < pixels; ++p) {
          double lc = lit.l_sun * sun_cpp[p * 3 + static_cast<std::size_t>(c)], lg = lit.l_sun * sun[p * 4 + static_cast<std::size_t>(c)];
          const float* w = &spts[(static_cast<std::size_t>(c) * pixels + p) * static_cast<std::size_t>(k_env) * 8];
          const double wo[3] = {w[0], w[1], w[2]};
          const auto point = rts[m].at(fiber, wo);
          double ec = 0.0, eg = 0.0;
          bool same_lobes = true;
          for (int k = 0; k < k_env; ++k) {
            const std::size_t d = (static_cast<std::size_t>(c) * pixels + p) * static_cast<std::size_t>(k_env) + static_cast<std::size_t>(k);
            const double u3[3] = {spts[d * 8 + 4], spts[d * 8 + 5], spts[d * 8 + 6]};
            const auto cs = point.sample(u3);
            const float* g = &env[d * 8];
            if ((cs.pdf > 0.0) != (g[3] > 0.0f)) ++drawn_mismatch;
            if (cs.pdf > 0.0 && g[3] > 0.0f && static_cast<int>(g[7]) != cs.lobe) ++other_lobe, same_lobes = false;
            if (cs.pdf > 0.0) ec += cs.weight[c];
            if (g[3] > 0.0f) eg += g[4 + c];
          }
          lc += lit.l_env * ec / k_env, lg += lit.l_env * eg / k_env;
          const std::size_t o = p * 3 + static_cast<std::size_t>(c);
          cpu[o] = lc, gpu[o] = lg;
          if (!std::isfinite(lg)) {
            ++nonfinite;
            continue;
          }
          const double diff = std::fabs(lg - lc);
          // A draw whose lobe differs is another sample of the same density, not an error: the lobe
          // is chosen by what is left of u0 after the θr row, and float's rounding of that
          // remainder decides near a boundary between two lobes' shares.
          if (!same_lobes) ++pixels_other_lobe;
          else if (diff > eps * lc) ++over;
          if (same_lobes && lc > 0.0) max_rel_same = std::max(max_rel_same, diff / lc);
          max_diff = std::max(max_diff, diff), brightest = std::max(brightest, lc), sum2 += diff * diff;
          if (lc > 0.0) max_rel = std::max(max_rel, diff / lc);
        }
      const std::string look = groups[m].substr(10), file = "render-gpu-" + look + ".png";
      render::write_png(std::filesystem::path(args.out) / file, 3 * width, height, render::compose_panels(width, height, fibers, cpu, gpu, args.gain));
      const double rms = std::sqrt(sum2 / static_cast<double>(cpu.size()));
      std::printf("%s: max |GPU - C++| %.3g (%.3g of the brightest pixel, %.3g of the pixel at most), rms %.3g; %zu draws differ in being drawn, "
                  "%zu non-finite; %zu draws of %zu chose another lobe (in %zu pixel values); of the others %zu beyond %g of the pixel, %.3g at most -> %s\n",
                  look.c_str(), max_diff, max_diff / std::max(brightest, 1e-300), max_rel, rms, drawn_mismatch, nonfinite, other_lobe, draws,
                  pixels_other_lobe, over, eps, max_rel_same, file.c_str());
      summary["images"].push_back({{"look", look}, {"file", file}, {"max_abs_difference", max_diff},
                                   {"max_relative_to_brightest", max_diff / std::max(brightest, 1e-300)}, {"max_relative_to_pixel", max_rel},
                                   {"rms_difference", rms}, {"brightest", brightest}, {"drawn_mismatch", drawn_mismatch},
                                   {"nonfinite", nonfinite}, {"draws", draws}, {"draws_other_lobe", other_lobe},
                                   {"pixel_values_with_another_lobe", pixels_other_lobe}, {"pixel_values_beyond_accuracy", over},
                                   {"max_relative_to_pixel_same_lobes", max_rel_same}});
      if (drawn_mismatch || nonfinite || over) ok = false;
    }
    std::ofstream(std::filesystem::path(args.out) / "gpu-render.json") << summary.dump(2) << "\n";
    if (args.check && !ok) {
      std::fprintf(stderr, "render-gpu-patch: the GPU image differs from the C++ runtime's beyond the tables' accuracy\n");
      return 1;
    }
  } catch (const gpu_test::Unavailable& e) {
    std::printf("SKIP: %s\n", e.what());
    return 77;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render-gpu-patch: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
