// tests/tools/run_command.hpp — runs a command line, capturing its output and exit code
// (for the tests of the command-line programs).
#pragma once

#include <catch2/catch.hpp>

#include <array>
#include <cstdio>
#include <string>
#include <sys/wait.h>

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

}  // namespace magsim::test
