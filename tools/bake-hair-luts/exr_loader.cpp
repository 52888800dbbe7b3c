#include "exr_loader.hpp"

#include <dlfcn.h>

#include <filesystem>
#include <hairlut/io/engine_exr.hpp>
#include <hairlut/io/hdf5_io.hpp>  // IoError
#include <string>
#include <vector>

namespace hairlut_tools {

hairlut::ExrCodec exr_codec_for(const hairlut::BakeConfig& config) {
  hairlut::ExrCodec codec;
  if (!config.output.exr && hairlut::engine_outputs(config).empty()) return codec;
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path exe_dir = fs::read_symlink("/proc/self/exe", ec).parent_path();
  // Beside the executable (the build tree), then the installed module directory.
  const std::vector<fs::path> candidates = {exe_dir / "hairlut-exr.so", exe_dir / HAIRLUT_EXR_MODULE_FROM_BINDIR / "hairlut-exr.so"};
  std::string why;
  for (const fs::path& p : candidates) {
    if (!fs::exists(p, ec)) continue;
    // The module stays loaded until the process exits (never dlclose'd).
    void* module = ::dlopen(p.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!module) {
      const char* e = ::dlerror();
      why = p.string() + ": " + (e ? e : "cannot load");
      continue;
    }
    auto* entry = reinterpret_cast<void (*)(hairlut::ExrCodec*)>(::dlsym(module, "hairlut_exr_codec_v1"));
    if (!entry) {
      why = p.string() + ": no entry point hairlut_exr_codec_v1";
      continue;
    }
    entry(&codec);
    return codec;
  }
  if (why.empty()) why = "not found beside " + exe_dir.string() + " nor in " + (exe_dir / HAIRLUT_EXR_MODULE_FROM_BINDIR).lexically_normal().string();
  throw hairlut::IoError("OpenEXR module hairlut-exr.so (needed for EXR output): " + why);
}

}  // namespace hairlut_tools
