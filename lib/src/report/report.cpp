#include "hairlut/report/report.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "hairlut/report/compare.hpp"
#include "hairlut/io/hdf5_io.hpp"  // IoError
#include "hairlut/report/svg_plot.hpp"
#include "hairlut/report/model_kind_report.hpp"
#include "hairlut/report/table_kind_report.hpp"
#include "report_html.hpp"
#include "validate_sections.hpp"

namespace hairlut {

namespace detail::html {

std::string fmt(const nlohmann::ordered_json& v) {
  if (v.is_null()) return "-";
  if (v.is_number()) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v.get<double>());
    return buf;
  }
  return v.is_string() ? v.get<std::string>() : v.dump();
}

std::vector<double> vec(const nlohmann::ordered_json& j) { return j.get<std::vector<double>>(); }

std::string lobe_colour(const std::string& key) {
  static const std::pair<const char*, const char*> colours[] = {{"total", "#000000"}, {"R", "#d62728"},  {"TT", "#2ca02c"},
                                                                {"TRT", "#9467bd"},   {"TRRT", "#ff7f0e"}, {"residual", "#17becf"}};
  for (const auto& [k, c] : colours)
    if (key == k) return c;
  return "";
}

svg::LinePlot energy_plot(std::string title) {
  svg::LinePlot p;
  p.title = std::move(title);
  p.xlabel = "theta_i [deg]";
  p.ylabel = "energy";
  p.y_reference = 1.0;
  return p;
}

}  // namespace detail::html

namespace {

using json = nlohmann::ordered_json;
using svg::escape;
using detail::html::fmt;
using detail::html::lobe_colour;
using detail::html::vec;

std::string status_badge(const std::string& s) {
  const char* colour = s == "pass" ? "#1a7f37" : s == "fail" ? "#cf222e" : "#6e7781";
  return "<span class=\"badge\" style=\"background:" + std::string(colour) + "\">" + s + "</span>";
}

// An axis label with its unit, in the unit the report's text uses: angles (stored in radians) are
// shown in degrees, and `centres` converted to match; a unitless axis says so.
std::string axis_label(const std::string& name, const std::string& units, std::vector<double>& centres) {
  if (units == "rad") {
    for (double& c : centres) c *= 180.0 / M_PI;
    return name + " [deg]";
  }
  return name + " [" + (units.empty() || units == "1" ? std::string("unitless") : units) + "]";
}

// The worst-point search of the accuracy section: per table, the worst found, where, and how
// many points each stage evaluated with the worst of each.
std::string search_stages(const json& t) {
  std::string s;
  for (const json& st : t["search"]["stages"])
    s += (s.empty() ? "" : ", ") + st["stage"].get<std::string>() + " " + std::to_string(st["points"].get<std::size_t>()) + " (" + fmt(st["max_rel"]) + ")";
  return s;
}

std::string search_markdown(const json& r) {
  if (!r.contains("accuracy_search")) return "";
  std::ostringstream o;
  o << "\n### Worst-point search (seed " << r["accuracy_search"]["seed"].dump()
    << ")\n\n| table | worst found | where | points per stage (worst there) |\n|---|---|---|---|\n";
  for (const json& t : r["accuracy"])
    if (t.contains("search"))
      o << "| " << t["path"].get<std::string>() << " | " << fmt(t["worst"]["max_rel"]) << " | " << t["worst"]["where"].get<std::string>() << " | "
        << search_stages(t) << " |\n";
  return o.str();
}

std::string search_html(const json& r) {
  if (!r.contains("accuracy_search")) return "";
  std::ostringstream o;
  o << "<h3>Worst-point search</h3>\n<p>After the random points, each table is searched for its worst point: the first and last cell of "
       "every axis, every corner, known features (N_p's caustics and lobe edges in &phi;, M_p's specular cone), every cell where the "
       "exact value is cheap (M_p, at its narrowest &beta;), grazing ends of angle axes, then coordinate search from the worst points found "
       "and from the worst in each &beta; cell. The checks judge the worst found. Seed "
    << escape(r["accuracy_search"]["seed"].dump()) << " (<code>--seed</code> repeats the run).</p>\n"
    << "<table><tr><th>table</th><th>worst found</th><th>where</th><th>points per stage (worst there)</th></tr>\n";
  for (const json& t : r["accuracy"])
    if (t.contains("search"))
      o << "<tr><td>" << escape(t["path"].get<std::string>()) << "</td><td>" << fmt(t["worst"]["max_rel"]) << "</td><td>"
        << escape(t["worst"]["where"].get<std::string>()) << "</td><td>" << escape(search_stages(t)) << "</td></tr>\n";
  o << "</table>\n";
  return o.str();
}

}  // namespace

