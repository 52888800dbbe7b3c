// Small self-contained SVG charts for reports: line plots, heat maps and colour swatches, as
// inline <svg> elements with no scripts and no external resources.
#pragma once

#include <cmath>
#include <string>
#include <vector>

namespace hairlut::svg {

struct Series {
  std::string name;
  std::vector<double> x, y;
  std::string color;        ///< CSS colour; empty picks one from the palette
  bool dashed = false;
  bool markers = false;     ///< draw points (and no line)
};

struct LinePlot {
  std::string title, xlabel, ylabel;
  std::vector<Series> series;
  bool log_y = false;
  bool log_x = false;
  double y_reference = NAN;  ///< a horizontal reference line (e.g. 1 for energies), NAN for none
  double min_span = 0.0;     ///< the y axis spans at least this much (keeps rounding noise flat)
  int width = 520, height = 320;
};

/// The plot as an <svg> element.
std::string line_plot(const LinePlot& plot);

struct HeatMap {
  std::string title, xlabel, ylabel;
  std::vector<double> x, y;                 ///< cell centre coordinates (for tick labels)
  std::vector<std::vector<double>> values;  ///< values[iy][ix] ≥ 0; NaN marks a cell without data (grey)
  bool log_scale = true;                    ///< colour by log10 of the value
  int width = 360, height = 300;
};

/// The heat map (viridis-like colours, colour bar) as an <svg> element.
std::string heat_map(const HeatMap& map);

struct Swatch {
  double r, g, b;     ///< linear sRGB in [0, 1]; encoded with the sRGB transfer function
  std::string label;  ///< tooltip
};

/// A grid of colour squares, `columns` per row, with row and column labels.
std::string swatch_grid(const std::string& title, const std::vector<Swatch>& swatches, int columns,
                        const std::vector<std::string>& row_labels, const std::vector<std::string>& column_labels,
                        const std::string& row_title, const std::string& column_title);

struct PolarPlot {
  std::string title;
  std::vector<Series> series;  ///< x: azimuth φ (radians), y: radius ≥ 0; non-finite values break the curve
  double r_max = NAN;          ///< radii beyond are drawn on the rim (clipped); NaN: the largest finite radius
  bool mirror = true;          ///< also draw each curve at −φ (an even function given on [0, π])
  std::string note;            ///< a line under the title (e.g. what was clipped)
  int size = 360;              ///< width and height of the circle's square
};

/// Polar plot with φ = 0 to the right and φ growing counterclockwise, rings and spokes every 30°.
std::string polar_plot(const PolarPlot& plot);

/// Escapes &, <, >, " for HTML and SVG text.
std::string escape(const std::string& text);

}  // namespace hairlut::svg
