// tools/cli_common.hpp — what magsim-scene and magsolve share on the command line: the exit
// codes, the help footer that states them, and CLI11's parse with those codes.
#pragma once

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstring>
#include <string>

namespace magsim::tools {

/// The exit codes of both programs (README, their --help).
enum Exit { kOk = 0, kBadInput = 1, kRunFailed = 2, kIoError = 3 };

/// "Exit codes: 0 done, 1 <bad_input>, 2 <failed>, 3 <io>." and then `more` on its own line.
inline std::string exit_codes_footer(const std::string& bad_input, const std::string& failed,
                                     const std::string& io, const std::string& more) {
  return "Exit codes: 0 done, 1 " + bad_input + ", 2 " + failed + ", 3 " + io + "." +
         (more.empty() ? "" : "\n" + more);
}

/// app.parse(argc, argv): -1 when the command line is good; else the code to exit with
/// (0 after --help, kBadInput after a bad flag, CLI11's message printed).
inline int parse_command_line(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kBadInput;
  }
  return -1;
}

/// strerror(errno) for a failed write, "write error" when errno says nothing.
inline std::string errno_text() { return errno ? std::strerror(errno) : "write error"; }

}  // namespace magsim::tools