std::string render_report_markdown(const json& r) {
  std::ostringstream o;
  const json& s = r["summary"];
  o << "# hairlut validation: " << (s["status"] == "pass" ? "PASS" : "FAIL") << "\n\n";
  o << "Source: `" << r["source"].get<std::string>() << "`  \n";
  o << "Checks: " << s["passed"] << " passed, " << s["failed"] << " failed, " << s["skipped"] << " skipped\n\n";
  o << "| check | status | value | threshold | detail |\n|---|---|---|---|---|\n";
  for (const json& c : r["checks"])
    o << "| " << c["id"].get<std::string>() << " | " << c["status"].get<std::string>() << " | " << fmt(c["value"]) << " | "
      << c["comparison"].get<std::string>() << ' ' << fmt(c["threshold"]) << " | " << c["detail"].get<std::string>() << " |\n";
  if (r.contains("accuracy") && !r["accuracy"].empty()) {
    o << "\n## Table accuracy where a renderer samples\n\nRandom points over each table's declared domain, the table interpolated as its "
         "metadata declare, against direct evaluation. Error = |sampled - exact| / denominator, where the denominator is:\n\n";
    std::vector<std::string> seen;
    for (const json& t : r["accuracy"]) {
      const std::string d = t.value("denominator", std::string());
      if (!d.empty() && std::find(seen.begin(), seen.end(), d) == seen.end()) {
        seen.push_back(d);
        o << "- " << t.value("kind", std::string()) << ": " << d << "\n";
      }
    }
    o << "\n| table | points | worst | p99 | mean | worst (half) | p99 (half) | worst point |\n|---|---|---|---|---|---|---|---|\n";
    for (const json& t : r["accuracy"])
      o << "| " << t["path"].get<std::string>() << " | " << t["off_node"]["points"] << " | " << fmt(t["off_node"]["max_rel"]) << " | "
        << fmt(t["off_node"]["p99_rel"]) << " | " << fmt(t["off_node"].value("mean_rel", 0.0)) << " | " << fmt(t["off_node_half"]["max_rel"]) << " | "
        << fmt(t["off_node_half"]["p99_rel"]) << " | " << (t.contains("worst") ? t["worst"]["where"].get<std::string>() : std::string()) << " |\n";
    o << search_markdown(r);
  }
  o << detail::render_dual_scattering_markdown(r);
  return o.str();
}

