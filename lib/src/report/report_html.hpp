// Internal: what report.html's sections share (report.cpp), the models' sections included
// (lib/models/<model>/<model>_report.cpp).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hairlut/report/svg_plot.hpp"

namespace hairlut::detail::html {

/// A report value as text: numbers to 3 significant digits, null as "-".
std::string fmt(const nlohmann::ordered_json& v);
/// A report array as numbers.
std::vector<double> vec(const nlohmann::ordered_json& j);
/// One colour per lobe name ("total", "R", ..., "residual"), the same in every plot; "" for others.
std::string lobe_colour(const std::string& key);
/// A plot of E(θi) against θi in degrees, with the line E = 1 drawn.
svg::LinePlot energy_plot(std::string title);

}  // namespace hairlut::detail::html
