// libFuzzer target: arbitrary bytes as a bake config. Valid outcomes are a parsed config or a
// ConfigError (one line); anything else (another exception, a crash, a sanitizer report) is a bug.
#include <cstddef>
#include <cstdint>
#include <hairlut/bake/config.hpp>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception&) {  // not JSON at all (load_config reports these)
    return 0;
  }
  try {
    const hairlut::BakeConfig c = hairlut::parse_config(doc, "fuzz.json", "/nonexistent");
    (void)c;
  } catch (const hairlut::ConfigError& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) __builtin_trap();  // errors are one line
  }
  return 0;
}
