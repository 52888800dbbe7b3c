// A small PNG encoder for reports: 8-bit RGB images (zlib-compressed, filter 0 per row),
// returned as bytes or as a data: URI to embed in HTML or SVG (the reports' plots).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace hairlut::png {

/// An image of width × height pixels, row-major from the top row, 3 bytes (R, G, B) per pixel.
struct Rgb8 {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;
  Rgb8(int w, int h) : width(w), height(h), pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3, 0) {}
  void set(int x, int y, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    std::uint8_t* p = &pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3];
    p[0] = r, p[1] = g, p[2] = b;
  }
};

/// The PNG file's bytes. Throws IoError when zlib fails.
std::string encode(const Rgb8& image);

/// "data:image/png;base64,..." of encode(image).
std::string data_uri(const Rgb8& image);

}  // namespace hairlut::png
