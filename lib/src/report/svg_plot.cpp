#include "hairlut/report/svg_plot.hpp"

#include <cstdint>
#include <utility>

#include "hairlut/io/png.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace hairlut::svg {
namespace {

const char* kPalette[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2", "#7f7f7f"};

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string label(double v) {
  char buf[32];
  if (v != 0.0 && (std::abs(v) < 1e-3 || std::abs(v) >= 1e5)) std::snprintf(buf, sizeof buf, "%.0e", v);
  else std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// "Nice" tick positions covering [lo, hi].
std::vector<double> ticks(double lo, double hi, int target = 6) {
  if (!(hi > lo)) return {lo};
  const double raw = (hi - lo) / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  std::vector<double> t;
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * step; v += step) t.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  return t;
}

// Ticks of a log10 range (colour bars, log axes) [lo, hi]: 1, 2, 5 × 10^k inside it (decades only when those
// are many), labelled as plain numbers ("0.002", "1e-06"), never as a fractional exponent.
std::vector<std::pair<double, std::string>> log_ticks(double lo, double hi) {
  std::vector<std::pair<double, std::string>> all, decades;
  for (int d = static_cast<int>(std::floor(lo)); d <= static_cast<int>(std::ceil(hi)); ++d)
    for (double m : {1.0, 2.0, 5.0}) {
      const double t = std::log10(m) + d;
      if (t < lo - 1e-9 || t > hi + 1e-9) continue;
      all.push_back({t, label(m * std::pow(10.0, d))});
      if (m == 1.0) decades.push_back(all.back());
    }
  if (all.size() > 7) {
    if (decades.size() > 7) {  // every k-th decade
      std::vector<std::pair<double, std::string>> some;
      const std::size_t k = (decades.size() + 6) / 7;
      for (std::size_t i = 0; i < decades.size(); i += k) some.push_back(decades[i]);
      return some;
    }
    return decades;
  }
  if (all.size() < 2) all = {{lo, label(std::pow(10.0, lo))}, {hi, label(std::pow(10.0, hi))}};
  return all;
}


// Viridis-like colour map from 5 anchors.
std::string colour(double u) {
  static const double c[5][3] = {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  u = (u >= 0.0 ? std::min(u, 1.0) : 0.0) * 4.0;  // NaN (a failed measurement) maps to the lowest colour, not an index
  const int i = std::min(3, static_cast<int>(u));
  const double w = u - i;
  char buf[16];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", static_cast<int>(c[i][0] * (1 - w) + c[i + 1][0] * w),
                static_cast<int>(c[i][1] * (1 - w) + c[i + 1][1] * w), static_cast<int>(c[i][2] * (1 - w) + c[i + 1][2] * w));
  return buf;
}

double srgb_encode(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

}  // namespace

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string line_plot(const LinePlot& p) {
  // The legend's width follows its longest label (about 6.2 px per character at 11 px).
  std::size_t longest = 0;
  for (const Series& s : p.series) longest = std::max(longest, s.name.size());
  const double left = 64, right = std::max(150.0, 40.0 + 6.2 * static_cast<double>(longest)), top = 28, bottom = 44;
  const double w = std::max(200.0, p.width - left - right), h = p.height - top - bottom;
  const int total_width = static_cast<int>(left + w + right);
  double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY;
  auto ty = [&](double y) { return p.log_y ? std::log10(std::max(y, 1e-300)) : y; };
  auto tx = [&](double x) { return p.log_x ? std::log10(std::max(x, 1e-300)) : x; };
  for (const Series& s : p.series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.y[i]) || (p.log_y && s.y[i] <= 0) || (p.log_x && s.x[i] <= 0)) continue;
      xlo = std::min(xlo, tx(s.x[i])), xhi = std::max(xhi, tx(s.x[i]));
      ylo = std::min(ylo, ty(s.y[i])), yhi = std::max(yhi, ty(s.y[i]));
    }
  if (std::isfinite(p.y_reference)) ylo = std::min(ylo, ty(p.y_reference)), yhi = std::max(yhi, ty(p.y_reference));
  if (!std::isfinite(xlo)) xlo = 0, xhi = 1, ylo = 0, yhi = 1;
  if (xhi == xlo) xhi = xlo + 1;
  if (yhi == ylo) yhi = ylo + (p.log_y ? 1 : std::max(1e-6, std::abs(ylo) * 0.1)), ylo -= (p.log_y ? 1 : std::max(1e-6, std::abs(ylo) * 0.1));
  if (!p.log_y && yhi - ylo < p.min_span) {
    const double mid = 0.5 * (yhi + ylo);
    ylo = mid - 0.5 * p.min_span, yhi = mid + 0.5 * p.min_span;
  }
  const double pad = 0.05 * (yhi - ylo);
  ylo -= pad, yhi += pad;
  if (p.log_x) {
    const double xpad = 0.05 * (xhi - xlo);
    xlo -= xpad, xhi += xpad;
  }
  auto X = [&](double x) { return left + (tx(x) - xlo) / (xhi - xlo) * w; };
  auto Y = [&](double y) { return top + (1.0 - (ty(y) - ylo) / (yhi - ylo)) * h; };
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << total_width << "\" height=\"" << p.height << "\" viewBox=\"0 0 " << total_width << ' '
    << p.height << "\" font-family=\"sans-serif\" font-size=\"11\">";
  o << "<text x=\"" << num(left + w / 2) << "\" y=\"16\" text-anchor=\"middle\" font-weight=\"bold\">" << escape(p.title) << "</text>";
  o << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << w << "\" height=\"" << h << "\" fill=\"none\" stroke=\"#444\"/>";
  // Log axes are labelled with the values (1, 2, 5 x 10^k), never with a fractional exponent.
  const auto axis_ticks = [](double lo, double hi, bool log, int target) {
    if (log) return log_ticks(lo, hi);
    std::vector<std::pair<double, std::string>> out;
    for (double v : ticks(lo, hi, target)) out.push_back({v, label(v)});
    return out;
  };
  for (const auto& [t, text] : axis_ticks(xlo, xhi, p.log_x, 6)) {
    const double xx = left + (t - xlo) / (xhi - xlo) * w;
    o << "<line x1=\"" << num(xx) << "\" y1=\"" << num(top + h) << "\" x2=\"" << num(xx) << "\" y2=\"" << num(top + h + 4) << "\" stroke=\"#444\"/>"
      << "<text x=\"" << num(xx) << "\" y=\"" << num(top + h + 15) << "\" text-anchor=\"middle\">" << text << "</text>";
  }
  for (const auto& [t, text] : axis_ticks(ylo, yhi, p.log_y, 5)) {
    const double yy = top + (1.0 - (t - ylo) / (yhi - ylo)) * h;
    o << "<line x1=\"" << num(left) << "\" y1=\"" << num(yy) << "\" x2=\"" << num(left + w) << "\" y2=\"" << num(yy) << "\" stroke=\"#eee\"/>"
      << "<text x=\"" << num(left - 5) << "\" y=\"" << num(yy + 4) << "\" text-anchor=\"end\">" << text << "</text>";
  }
  if (std::isfinite(p.y_reference))
    o << "<line x1=\"" << num(left) << "\" y1=\"" << num(Y(p.y_reference)) << "\" x2=\"" << num(left + w) << "\" y2=\"" << num(Y(p.y_reference))
      << "\" stroke=\"#999\" stroke-dasharray=\"2,3\"/>";
  o << "<text x=\"" << num(left + w / 2) << "\" y=\"" << p.height - 8 << "\" text-anchor=\"middle\">" << escape(p.xlabel) << "</text>";
  o << "<text transform=\"translate(14," << num(top + h / 2) << ") rotate(-90)\" text-anchor=\"middle\">" << escape(p.ylabel) << "</text>";
  for (std::size_t si = 0; si < p.series.size(); ++si) {
    const Series& s = p.series[si];
    const std::string c = s.color.empty() ? kPalette[si % 9] : s.color;
    if (s.markers) {
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
        if (std::isfinite(s.y[i]) && (!p.log_y || s.y[i] > 0) && (!p.log_x || s.x[i] > 0))
          o << "<circle cx=\"" << num(X(s.x[i])) << "\" cy=\"" << num(Y(s.y[i])) << "\" r=\"3.5\" fill=\"" << c << "\"/>";
    } else {
      o << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"1.6\"" << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << " points=\"";
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
        if (std::isfinite(s.y[i]) && (!p.log_y || s.y[i] > 0) && (!p.log_x || s.x[i] > 0)) o << num(X(s.x[i])) << ',' << num(Y(s.y[i])) << ' ';
      o << "\"/>";
    }
    const double ly = top + 10 + 15.0 * static_cast<double>(si);
    o << "<line x1=\"" << num(left + w + 8) << "\" y1=\"" << num(ly) << "\" x2=\"" << num(left + w + 28) << "\" y2=\"" << num(ly) << "\" stroke=\"" << c
      << "\" stroke-width=\"2\"" << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << "/><text x=\"" << num(left + w + 32) << "\" y=\""
      << num(ly + 4) << "\">" << escape(s.name) << "</text>";
  }
  o << "</svg>";
  return o.str();
}