std::string render_report_html(const json& r) {
  std::ostringstream o;
  const json& s = r["summary"];
  o << "<h1>hairlut validation report</h1>\n<p class=\"big\">" << status_badge(s["status"].get<std::string>()) << " &nbsp; " << s["passed"]
    << " passed, " << s["failed"] << " failed, " << s["skipped"] << " skipped</p>\n";
  const json& m = r["table_metadata"];
  o << "<p>Source <code>" << escape(r["source"].get<std::string>()) << "</code>; tables <code>" << escape(m.value("name", std::string("?")))
    << "</code> baked by hairlut " << escape(m.value("hairlut_version", std::string("?"))) << ", model " << escape(m.value("model", std::string("?")))
    << ", &eta; = " << fmt(m.value("eta", json())) << ", lobes " << escape(m.value("lobes", json::array()).dump()) << (m.value("residual", false) ? " + residual" : "")
    << ", absorption path " << escape(m.value("absorption_path", std::string("?"))) << ".</p>\n";
  o << "<h2>Summary</h2>\n<table><tr><th>check</th><th>status</th><th>value</th><th>threshold</th><th>detail</th></tr>\n";
  for (const json& c : r["checks"])
    o << "<tr><td><b>" << escape(c["id"].get<std::string>()) << "</b><br>" << escape(c["title"].get<std::string>()) << "</td><td>"
      << status_badge(c["status"].get<std::string>()) << "</td><td>" << fmt(c["value"]) << "</td><td>" << escape(c["comparison"].get<std::string>())
      << ' ' << fmt(c["threshold"]) << "</td><td>" << escape(c["detail"].get<std::string>()) << "</td></tr>\n";
  o << "</table>\n";

  const std::string model = m.value("model", std::string());
  for (const ModelKindReport* k : model_kind_reports())  // lib/models/: the model's energy sections
    if (k->name() == model) o << k->html(r);
  // Longitudinal.
  const json& l = r["longitudinal"];
  o << "<h2>Longitudinal energy: &int; M cos &theta;<sub>r</sub> d&theta;<sub>r</sub></h2>\n<p>d'Eon's M<sub>p</sub> (solid) is 1 everywhere; "
       "Marschner's Gaussian with the 1/cos&sup2;&theta;<sub>d</sub> factor, energy measure cos&sup2;&theta;<sub>r</sub> (d'Eon 2011 Fig. 3): "
       "&asymp;2 with &theta;<sub>h</sub> at low roughness, with 2&theta;<sub>h</sub> a gain at grazing angles and a loss at high roughness.</p><div class=\"plots\">\n";
  const auto lth = vec(l["theta_i_deg"]);
  for (const char* key : {"deon", "gaussian_theta_h", "gaussian_2theta_h"}) {
    svg::LinePlot p;
    p.title = std::string(key == std::string("deon") ? "d'Eon M_p" : key == std::string("gaussian_theta_h") ? "Gaussian, theta_h" : "Gaussian, 2 theta_h");
    p.xlabel = "theta_i [deg]";
    p.ylabel = "energy";
    p.y_reference = 1.0;
    p.min_span = 0.2;
    for (const json& c : l["curves"]) p.series.push_back({"beta " + fmt(c["beta_deg"]) + " deg", lth, vec(c[key]), "", false});
    o << svg::line_plot(p) << "\n";
  }
  for (const json& tb : l["tables"]) {
    svg::LinePlot p;
    p.title = tb["path"].get<std::string>() + ": table vs exact";
    p.xlabel = "theta_i [deg]";
    p.ylabel = "int M cos(theta_r)";
    const auto tth = tb.contains("theta_i_deg") ? vec(tb["theta_i_deg"]) : lth;
    for (const json& c : tb["curves"]) {
      p.series.push_back({"table, beta " + fmt(c["beta_deg"]), tth, vec(c["table"]), "", true});
      p.series.push_back({"exact, beta " + fmt(c["beta_deg"]), tth, vec(c["exact"]), "", false});
    }
    o << svg::line_plot(p) << "\n";
  }
  o << "</div>\n";
  // Accuracy.
  o << "<h2>Table accuracy where a renderer samples</h2>\n<p>|sampled &minus; direct| at random points drawn uniformly over each table's "
       "declared domain (log-uniform on log axes), the table interpolated with the reconstruction its metadata declare, divided by the "
       "denominator of its kind; &ldquo;half&rdquo; is the same with the values rounded to half floats. Per axis: the worst error of the "
       "points in the worst cell of that axis (cell index from 0).</p>\n<ul>\n";
  {
    std::vector<std::string> seen;
    for (const json& a : r["accuracy"]) {
      const std::string d = a.value("denominator", std::string());
      if (!d.empty() && std::find(seen.begin(), seen.end(), d) == seen.end()) {
        seen.push_back(d);
        o << "<li>" << escape(a.value("kind", std::string())) << ": " << escape(d) << "</li>\n";
      }
    }
  }
  o << "</ul>\n<table><tr><th>table</th><th>points</th><th>worst</th><th>p99</th><th>mean</th><th>worst (half)</th><th>p99 (half)</th>"
       "<th>per axis (worst cell)</th><th>worst point</th></tr>\n";
  for (const json& a : r["accuracy"]) {
    std::string per;
    for (const json& pa : a["per_axis"])
      per += escape(pa["axis"].get<std::string>()) + ": " + fmt(pa["max_rel"]) +
             (pa.contains("worst_cell") ? " (cell " + std::to_string(pa["worst_cell"].get<int>()) + ")" : std::string()) + "<br>";
    o << "<tr><td>" << escape(a["path"].get<std::string>()) << "</td><td>" << a["off_node"]["points"] << "</td><td>" << fmt(a["off_node"]["max_rel"])
      << "</td><td>" << fmt(a["off_node"]["p99_rel"]) << "</td><td>" << fmt(a["off_node"].value("mean_rel", 0.0)) << "</td><td>"
      << fmt(a["off_node_half"]["max_rel"]) << "</td><td>" << fmt(a["off_node_half"]["p99_rel"]) << "</td><td>" << per << "</td><td>"
      << (a.contains("worst") ? escape(a["worst"]["where"].get<std::string>()) : std::string()) << "</td></tr>\n";
  }
  o << "</table>\n" << search_html(r);
  for (const json& a : r["accuracy"]) {
    if (a["heatmaps"].empty()) continue;
    o << "<h3>" << escape(a["path"].get<std::string>()) << ": largest relative error per pair of axes</h3><div class=\"plots\">\n";
    for (const json& h : a["heatmaps"]) {
      svg::HeatMap hm;
      hm.title = h["y"].get<std::string>() + " vs " + h["x"].get<std::string>();
      hm.x = vec(h["x_centres"]);
      hm.y = vec(h["y_centres"]);
      hm.xlabel = axis_label(h["x"].get<std::string>(), h.value("x_units", std::string()), hm.x);
      hm.ylabel = axis_label(h["y"].get<std::string>(), h.value("y_units", std::string()), hm.y);
      hm.values = h["max_rel"].get<std::vector<std::vector<double>>>();
      o << svg::heat_map(hm) << "\n";
    }
    o << "</div>\n";
  }
  // Sanity.
  o << "<h2>Sanity</h2>\n<table><tr><th>table</th><th>values</th><th>NaN</th><th>Inf</th><th>negative</th></tr>\n";
  for (const json& st : r["sanity"]["tables"])
    o << "<tr><td>" << escape(st["path"].get<std::string>()) << "</td><td>" << st["values"] << "</td><td>" << st["nan"] << "</td><td>" << st["inf"]
      << "</td><td>" << st["negative"] << "</td></tr>\n";
  o << "</table>\n";
  // Absorption.
  const json& ab = r["absorption"];
  if (!ab["energies"].empty()) {
    o << "<h2>Absorption: lobe energy against &sigma;<sub>a</sub> and &theta;<sub>d</sub></h2><div class=\"plots\">\n";
    for (const json& e : ab["energies"]) {
      const auto sig = vec(e["sigma_a"]), th = vec(e["theta_d"]);
      const auto grid = e["energy"].get<std::vector<std::vector<double>>>();
      svg::LinePlot p;
      p.title = "energy of " + e["lobe"].get<std::string>();
      p.xlabel = "sigma_a [1/radius]";
      p.ylabel = "1/2 int A dh";
      double emin = INFINITY, emax = 0.0;
      for (const auto& row : grid)
        for (double v : row)
          if (v > 0) emin = std::min(emin, v), emax = std::max(emax, v);
      p.log_y = emax > 100.0 * emin;
      for (std::size_t j = 0; j < th.size(); j += std::max<std::size_t>(1, th.size() / 4)) {
        std::vector<double> col;
        for (const auto& row : grid) col.push_back(row[j]);
        p.series.push_back({"theta_d " + fmt(th[j] * 180.0 / M_PI) + " deg", sig, col, "", false});
      }
      o << svg::line_plot(p) << "\n";
    }
    o << "</div>\n";
  }
  for (const TableKindReport* k : table_kind_reports())  // lib/kinds/
    if (r.contains(k->name())) o << k->html(r[std::string(k->name())]);
  o << detail::render_dual_scattering_html(r);
  o << "<h2>Thresholds</h2><p><code>" << escape(r["thresholds"].dump()) << "</code></p>\n";
  return html_page("hairlut validation: " + r["source"].get<std::string>(), o.str());
}

