// Tables too large for memory: baked and written slab by slab.
//
// A slabbed table is part of a TableSet (axes, attributes, place in the set's order) but holds no
// values; its producer computes any range of leading-axis rows on demand. The HDF5 writer asks
// for chunk-aligned ranges in order, writes each as a hyperslab while the next one is baked, and
// hashes the values in the order content_checksum uses, so the file records the same checksum
// and the same values as when the table is held whole. Values do not depend on how a table is
// cut into slabs, nor on the thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "hairlut/tables/tables.hpp"

namespace hairlut {

struct SlabbedTable {
  std::size_t table = 0;  ///< index in TableSet::tables (that Table has no values)
  /// Computes leading-axis rows [row0, row0 + rows) into `out`, whose values (rows × the product
  /// of the other axes' counts, stored precision, allocated by the caller) it sets with Table::set.
  /// May run its work on several threads; throws BakeCancelled when the bake is cancelled.
  std::function<void(std::size_t row0, std::size_t rows, Table& out)> fill;
};

struct SlabbedTables {
  std::vector<SlabbedTable> tables;
  /// Largest slab in bytes; the writer keeps two (one baked while the other is written).
  std::uint64_t slab_bytes = std::uint64_t{64} << 20;
  bool empty() const { return tables.empty(); }
};

}  // namespace hairlut
