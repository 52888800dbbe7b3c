// What a reader of a table set relies on beyond its checksum, checked when a file is loaded: a
// checksum recomputed over altered contents still passes, so the contents themselves must make
// sense. Each table's quantity is the one its name implies (a relabelled np/TT would drop out of
// the sampler); sampling data are finite, their masses and clamp bounds >= 0; Fourier tables'
// parameters lie in the ranges a config can give (fourier_table_info); the beta bands listed in
// the metadata are ordered, tile the beta range without gaps or overlaps, and each band's tables
// cover exactly its range and name it.
#pragma once

#include <string>

#include "hairlut/tables/tables.hpp"

namespace hairlut::detail {

/// Throws IoError("<name>: <what is wrong>") on the first violation.
void check_table_semantics(const TableSet& set, const std::string& name);

}  // namespace hairlut::detail