namespace {

// The colour of u ∈ [0, 1] as bytes (colour()'s map).
void colour_bytes(double u, std::uint8_t* rgb) {
  const std::string c = colour(u);
  for (int k = 0; k < 3; ++k) rgb[k] = static_cast<std::uint8_t>(std::stoi(c.substr(1 + 2 * static_cast<std::size_t>(k), 2), nullptr, 16));
}

}  // namespace

std::string heat_map(const HeatMap& m) {
  const double left = 64, right = 78, top = 28, bottom = 44;
  const double w = m.width - left - right, h = m.height - top - bottom;
  const std::size_t ny = m.values.size(), nx = ny ? m.values[0].size() : 0;
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& row : m.values)
    for (double v : row) {
      if (std::isnan(v)) continue;
      const double t = m.log_scale ? std::log10(std::max(v, 1e-16)) : v;
      lo = std::min(lo, t), hi = std::max(hi, t);
    }
  if (!std::isfinite(lo)) lo = 0, hi = 1;
  if (hi == lo) hi = lo + 1;
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"heat-map\" width=\"" << m.width << "\" height=\"" << m.height
    << "\" font-family=\"sans-serif\" font-size=\"11\">";
  o << "<text x=\"" << num(left + w / 2) << "\" y=\"16\" text-anchor=\"middle\" font-weight=\"bold\">" << escape(m.title) << "</text>";
  const double cw = nx ? w / static_cast<double>(nx) : w, ch = ny ? h / static_cast<double>(ny) : h;
  // The cells as one PNG, a pixel per cell (top row first), stretched over the plot area without
  // smoothing: a few kilobytes where one SVG rectangle per cell took a hundred bytes each.
  if (nx > 0 && ny > 0) {
    png::Rgb8 image(static_cast<int>(nx), static_cast<int>(ny));
    for (std::size_t iy = 0; iy < ny; ++iy)
      for (std::size_t ix = 0; ix < nx; ++ix) {
        const double v = ix < m.values[iy].size() ? m.values[iy][ix] : NAN;
        std::uint8_t rgb[3] = {0xd0, 0xd0, 0xd0};  // grey: not sampled
        if (!std::isnan(v)) colour_bytes(((m.log_scale ? std::log10(std::max(v, 1e-16)) : v) - lo) / (hi - lo), rgb);
        image.set(static_cast<int>(ix), static_cast<int>(ny - 1 - iy), rgb[0], rgb[1], rgb[2]);
      }
    o << "<image x=\"" << num(left) << "\" y=\"" << num(top) << "\" width=\"" << num(w) << "\" height=\"" << num(h)
      << "\" preserveAspectRatio=\"none\" style=\"image-rendering:pixelated\" href=\"" << png::data_uri(image) << "\"/>";
  }
  o << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << w << "\" height=\"" << h << "\" fill=\"none\" stroke=\"#444\"/>";
  auto axis_labels = [&](const std::vector<double>& c, bool horizontal) {
    const std::size_t n = c.size();
    const std::size_t step = std::max<std::size_t>(1, (n + 3) / 4);
    for (std::size_t k = 0; k < n; k += step) {
      if (horizontal)
        o << "<text x=\"" << num(left + (static_cast<double>(k) + 0.5) * cw) << "\" y=\"" << num(top + h + 14) << "\" text-anchor=\"middle\">"
          << label(c[k]) << "</text>";
      else
        o << "<text x=\"" << num(left - 4) << "\" y=\"" << num(top + h - (static_cast<double>(k) + 0.5) * ch + 4) << "\" text-anchor=\"end\">"
          << label(c[k]) << "</text>";
    }
  };
  axis_labels(m.x, true);
  axis_labels(m.y, false);
  o << "<text x=\"" << num(left + w / 2) << "\" y=\"" << m.height - 8 << "\" text-anchor=\"middle\">" << escape(m.xlabel) << "</text>";
  o << "<text transform=\"translate(12," << num(top + h / 2) << ") rotate(-90)\" text-anchor=\"middle\">" << escape(m.ylabel) << "</text>";
  for (int k = 0; k < 20; ++k)
    o << "<rect x=\"" << num(left + w + 12) << "\" y=\"" << num(top + h - (k + 1) * h / 20) << "\" width=\"12\" height=\"" << num(h / 20 + 0.6)
      << "\" fill=\"" << colour((k + 0.5) / 20) << "\"/>";
  std::vector<std::pair<double, std::string>> bar;
  if (m.log_scale)
    bar = log_ticks(lo, hi);
  else
    for (double v : ticks(lo, hi, 5)) bar.push_back({v, label(v)});
  for (const auto& [t, text] : bar) {
    const double y = top + h - (t - lo) / (hi - lo) * h;
    o << "<line x1=\"" << num(left + w + 24) << "\" y1=\"" << num(y) << "\" x2=\"" << num(left + w + 28) << "\" y2=\"" << num(y)
      << "\" stroke=\"#444\"/><text x=\"" << num(left + w + 30) << "\" y=\"" << num(y + 4) << "\">" << text << "</text>";
  }
  o << "</svg>";
  return o.str();
}

