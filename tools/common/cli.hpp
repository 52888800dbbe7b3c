// Command-line parsing shared by the hairlut tools: CLI11 parsing with hairlut's error
// convention. A command-line error is one line on stderr, `tool: error: <reason> (see --help)`,
// and exit status 2; --help and --version print to stdout and exit 0.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace hairlut::tools {

// Prints `tool: error: message` as one line (newlines in the message become "; ").
inline void print_error(const char* tool, std::string message) {
  for (std::size_t i = message.find('\n'); i != std::string::npos; i = message.find('\n', i)) message.replace(i, 1, "; ");
  while (!message.empty() && (message.back() == ' ' || message.back() == ';')) message.pop_back();
  std::fprintf(stderr, "%s: error: %s\n", tool, message.c_str());
}

// Parses argv into app. Returns the exit status when the tool must stop (0 after --help or
// --version, 2 after a command-line error), or nothing when it should go on.
inline std::optional<int> parse_command_line(CLI::App& app, const char* tool, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // help or version text on stdout, exit 0
  } catch (const CLI::ParseError& e) {
    // CLI11 checks required options before it complains about arguments it did not recognise;
    // a misspelt option is the more useful thing to report.
    const std::vector<std::string> unknown = app.remaining(true);
    if (!unknown.empty() && dynamic_cast<const CLI::ExtrasError*>(&e) == nullptr) {
      std::string list;
      for (const std::string& a : unknown) list += (list.empty() ? "" : " ") + a;
      print_error(tool, "unknown option or argument: " + list + " (see --help)");
    } else {
      print_error(tool, std::string(e.what()) + " (see --help)");
    }
    return 2;
  }
  return std::nullopt;
}

}  // namespace hairlut::tools
