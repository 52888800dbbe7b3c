// The OpenEXR readers and writers that write_outputs and load_tables call (exr_io.hpp,
// engine_exr.hpp), as a table of function pointers. write_outputs and load_tables use the ones
// linked into the library (linked_exr_codec); their *_with forms take the table from the caller,
// so that a program can load the OpenEXR code only when a config asks for EXR files (the baker
// loads it as a module: starting the process then maps no OpenEXR library at all).
#pragma once

#include <filesystem>

#include "hairlut/bake/engine_presets.hpp"
#include "hairlut/io/exr_io.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

struct ExrCodec {
  void (*write_exr)(const TableSet& set, const std::filesystem::path& file, const ExrWriteOptions& options) = nullptr;
  void (*write_engine_texture)(const TableSet& set, const EngineTexture& texture, const std::filesystem::path& file) = nullptr;
  TableSet (*read_exr)(const std::filesystem::path& file) = nullptr;
};

/// The OpenEXR functions linked into this library (every entry set).
ExrCodec linked_exr_codec();

}  // namespace hairlut
