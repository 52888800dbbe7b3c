// write_outputs, load_tables and load_table_file (table_io.hpp) with the OpenEXR code linked into
// the library. Kept apart from table_io.cpp so that a program that calls only the *_with forms
// links no OpenEXR (static library: this object, and the OpenEXR code, stay out of it).
#include "hairlut/io/exr_codec.hpp"
#include "hairlut/io/table_io.hpp"

namespace hairlut {

std::vector<std::filesystem::path> write_outputs(const TableSet& set, const BakeConfig& config, const BakeReport& report,
                                                 const std::atomic<bool>* cancel, const SlabbedTables* slabbed) {
  return write_outputs_with(linked_exr_codec(), set, config, report, cancel, slabbed);
}

TableSet load_tables(const std::filesystem::path& file) { return load_tables_with(linked_exr_codec(), file); }

TableSet load_table_file(const std::filesystem::path& file) { return load_table_file_with(linked_exr_codec(), file); }

}  // namespace hairlut
