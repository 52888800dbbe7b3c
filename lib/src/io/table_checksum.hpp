// content_checksum (tables.hpp) with the tables' descriptions already dumped: the same bytes in
// the same order (the metadata, then each table's description and stored values), so the same
// hash, for a writer that needs the descriptions anyway.
#pragma once

#include <string>
#include <vector>

#include "hairlut/util/hash.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut::detail {

/// content_checksum(set, ChecksumRounding::as_stored, kFileHash), given described[i] == set.tables[i].describe().dump().
inline std::string content_checksum_of(const TableSet& set, const std::vector<std::string>& described) {
  Hasher h(kFileHash);
  h.update(set.metadata.dump());
  for (std::size_t i = 0; i < set.tables.size(); ++i) {
    const Table& t = set.tables[i];
    h.update(described.at(i));
    if (t.precision == Precision::float64) h.update(t.f64.data(), t.f64.size() * sizeof(double));
    else h.update(t.f32.data(), t.f32.size() * sizeof(float));
  }
  return h.hex();
}

}  // namespace hairlut::detail
