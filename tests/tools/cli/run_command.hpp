// tests/tools/cli/run_command.hpp — runs a command line, capturing its output and exit code
// (for the tests of the command-line programs).
#pragma once

#include <catch2/catch.hpp>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <sys/wait.h>
#include <system_error>
#include <unistd.h>

namespace magsim::test {

struct CommandResult {
  int code = -1;
  std::string out;  // stdout and stderr together
};

/// Runs `program args` through the shell, stderr folded into stdout.
inline CommandResult run_command(const std::string& program, const std::string& args) {
  CommandResult r;
  const std::string cmd = program + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int st = pclose(p);
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : 128;
  return r;
}

/// This test process's folder for the files and output folders it hands to the programs:
/// under the system's temporary directory ($TMPDIR, else /tmp), made on first use and
/// removed with everything in it when the process exits, so repeated runs of the suite
/// leave nothing behind (a crashed test's files stay, to look at).
inline const std::filesystem::path& scratch_dir() {
  struct Dir {
    std::filesystem::path path;
    Dir() : path(std::filesystem::temp_directory_path() / ("magsim_test_" + std::to_string(getpid()))) {
      std::filesystem::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;  // best effort: a destructor at exit must not throw
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

/// scratch_dir()/name, as a string to put on a command line.
inline std::string scratch(const std::string& name) { return (scratch_dir() / name).string(); }

}  // namespace magsim::test
