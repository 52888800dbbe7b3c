// Command-line conventions shared by the hairlut tools, so that they behave alike:
//
//   exit status 0  done (a validator: every check passes)
//               1  the work failed: a check failed, a computation or an I/O operation failed
//               2  bad command line or bad input: an unknown or malformed option, a missing,
//                  unreadable or malformed input file or config
//               128 + signal  interrupted (tools/common/cancel.hpp)
//
// A command-line error is one line on stderr, `tool: error: <reason> (see --help)`; an option or
// argument the tool does not know is always reported as `unknown option or argument: <them>`.
// --help and --version print to stdout and exit 0; --version prints `tool (hairlut) <version>`.
#pragma once

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <hairlut/util/version.hpp>
#include <cerrno>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

namespace hairlut::tools {

// Prints `tool: error: message` as one line (newlines in the message become "; ").
inline void print_error(const char* tool, std::string message) {
  for (std::size_t i = message.find('\n'); i != std::string::npos; i = message.find('\n', i)) message.replace(i, 1, "; ");
  while (!message.empty() && (message.back() == ' ' || message.back() == ';')) message.pop_back();
  std::fprintf(stderr, "%s: error: %s\n", tool, message.c_str());
}

// Adds --version (`tool (hairlut) <version>`) and parses argv into app. Returns the exit status
// when the tool must stop (0 after --help or --version, 2 after a command-line error), or
// nothing when it should go on.
inline std::optional<int> parse_command_line(CLI::App& app, const char* tool, int argc, char** argv) {
  app.set_version_flag("--version", std::string(tool) + " (hairlut) " + hairlut::kVersion);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // help or version text on stdout, exit 0
  } catch (const CLI::ParseError& e) {
    // Arguments CLI11 did not recognise are reported in one wording whichever error CLI11 raised:
    // it checks required options before it complains about unknown ones, and a misspelt option
    // is the more useful thing to report.
    const std::vector<std::string> unknown = app.remaining(true);
    if (!unknown.empty()) {
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

// Why the directory `dir` cannot take the files a tool writes, or nothing when it can: it is
// created if missing (as the tool would create it), and a probe file is written into it and
// removed (its name ends in ".tmp-<pid>", which the cancel handlers clean up). Checked before the
// work starts, so that a long run does not fail at its last step.
inline std::optional<std::string> unwritable_directory(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return dir.string() + ": cannot create the directory (" + ec.message() + ")";
  if (!fs::is_directory(dir, ec)) return dir.string() + ": not a directory";
  const fs::path probe = dir / (".write-probe.tmp-" + std::to_string(::getpid()));
  std::FILE* f = std::fopen(probe.c_str(), "wb");
  if (!f) return dir.string() + ": cannot write into the directory (" + std::generic_category().message(errno) + ")";
  std::fclose(f);
  fs::remove(probe, ec);
  return std::nullopt;
}

}  // namespace hairlut::tools