std::string polar_plot(const PolarPlot& p) {
  std::size_t longest = 0;
  for (const Series& s : p.series) longest = std::max(longest, s.name.size());
  const double legend = std::max(120.0, 40.0 + 6.2 * static_cast<double>(longest));
  const double top = p.note.empty() ? 30 : 44, pad = 24;
  const double radius = 0.5 * p.size - pad, cx = pad + radius + 8, cy = top + pad + radius;
  const int width = static_cast<int>(2 * (pad + radius) + 16 + legend), height = static_cast<int>(top + 2 * (pad + radius) + 6);
  double r_max = p.r_max;
  if (!std::isfinite(r_max)) {
    r_max = 0.0;
    for (const Series& s : p.series)
      for (double v : s.y)
        if (std::isfinite(v)) r_max = std::max(r_max, v);
  }
  if (!(r_max > 0.0)) r_max = 1.0;
  auto X = [&](double phi, double r) { return cx + radius * std::min(r, r_max) / r_max * std::cos(phi); };
  auto Y = [&](double phi, double r) { return cy - radius * std::min(r, r_max) / r_max * std::sin(phi); };
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height << "\" viewBox=\"0 0 " << width << ' ' << height
    << "\" font-family=\"sans-serif\" font-size=\"11\">";
  o << "<text x=\"" << num(cx) << "\" y=\"16\" text-anchor=\"middle\" font-weight=\"bold\">" << escape(p.title) << "</text>";
  if (!p.note.empty()) o << "<text x=\"" << num(cx) << "\" y=\"31\" text-anchor=\"middle\" fill=\"#555\">" << escape(p.note) << "</text>";
  for (double t : ticks(0.0, r_max, 4)) {
    if (t <= 0.0) continue;
    o << "<circle cx=\"" << num(cx) << "\" cy=\"" << num(cy) << "\" r=\"" << num(radius * t / r_max) << "\" fill=\"none\" stroke=\"#e4e4e4\"/>"
      << "<text x=\"" << num(cx + 3) << "\" y=\"" << num(cy - radius * t / r_max - 2) << "\" fill=\"#888\" font-size=\"9\">" << label(t) << "</text>";
  }
  o << "<circle cx=\"" << num(cx) << "\" cy=\"" << num(cy) << "\" r=\"" << num(radius) << "\" fill=\"none\" stroke=\"#444\"/>";
  for (int d = 0; d < 360; d += 30) {
    const double a = d * 3.14159265358979323846 / 180.0;
    o << "<line x1=\"" << num(cx) << "\" y1=\"" << num(cy) << "\" x2=\"" << num(X(a, r_max)) << "\" y2=\"" << num(Y(a, r_max))
      << "\" stroke=\"#eee\"/><text x=\"" << num(cx + (radius + 12) * std::cos(a)) << "\" y=\"" << num(cy - (radius + 12) * std::sin(a) + 4)
      << "\" text-anchor=\"middle\" fill=\"#555\" font-size=\"9\">" << (d > 180 ? d - 360 : d) << "&#176;</text>";
  }
  for (std::size_t si = 0; si < p.series.size(); ++si) {
    const Series& s = p.series[si];
    const std::string c = s.color.empty() ? kPalette[si % 9] : s.color;
    for (double sign : p.mirror ? std::vector<double>{1.0, -1.0} : std::vector<double>{1.0}) {
      std::string points;
      auto flush = [&] {
        if (!points.empty())
          o << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"1.5\"" << (s.dashed ? " stroke-dasharray=\"5,3\"" : "")
            << " points=\"" << points << "\"/>";
        points.clear();
      };
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
        if (!(s.y[i] >= 0.0) || std::isnan(s.y[i])) {
          flush();
          continue;
        }
        const double r = std::isfinite(s.y[i]) ? s.y[i] : r_max;
        points += num(X(sign * s.x[i], r)) + "," + num(Y(sign * s.x[i], r)) + " ";
      }
      flush();
    }
    const double ly = top + 10 + 15.0 * static_cast<double>(si), lx = 2 * (pad + radius) + 16;
    o << "<line x1=\"" << num(lx) << "\" y1=\"" << num(ly) << "\" x2=\"" << num(lx + 20) << "\" y2=\"" << num(ly) << "\" stroke=\"" << c
      << "\" stroke-width=\"2\"" << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << "/><text x=\"" << num(lx + 24) << "\" y=\"" << num(ly + 4)
      << "\">" << escape(s.name) << "</text>";
  }
  o << "</svg>";
  return o.str();
}