std::string html_page(const std::string& title, const std::string& body) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + escape(title) +
         "</title><style>"
         "body{font-family:sans-serif;margin:24px;max-width:1200px;color:#1f2328}code{overflow-wrap:anywhere}"
         "table{border-collapse:collapse;margin:8px 0 16px}td,th{border:1px solid #d0d7de;padding:4px 8px;font-size:13px;text-align:left;vertical-align:top}"
         "th{background:#f6f8fa}.badge{color:#fff;border-radius:4px;padding:1px 6px;font-weight:bold}"
         ".big{font-size:20px}.plots{display:flex;flex-wrap:wrap;gap:12px}h2{border-bottom:1px solid #d0d7de;padding-bottom:4px;margin-top:32px}"
         "code{background:#f6f8fa;padding:1px 4px}"
         "</style></head><body>\n" +
         body + "</body></html>\n";
}

void write_text_files(const std::filesystem::path& directory, const std::vector<std::pair<std::string, std::string>>& files) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec) throw IoError(directory.string() + ": cannot create report directory (" + ec.message() + ")");
  const std::string suffix = ".tmp-" + std::to_string(::getpid());
  std::vector<fs::path> temps;
  try {
    for (const auto& [name, text] : files) {
      const fs::path tmp = directory / (name + suffix);
      temps.push_back(tmp);
      std::ofstream out(tmp, std::ios::binary);
      out << text;
      if (!out) throw IoError(tmp.string() + ": cannot write");
    }
    for (std::size_t i = 0; i < temps.size(); ++i) {
      fs::rename(temps[i], directory / files[i].first, ec);
      if (ec) throw IoError((directory / files[i].first).string() + ": cannot move into place (" + ec.message() + ")");
    }
  } catch (...) {
    for (const auto& t : temps) fs::remove(t, ec);
    throw;
  }
}

void write_report(const json& report, const std::filesystem::path& directory) {
  write_text_files(directory, {{"report.json", report.dump(1) + "\n"}, {"report.md", render_report_markdown(report)},
                               {"report.html", render_report_html(report)}});
}

}  // namespace hairlut
