// Internal: table descriptions (Table::describe) as JSON text for the writers, the same bytes as
// dumping describe() but with each distinct axis dumped once. A set's tables repeat a few axes
// (a per-material file: channel, theta_d and phi in every material's tables), and their node
// values are most of the text: dumping them once per table took most of the writers' JSON time.
//
// How: the tables' JSON is built with a placeholder string in place of each axis ("\u0001" + the
// axis's index + "\u0001", which no description contains), dumped, and every placeholder then
// replaced by that axis's own dump (re-indented for its depth in an indented document).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hairlut/tables/tables.hpp"

namespace hairlut::detail {

class TableText {
 public:
  using json = nlohmann::ordered_json;

  /// t.describe().dump(), byte for byte.
  std::string compact(const Table& t);
  /// t.describe() with placeholders for its axes, for documents dumped by indented().
  json with_placeholders(const Table& t);
  /// doc.dump(2), byte for byte as if doc held the axes themselves, where every placeholder of
  /// `doc` sits `depth` levels deep (an array element of "axes" in a table object of a top-level
  /// array: depth 4).
  std::string indented(const json& doc, int depth);

 private:
  struct Axis {
    GridAxis axis;
    std::string compact, indented;  // indented: dump(2) of the axis alone
    std::string padded;             // indented with padded_by spaces after each line break
    int padded_by = -1;
  };
  std::size_t index_of(const GridAxis& a);
  std::string substitute(const std::string& text, int indent_by);

  std::vector<Axis> axes_;
};

}  // namespace hairlut::detail
