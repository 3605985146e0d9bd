// tools/cli/cli_common.hpp — what magsim-scene and magsolve share on the command line: the exit
// codes, the help footer that states them, CLI11's parse with those codes and one-line
// errors, the flag validators (decimal integers, ranges in %g), the thread cap that holds for
// --threads and OMP_NUM_THREADS alike, and the signal dispositions of both programs.
#pragma once

#include "engine/options_table.hpp"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <thread>
#include <type_traits>

namespace magsim::tools {

/// The exit codes of both programs (README, their --help).
enum Exit { kOk = 0, kBadInput = 1, kRunFailed = 2, kIoError = 3 };

/// "Exit codes: 0 done, 1 <bad_input>, 2 <failed>, 3 <io>." and then `more` on its own line.
inline std::string exit_codes_footer(const std::string& bad_input, const std::string& failed,
                                     const std::string& io, const std::string& more) {
  return "Exit codes: 0 done, 1 " + bad_input + ", 2 " + failed + ", 3 " + io + "." +
         (more.empty() ? "" : "\n" + more);
}

/// strerror(errno) for a failed write, "write error" when errno says nothing.
inline std::string errno_text() { return errno ? std::strerror(errno) : "write error"; }

/// `s` on one line: control bytes escaped (\n, \r, \t, \xNN), so a name or value holding
/// them cannot split an error line or reach the terminal raw.
inline std::string one_line(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (const char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else if (c < 0x20 || c == 0x7f) {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    } else {
      out += ch;
    }
  }
  return out;
}

/// x as %g ("1.79769e+308", not 309 digits).
inline std::string fmt_g(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", x);
  return b;
}

/// Both programs' signal dispositions, set first in main: a closed pipe (SIGPIPE) and a file
/// size limit (SIGXFSZ) become failed writes (EPIPE, EFBIG) that the program reports as I/O
/// errors (exit 3), instead of killing it with its outputs cut mid-line.
inline void ignore_write_signals() {
  std::signal(SIGPIPE, SIG_IGN);
  std::signal(SIGXFSZ, SIG_IGN);
}

/// True when everything written to stdout (C and C++ streams) reached it; else prints
/// "<prefix>writing <what> to stdout failed (<why>)" on stderr and returns false. <why> is
/// errno's: callers clear it before they write.
inline bool stdout_written(const char* prefix, const char* what) {
  std::cout.flush();
  const bool ok = std::cout.good() && std::fflush(stdout) == 0 && !std::ferror(stdout);
  if (!ok) std::fprintf(stderr, "%swriting %s to stdout failed (%s)\n", prefix, what, errno_text().c_str());
  return ok;
}

/// The most OpenMP threads either program runs: 4 x the cores. More only slows the run down,
/// and libgomp crashes starting 100000.
inline int max_threads() {
  const unsigned cores = std::thread::hardware_concurrency();
  return 4 * static_cast<int>(cores > 0 ? cores : 1);
}

/// "" when OMP_NUM_THREADS is unset or a thread count (or OpenMP's comma-separated list of
/// them, one per nesting level) in [1, max_threads()], decimal digits only; else the one-line
/// reason. libgomp reads it before main: 0, abc or -1 it ignores without a word, 100000 it
/// tries to start (and crashes), so both programs refuse such a value before any parallel work.
inline std::string omp_num_threads_error() {
  const char* v = std::getenv("OMP_NUM_THREADS");
  if (!v) return {};
  const std::string value = one_line(v);
  const std::string cores = "(4 x the " + std::to_string(max_threads() / 4) + " cores)";
  const std::string bad = "OMP_NUM_THREADS='" + value + "': must be a thread count in [1, " +
                          std::to_string(max_threads()) + "] " + cores;
  const std::string s = v;
  if (s.empty()) return bad + " or unset";
  for (std::size_t i = 0; i < s.size(); ++i) {  // one count per comma-separated entry
    long long n = 0;
    const std::size_t start = i;
    for (; i < s.size() && s[i] >= '0' && s[i] <= '9'; ++i) n = n > INT_MAX ? n : n * 10 + (s[i] - '0');
    if (i == start || (i < s.size() && (s[i] != ',' || i + 1 == s.size()))) return bad + ", decimal digits only";
    if (n < 1) return bad;
    if (n > max_threads())
      return "OMP_NUM_THREADS=" + value + ": more than the " + std::to_string(max_threads()) + " threads allowed " + cores;
  }
  return {};
}

/// The --help line of both programs on MAGSIM_KERNEL (checked by magsim_kernel_error below).
inline constexpr const char* kMagsimKernelHelp =
    "MAGSIM_KERNEL=portable: the field kernels of a CPU without AVX-512 even on one with it; "
    "generic: those of a CPU without FMA either (slow); unset or auto: the fastest the CPU has "
    "(every path gives the same bits; other values are refused).";

/// "" when MAGSIM_KERNEL is unset, "auto", "portable" or "generic" (magnetics/field_kernel.hpp:
/// kernel_path), else the one-line reason. The library takes any other value as "auto"; both
/// programs refuse it, so that a typo cannot pass for the switch.
inline std::string magsim_kernel_error() {
  const char* v = std::getenv("MAGSIM_KERNEL");
  if (!v) return {};
  for (const char* ok : {"auto", "portable", "generic"})
    if (std::strcmp(v, ok) == 0) return {};
  return "MAGSIM_KERNEL='" + one_line(v) + "': must be auto, portable or generic, or unset";
}

// ---- flag validators ---------------------------------------------------------------------
// CLI11's own ranges print their bounds with std::to_string (DBL_MAX as 309 digits) and its
// integer conversion takes 0x10 as 16 and 010 as 8; these print %g and take decimal only.

/// "" when `v` is an optional sign and decimal digits without leading zeros (CLI11 reads
/// 0x10 as 16 and 010 as 8), else why not.
inline std::string decimal_error(const std::string& v) {
  const std::size_t start = (!v.empty() && (v[0] == '+' || v[0] == '-')) ? 1 : 0;
  if (v.size() == start || v.find_first_not_of("0123456789", start) != std::string::npos)
    return "must be a whole decimal number";
  if (v[start] == '0' && v.size() > start + 1) return "must be a whole decimal number without leading zeros";
  return {};
}

/// An integer flag's value in decimal (decimal_error); checks nothing else (the option's
/// own range does).
inline const CLI::Validator Decimal(
    [](std::string& v) -> std::string {
      const std::string e = decimal_error(v);
      return e.empty() ? e : e + ", got '" + one_line(v) + "'";
    },
    "DECIMAL");

/// [lo, hi]: for an integral T a whole decimal number (decimal_error), else any number
/// (strtod), the bounds printed %g.
template <class T>
CLI::Validator Range(T lo, T hi) {
  if constexpr (std::is_integral_v<T>) {
    const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    return CLI::Validator(
        [lo, hi, range](std::string& v) -> std::string {
          if (const std::string e = decimal_error(v); !e.empty()) return e + " in " + range + ", got '" + one_line(v) + "'";
          errno = 0;
          const long long x = std::strtoll(v.c_str(), nullptr, 10);
          if (errno == ERANGE || x < static_cast<long long>(lo) || x > static_cast<long long>(hi))
            return "must be in " + range + ", got " + v;
          return {};
        },
        range);
  } else {
    const double a = static_cast<double>(lo), b = static_cast<double>(hi);
    const std::string range = "[" + fmt_g(a) + ", " + fmt_g(b) + "]";
    return CLI::Validator(
        [a, b, range](std::string& v) -> std::string {
          char* end = nullptr;
          const double x = std::strtod(v.c_str(), &end);
          if (v.empty() || *end != '\0' || !(x >= a && x <= b)) return "must be a number in " + range + ", got " + one_line(v);
          return {};
        },
        range);
  }
}

/// The flag of a number option: its one range (engine/options_table.hpp), the scene file's
/// too. An integer option takes decimal digits only (decimal_error).
inline CLI::Validator OptionCheck(const engine::OptionRange& r) {
  return CLI::Validator(
      [r](std::string& v) -> std::string {
        const std::string bad = "must be " + r.what() + ", got '" + one_line(v) + "'";
        double x;
        if (r.integer) {
          if (const std::string e = decimal_error(v); !e.empty()) return e + " in " + r.text() + ", got '" + one_line(v) + "'";
          errno = 0;
          const long long n = std::strtoll(v.c_str(), nullptr, 10);
          if (errno == ERANGE) return bad;
          x = static_cast<double>(n);
        } else {
          char* end = nullptr;
          x = std::strtod(v.c_str(), &end);
          if (v.empty() || *end != '\0') return bad;
        }
        return r.contains(x) ? std::string() : "must be " + r.what() + ", got " + one_line(v);
      },
      r.text());
}
/// The same for the option at `key` (an engine::options_table() key).
inline CLI::Validator OptionCheck(const char* key) { return OptionCheck(engine::option_spec(key).range); }

/// A number > 0 (CLI::PositiveNumber with a one-line message).
inline const CLI::Validator PositiveNumber(
    [](std::string& v) -> std::string {
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !(x > 0)) return "must be a number > 0, got " + one_line(v);
      return {};
    },
    "POSITIVE");

/// A number >= 0 (CLI::NonNegativeNumber with a one-line message).
inline const CLI::Validator NonNegativeNumber(
    [](std::string& v) -> std::string {
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !(x >= 0)) return "must be a number >= 0, got " + one_line(v);
      return {};
    },
    "NONNEGATIVE");

/// app.parse(argc, argv): -1 when the command line is good; else the code to exit with.
/// --help: 0 once the help reached stdout, kIoError when it did not (a full disk, a closed
/// pipe). A bad flag: kBadInput after one line "<prefix><CLI11's message>" on stderr.
inline int parse_command_line(CLI::App& app, int argc, char** argv, const char* prefix) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help
    errno = 0;
    app.exit(e);
    return stdout_written(prefix, "the help") ? kOk : kIoError;
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s%s (--help for usage)\n", prefix, one_line(e.what()).c_str());
    return kBadInput;
  }
  return -1;
}

}  // namespace magsim::tools
