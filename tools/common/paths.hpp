// Where a tool finds hairlut's data (the shipped configs and default tables, the schemas): below
// the installed share/hairlut when the tool runs from an installed bin/, below the source tree it
// was built from otherwise. Both hold tables/configs/, tables/default/ and schemas/.
#pragma once

#include <filesystem>
#include <string>

namespace hairlut::tools {

/// The running executable (/proc/self/exe), or an empty path where it cannot be read.
inline std::filesystem::path executable_path() {
  std::error_code ec;
  std::filesystem::path p = std::filesystem::canonical("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : p;
}

/// `<prefix>/share/hairlut` when this executable is `<prefix>/bin/<tool>` and that folder holds
/// tables/configs; otherwise `source_dir` (the checkout the build tree was configured from).
inline std::string data_root(const std::string& source_dir) {
  const std::filesystem::path exe = executable_path();
  if (!exe.empty() && exe.parent_path().filename() == "bin") {
    const std::filesystem::path share = exe.parent_path().parent_path() / "share" / "hairlut";
    std::error_code ec;
    if (std::filesystem::is_directory(share / "tables" / "configs", ec)) return share.string();
  }
  return source_dir;
}

/// Another tool of this installation or build tree: `bin/<name>` beside an installed tool, or
/// `tools/<name>/<name>` in the build tree.
inline std::string sibling_tool(const std::string& name) {
  const std::filesystem::path exe = executable_path();
  if (exe.empty()) return name;
  if (exe.parent_path().filename() == "bin") return (exe.parent_path() / name).string();
  return (exe.parent_path().parent_path() / name / name).string();
}

}  // namespace hairlut::tools
