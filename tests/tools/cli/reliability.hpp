// tests/tools/cli/reliability.hpp — what the reliability tests of magsolve and magsim-scene
// share: running the programs (captured, or as a child with its own signals and a
// time limit), scratch paths, file helpers and the address-space limit for runs that
// must stay small. MAGSOLVE_BIN, MAGSIM_SCENE_BIN and MAGSIM_SOURCE_DIR come from CMake.
#pragma once

#include "tests/tools/cli/run_command.hpp"

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

namespace magsim::test::reliability {

using magsim::test::CommandResult;

inline CommandResult scene(const std::string& args) { return magsim::test::run_command(MAGSIM_SCENE_BIN, args); }
inline CommandResult solve(const std::string& args) { return magsim::test::run_command(MAGSOLVE_BIN, args); }

inline std::string input(const std::string& name) { return std::string(MAGSIM_SOURCE_DIR) + "/tests/tools/cli/inputs/" + name; }
inline std::string example(const std::string& name) { return std::string(MAGSIM_SOURCE_DIR) + "/tools/examples/" + name; }

inline std::string tmp(const std::string& name) { return magsim::test::scratch("reliability_" + name); }

inline std::size_t lines(const std::string& s) {
  std::size_t n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

inline std::string text_of(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

// the kind of file at path, not following a symlink (S_IFREG, S_IFIFO, S_IFLNK, …; 0: none)
inline mode_t kind_at(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0 ? (st.st_mode & S_IFMT) : 0;
}

inline long long size_of(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? static_cast<long long>(st.st_size) : -1;
}

// How a child process ended: its exit code, or the signal that killed it.
struct Ended {
  bool signaled = false;
  int code = -1;
};

// `sh -c cmd` as a child with default signal dispositions and an empty signal mask (as from
// an interactive shell; the test runner's own must not leak into the program), stdout on
// out_fd when >= 0. cmd should `exec` the program, so the pid is the program's.
inline pid_t spawn(const std::string& cmd, int out_fd = -1) {
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGXFSZ}) std::signal(sig, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    if (out_fd >= 0) ::dup2(out_fd, 1);
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

// Waits for pid, at most `limit` (then kills it: a test never hangs).
inline Ended wait_for(pid_t pid, std::chrono::seconds limit = std::chrono::seconds(120)) {
  const auto end = std::chrono::steady_clock::now() + limit;
  int st = 0;
  for (;;) {
    const pid_t r = ::waitpid(pid, &st, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) return {};
    if (std::chrono::steady_clock::now() > end) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &st, 0);
      FAIL_CHECK("the program did not end within " << limit.count() << " s; killed");
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  Ended e;
  e.signaled = WIFSIGNALED(st);
  e.code = e.signaled ? WTERMSIG(st) : WEXITSTATUS(st);
  return e;
}

// Polls `done` every 10 ms for at most 60 s.
inline bool wait_until(const std::function<bool()>& done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

// `sh -c cmd` with its stdout on a pipe whose reader is gone (as `| head -1` after its line)
inline Ended run_into_closed_pipe(const std::string& cmd) {
  int fds[2];
  REQUIRE(::pipe(fds) == 0);
  ::close(fds[0]);
  const pid_t pid = spawn(cmd, fds[1]);
  ::close(fds[1]);
  return wait_for(pid);
}

// A balls_up run long enough to be caught mid-run (100000 steps of 244 bodies, every step a
// frame); `exec`, so a signal to the pid reaches the program.
inline std::string long_run(const std::string& out) {
  return std::string("exec ") + MAGSIM_SCENE_BIN + " balls_up --steps 100000 --no-render --threads 1 --fps 1000 --out " +
         out + " 2>/dev/null";
}

// every line of the CSV has `fields` fields and the file ends with a line break
inline void check_whole_rows(const std::string& path, std::size_t fields) {
  const std::string csv = text_of(path);
  REQUIRE(!csv.empty());
  CHECK(csv.back() == '\n');
  std::size_t start = 0, bad = 0, rows = 0;
  while (start < csv.size()) {
    std::size_t end = csv.find('\n', start);
    if (end == std::string::npos) end = csv.size();
    std::size_t commas = 0;
    for (std::size_t i = start; i < end; ++i) commas += csv[i] == ',';
    bad += commas + 1 != fields;
    ++rows;
    start = end + 1;
  }
  INFO(path << ": " << rows << " rows");
  CHECK(bad == 0);
}

// A bound on address space for the runs that must stay small ("ulimit -v"); empty under
// AddressSanitizer, which reserves terabytes of shadow address space at start-up.
#if defined(__SANITIZE_ADDRESS__)
inline const std::string kAddressLimit = "";
#else
inline const std::string kAddressLimit = "ulimit -v 1500000; ";
#endif

}  // namespace magsim::test::reliability
