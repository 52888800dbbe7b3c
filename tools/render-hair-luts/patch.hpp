// The hair patch that render-hair-luts draws, shared with the GLSL runtime's renderer
// (tests/gpu/render_gpu_patch.cpp) so that both draw the same picture: the fibers' tangents, the
// light and the view, the directions' angles in each fiber's frame, and the panels written as PNG.
//
// Fibers run down the image, waving in the image plane and leaning towards and away from the
// camera, which looks along −z (orthographic). Each fiber is shaded by its far-field scattering
// function, so a fiber's colour depends on its tangent only: L = L_sun · S(wo = view, wi = light)
// + L_env · ∫ S(wo = view, wi) dωi.
#pragma once

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace render {

struct Vec {
  double x, y, z;
};
inline Vec operator-(Vec a, Vec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec operator*(double s, Vec a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec cross(Vec a, Vec b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline Vec normalized(Vec a) { return (1.0 / std::sqrt(dot(a, a))) * a; }

/// The lighting: a directional light (the sun) and a uniform environment, radiances in linear units.
struct Lighting {
  Vec light = normalized({-0.3, 0.65, 0.7}), view = {0.0, 0.0, 1.0};
  double l_sun = 1.5, l_env = 0.15;
};

/// The light's and the view's angles in the frame of fiber `fiber` at row y of `height`: θ of each
/// [rad] and φ = φ_view − φ_light in (−π, π], the tables' θi (light), θr (view) and φ.
struct PatchAngles {
  double theta_light = 0.0, theta_view = 0.0, phi = 0.0;
};
inline PatchAngles patch_angles(const Lighting& lit, int fiber, int y, int height) {
  constexpr double pi = 3.14159265358979323846;
  // In-plane wave a and inclination b towards the viewer: the highlight (R) and the transmitted
  // glow move along each fiber as θv and φ change.
  const double a = 0.3 * std::sin(2.0 * pi * (1.1 * y / height + 0.37 * fiber)) + 0.06 * (fiber % 3 - 1);
  const double b = 0.7 * std::sin(2.0 * pi * (0.8 * y / height + 0.13 * fiber));
  const Vec t = normalized({std::sin(a) * std::cos(b), -std::cos(a) * std::cos(b), std::sin(b)});  // root (top) to tip
  auto angles = [&](Vec d, double* theta, double* phi_of) {
    const double s = std::clamp(dot(d, t), -1.0, 1.0);
    *theta = std::asin(s);
    const Vec perp = d - s * t;
    const Vec w = normalized(lit.view - dot(lit.view, t) * t), v = cross(t, w);
    *phi_of = std::atan2(dot(perp, v), dot(perp, w));
  };
  PatchAngles r;
  double pl, pv;
  angles(lit.light, &r.theta_light, &pl);
  angles(lit.view, &r.theta_view, &pv);
  r.phi = std::remainder(pv - pl, 2.0 * pi);
  return r;
}

/// Linear radiance to 8-bit sRGB, clamped to [0, 1].
inline unsigned char srgb8(double v) {
  v = std::clamp(v, 0.0, 1.0);
  const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return static_cast<unsigned char>(std::lround(255.0 * e));
}

/// Three panels side by side, each `width` × `height`: a, b and |a − b| × gain, from per-(fiber,
/// row, channel) radiances (index (fiber · height + y) · 3 + c); gaps between fibers are black.
inline std::vector<unsigned char> compose_panels(int width, int height, int fibers, const std::vector<double>& a, const std::vector<double>& b,
                                                 double gain) {
  const int w3 = 3 * width;
  std::vector<unsigned char> rgb(static_cast<std::size_t>(w3 * height * 3), 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double fx = (x + 0.5) * fibers / width;
      const int i = std::min(fibers - 1, static_cast<int>(fx));
      const double hoff = 2.0 * (fx - i) - 1.0;  // offset across the fiber
      if (std::fabs(hoff) > 0.85) continue;
      for (int c = 0; c < 3; ++c) {
        const std::size_t at = static_cast<std::size_t>((i * height + y) * 3 + c);
        const std::size_t row0 = static_cast<std::size_t>(y * w3 * 3);
        rgb[row0 + static_cast<std::size_t>(x * 3 + c)] = srgb8(a[at]);
        rgb[row0 + static_cast<std::size_t>((x + width) * 3 + c)] = srgb8(b[at]);
        rgb[row0 + static_cast<std::size_t>((x + 2 * width) * 3 + c)] = srgb8(gain * std::fabs(a[at] - b[at]));
      }
    }
  return rgb;
}

/// Writes 8-bit RGB rows as PNG through a temporary file renamed into place; throws
/// std::runtime_error naming the file on failure.
inline void write_png(const std::filesystem::path& file, int w, int h, const std::vector<unsigned char>& rgb) {
  const std::filesystem::path tmp = file.string() + ".tmp";
  FILE* out = std::fopen(tmp.c_str(), "wb");
  if (!out) throw std::runtime_error(file.string() + ": cannot write");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(out);
    std::filesystem::remove(tmp);
    throw std::runtime_error(file.string() + ": libpng failed");
  }
  png_init_io(png, out);
  png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < h; ++y) png_write_row(png, rgb.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(w) * 3);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(out) != 0) throw std::runtime_error(file.string() + ": cannot write");
  std::filesystem::rename(tmp, file);
}

}  // namespace render
