// The validator's side of a table kind in lib/kinds/<name>/ (bake/table_kind.hpp): which tables its
// accuracy check judges, and its own section of report.json and report.html. The validator reaches
// a kind only through this interface and table_kind_reports(), which the build generates from the
// folders that have a <name>_report.cpp.
#pragma once

#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>

#include "hairlut/tables/tables.hpp"

namespace hairlut {

class TableKindReport {
 public:
  virtual ~TableKindReport() = default;
  /// The kind's name (TableKind::name): the key of its section in report.json.
  virtual std::string_view name() const = 0;
  /// Whether its accuracy check judges table t.
  virtual bool owns(const Table& t) const = 0;
  /// The check over the worst error of its tables: its id, which is also the name of its
  /// threshold (ValidationThresholds), and its title.
  virtual std::string_view accuracy_check() const = 0;
  virtual std::string_view accuracy_title() const = 0;
  /// Its section of report.json from the set's tables (null: none).
  virtual nlohmann::ordered_json section(const TableSet& set) const = 0;
  /// That section as HTML for report.html.
  virtual std::string html(const nlohmann::ordered_json& section) const = 0;
};

/// Every kind under lib/kinds/ with a validator section, in the order of their folders' names.
std::span<const TableKindReport* const> table_kind_reports();

}  // namespace hairlut