std::string swatch_grid(const std::string& title, const std::vector<Swatch>& swatches, int columns, const std::vector<std::string>& row_labels,
                        const std::vector<std::string>& column_labels, const std::string& row_title, const std::string& column_title) {
  // The grid fits a report's 1200 px body: squares of up to 22 px, smaller for many columns.
  constexpr int kMaxWidth = 1100;
  const int left = 70, top = 40;
  const int rows = columns > 0 ? static_cast<int>((swatches.size() + static_cast<std::size_t>(columns) - 1) / static_cast<std::size_t>(columns)) : 0;
  const int cell = columns > 0 ? std::clamp((kMaxWidth - left - 20) / columns, 3, 22) : 22;
  const int width = left + columns * cell + 20, height = top + rows * cell + 20;
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height << "\" font-family=\"sans-serif\" font-size=\"10\">";
  o << "<text x=\"" << left << "\" y=\"14\" font-weight=\"bold\" font-size=\"11\">" << escape(title) << "</text>";
  o << "<text x=\"" << left << "\" y=\"28\">" << escape(column_title) << " &#8594;</text>";
  o << "<text transform=\"translate(10," << top + rows * cell / 2 << ") rotate(-90)\" text-anchor=\"middle\">" << escape(row_title) << " &#8594;</text>";
  if (columns > 0 && rows > 0) {
    // One pixel per swatch, each a cell - 1 px square with a 1 px white gap when cells are large.
    const int scale = cell >= 8 ? cell : 1;
    png::Rgb8 image(columns * scale, rows * scale);
    std::fill(image.pixels.begin(), image.pixels.end(), std::uint8_t{255});
    for (std::size_t i = 0; i < swatches.size(); ++i) {
      const int r = static_cast<int>(i) / columns, c = static_cast<int>(i) % columns;
      const Swatch& s = swatches[i];
      const auto byte = [](double v) { return static_cast<std::uint8_t>(std::lround(255 * srgb_encode(v))); };
      const int inner = scale > 1 ? scale - 1 : 1;
      for (int y = 0; y < inner; ++y)
        for (int x = 0; x < inner; ++x) image.set(c * scale + x, r * scale + y, byte(s.r), byte(s.g), byte(s.b));
    }
    o << "<image x=\"" << left << "\" y=\"" << top << "\" width=\"" << columns * cell << "\" height=\"" << rows * cell
      << "\" preserveAspectRatio=\"none\" style=\"image-rendering:pixelated\" href=\"" << png::data_uri(image) << "\"/>";
  }
  const std::size_t row_step = static_cast<std::size_t>(std::max(1, (12 + cell - 1) / cell));
  for (std::size_t r = 0; r < row_labels.size(); r += row_step)
    o << "<text x=\"" << left - 4 << "\" y=\"" << top + static_cast<int>(r) * cell + cell / 2 + 4 << "\" text-anchor=\"end\">" << escape(row_labels[r])
      << "</text>";
  const std::size_t column_step = std::max<std::size_t>({1, column_labels.size() / 8, static_cast<std::size_t>((40 + cell - 1) / cell)});
  for (std::size_t c = 0; c < column_labels.size(); c += column_step)
    o << "<text x=\"" << left + static_cast<int>(c) * cell + cell / 2 << "\" y=\"" << top - 3 << "\" text-anchor=\"middle\">" << escape(column_labels[c])
      << "</text>";
  o << "</svg>";
  return o.str();
}

}  // namespace hairlut::svg
