// export-hair-luts: a baked table set laid out for hairlut's GLSL runtime, as files an engine
// loads without hairlut (hairlut/io/gpu_export.hpp, docs/gpu.md).
#include <cstdio>
#include <exception>

#include "common/cli.hpp"
#include "hairlut/io/gpu_export.hpp"
#include "hairlut/io/table_io.hpp"
#include "hairlut/util/error.hpp"

int main(int argc, char** argv) {
  const char* tool = "export-hair-luts";
  CLI::App app{
      "Lays out a baked table set for hairlut's GLSL runtime (docs/gpu.md) as files an engine loads without hairlut:\n"
      "a per-material set as the N_p and M_p 2D array textures (OpenEXR, RGBA, layers stacked along y), the\n"
      "HairlutMaterial blocks and the sampling rows for lib/shaders/hairlut.glsl; a generic set as the HairlutGenericSet\n"
      "block and the values for lib/shaders/hairlut_generic.glsl. OUT.gpu.json names them; binary files are little-endian.\n"
      "Exit status: 0 done, 1 an output cannot be written, 2 bad command line or bad input (a missing, unreadable or\n"
      "malformed table file, or a set the shaders cannot read: Fourier N_p, beta bands, axes they do not reconstruct).",
      tool};
  std::string tables, out;
  bool half = false, quiet = false;
  app.add_option("tables", tables, "the table set (HDF5 or OpenEXR file, with its sidecar)")->required();
  app.add_option("--out", out, "the output path without suffix: OUT.gpu.json and OUT.* beside it")->required();
  app.add_flag("--half", half, "textures as RGBA half instead of float32 (adds about 5e-4 of relative error; buffers stay float32)");
  app.add_flag("-q,--quiet", quiet, "print nothing but errors");
  if (const auto status = hairlut::tools::parse_command_line(app, tool, argc, argv)) return *status;
  const std::filesystem::path base(out);
  if (const auto why = hairlut::tools::unwritable_directory(base.parent_path().empty() ? std::filesystem::path(".") : base.parent_path())) {
    hairlut::tools::print_error(tool, *why);
    return 1;
  }
  hairlut::TableSet set;
  try {
    set = hairlut::load_tables(tables);
  } catch (const std::exception& e) {
    hairlut::tools::print_error(tool, e.what());
    return 2;
  }
  try {
    hairlut::GpuExportOptions options;
    options.half = half;
    for (const std::filesystem::path& f : hairlut::write_gpu_export(set, base, options))
      if (!quiet) std::printf("%s\n", f.c_str());
  } catch (const hairlut::DomainError& e) {
    hairlut::tools::print_error(tool, std::string(tables) + ": " + e.what());
    return 2;
  } catch (const std::exception& e) {
    hairlut::tools::print_error(tool, e.what());
    return 1;
  }
  return 0;
}
