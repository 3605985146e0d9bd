// tests/tools/reliability_test.cpp — "never a crash, never a silent success":
// inputs that used to abort, segfault, run out of memory or exit 0 with nothing useful
// done now end in a one-line error and the documented exit code (0 done, 1 bad input or
// flags, 2 run failed, 3 I/O error).
#include "scenes/option_ranges.hpp"
#include "tests/tools/run_command.hpp"

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

namespace {

using magsim::test::CommandResult;

CommandResult scene(const std::string& args) { return magsim::test::run_command(MAGSIM_SCENE_BIN, args); }
CommandResult solve(const std::string& args) { return magsim::test::run_command(MAGSOLVE_BIN, args); }

std::string input(const std::string& name) { return std::string(MAGSIM_SOURCE_DIR) + "/tests/tools/inputs/" + name; }
std::string example(const std::string& name) { return std::string(MAGSIM_SOURCE_DIR) + "/tools/examples/" + name; }

std::string tmp(const std::string& name) { return magsim::test::scratch("reliability_" + name); }

std::size_t lines(const std::string& s) {
  std::size_t n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

std::string text_of(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

// the kind of file at path, not following a symlink (S_IFREG, S_IFIFO, S_IFLNK, …; 0: none)
mode_t kind_at(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0 ? (st.st_mode & S_IFMT) : 0;
}

long long size_of(const std::string& path) {
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
pid_t spawn(const std::string& cmd, int out_fd = -1) {
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
Ended wait_for(pid_t pid, std::chrono::seconds limit = std::chrono::seconds(120)) {
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
bool wait_until(const std::function<bool()>& done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

// `sh -c cmd` with its stdout on a pipe whose reader is gone (as `| head -1` after its line)
Ended run_into_closed_pipe(const std::string& cmd) {
  int fds[2];
  REQUIRE(::pipe(fds) == 0);
  ::close(fds[0]);
  const pid_t pid = spawn(cmd, fds[1]);
  ::close(fds[1]);
  return wait_for(pid);
}

// A balls_up run long enough to be caught mid-run (100000 steps of 244 bodies, every step a
// frame); `exec`, so a signal to the pid reaches the program.
std::string long_run(const std::string& out) {
  return std::string("exec ") + MAGSIM_SCENE_BIN + " balls_up --steps 100000 --no-render --threads 1 --fps 1000 --out " +
         out + " 2>/dev/null";
}

// every line of the CSV has `fields` fields and the file ends with a line break
void check_whole_rows(const std::string& path, std::size_t fields) {
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

}  // namespace

TEST_CASE("magsolve: a directory as the case file is a one-line error, exit 1", "[reliability]") {
  const CommandResult r = solve(std::string(MAGSIM_SOURCE_DIR) + "/tools/examples");
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("is a directory") != std::string::npos);
  CHECK(lines(r.out) == 1);
}

TEST_CASE("magsim-scene: --threads above 4x the cores is a flag error naming the limit", "[reliability]") {
  for (const char* n : {"100000", "1000000000"}) {
    const CommandResult r = scene(std::string("balls_up --count 5 --steps 1 --no-render --out ") + tmp("threads") +
                                  " --threads " + n);
    INFO(n << ": " << r.out);
    CHECK(r.code == 1);
    CHECK(r.out.find("--threads: at most") != std::string::npos);
  }
}

TEST_CASE("magsolve: a case too big for the Newton reference is refused up front with the size", "[reliability]") {
  // 20,000 induced moments: 3 matrices of 60,000² doubles = 80 GiB (it was a bad_alloc once)
  const std::string path = tmp("huge.json");
  {
    std::ofstream f(path);
    f << "{\"moments\": [";
    for (int i = 0; i < 20000; ++i)
      f << (i ? "," : "") << "{\"position\": [" << 0.02 * (i % 100) << ", " << 0.02 * (i / 100)
        << ", 0], \"volume\": 5e-7, \"Ms\": 1.6e6, \"kind\": \"induced\"}";
    f << "]}";
  }
  const CommandResult r = solve(path + " --max-iter 1");
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("20000 induced moments") != std::string::npos);
  CHECK(r.out.find("GiB") != std::string::npos);
}

TEST_CASE("magsim-scene: non-finite, too small or too large run flags are flag errors", "[reliability]") {
  struct Case {
    const char* args;
    const char* says;
  };
  const Case cases[] = {
      {"--seconds nan", "--seconds"},   {"--seconds inf", "--seconds"},
      {"--seconds 1e300", "steps"},     {"--seconds 1e8", "1e+11 steps"},
      {"--seconds 1e-9", "shorter than one rigid step"},
      {"--fps nan", "--fps"},           {"--fps 1e-300", "--fps"},
      {"--width 17", "even"},           {"--height 719", "even"},
      {"--steps 3000000000", "--steps"},
  };
  for (const Case& c : cases) {
    const CommandResult r = scene(std::string("balls_up --count 5 --no-render --out ") + tmp("flags") + " " + c.args);
    INFO(c.args << ": exit " << r.code << ", said: " << r.out);
    CHECK(r.code == 1);
    CHECK(r.out.find(c.says) != std::string::npos);
  }
}

TEST_CASE("magsim-scene: a scene file whose dt makes too many steps is refused with the numbers", "[reliability]") {
  const CommandResult r = scene(input("tiny_dt.json") + " --no-render --out " + tmp("tiny_dt"));
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("2e+12 steps") != std::string::npos);
}

TEST_CASE("magsolve: a failed write to stdout is exit 3, not a silent success", "[reliability]") {
  for (const char* format : {"json", "csv"}) {
    // stderr to the pipe, stdout to the full device
    const CommandResult r = magsim::test::run_command(std::string("{ ") + MAGSOLVE_BIN,
                                                      example("touching_spheres.json") + " --format " + format +
                                                          " 2>&1 > /dev/full; }");
    INFO(format << ": " << r.out);
    CHECK(r.code == 3);
    CHECK(r.out.find("No space left") != std::string::npos);
  }
}

TEST_CASE("magsolve: flag errors exit 1 like bad input", "[reliability]") {
  for (const char* flags : {"--format xml", "--dt 1", "--method nope", "--max-iter many", "--bogus"}) {
    const CommandResult r = solve(example("touching_spheres.json") + " " + flags);
    INFO(flags << ": " << r.out);
    CHECK(r.code == 1);
  }
}

TEST_CASE("duplicate JSON keys are errors naming the key and path, in both tools", "[reliability]") {
  const CommandResult s = scene(input("duplicate_key.json") + " --steps 1 --no-render --out " + tmp("dup"));
  INFO(s.out);
  CHECK(s.code == 1);
  CHECK(s.out.find("bodies[0].position: duplicate key") != std::string::npos);
  const CommandResult m = solve(input("duplicate_key_magsolve.json"));
  INFO(m.out);
  CHECK(m.code == 1);
  CHECK(m.out.find("moments[0].volume: duplicate key") != std::string::npos);
}

TEST_CASE("magsim-scene: a permanent moment without \"moment\" is refused", "[reliability]") {
  const CommandResult r = scene(input("permanent_without_moment.json") + " --steps 1 --no-render --out " + tmp("perm"));
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("bodies[0].moments[0].moment: required") != std::string::npos);
}

TEST_CASE("magsim-scene: body names with commas, quotes or line breaks are quoted in states.csv", "[reliability]") {
  const std::string out = tmp("names");
  const CommandResult r = scene(input("odd_body_name.json") + " --steps 1 --no-render --out " + out);
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::ifstream f(out + "/states.csv");
  const std::string csv((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  CHECK(csv.find("0,0,0,\"ball, \"\"zero\"\"\nline\",0,0,0.005,") != std::string::npos);
  CHECK(csv.find("0,0,1,plain,0.02,") != std::string::npos);  // ordinary names stay unquoted
}

TEST_CASE("magsim-scene: --out in the scene file's folder may not overwrite the scene file", "[reliability]") {
  const std::string dir = tmp("same");
  REQUIRE(std::system(("mkdir -p " + dir + " && cp " + input("odd_body_name.json") + " " + dir + "/summary.json").c_str()) == 0);
  const CommandResult r = scene(dir + "/summary.json --steps 1 --no-render --out " + dir);
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("would overwrite the input scene file") != std::string::npos);
  std::ifstream f(dir + "/summary.json");
  std::string first;
  std::getline(f, first);
  CHECK(first.rfind("// a body name", 0) == 0);  // the input is untouched
}

TEST_CASE("magsim-scene: a rerun deletes its own old outputs (stale frames) and nothing else", "[reliability]") {
  const std::string dir = tmp("rerun");
  REQUIRE(std::system(("mkdir -p " + dir + " && touch " + dir + "/frame_000099.png " + dir + "/frame_1234567.png " +
                       dir + "/keep.txt " + dir + "/frame_x.png " + dir + "/summary.json.tmp").c_str()) == 0);
  const CommandResult r = scene(input("odd_body_name.json") + " --steps 1 --no-render --out " + dir);
  INFO(r.out);
  REQUIRE(r.code == 0);
  auto exists = [&](const char* n) { return std::ifstream(dir + "/" + n).good(); };
  CHECK(!exists("frame_000099.png"));
  CHECK(!exists("frame_1234567.png"));
  CHECK(!exists("summary.json.tmp"));
  CHECK(exists("keep.txt"));
  CHECK(exists("frame_x.png"));
  CHECK(exists("summary.json"));
}

TEST_CASE("magsim-scene: a full disk is exit 3 naming the file, and leaves no summary.json", "[reliability]") {
  // a 64 KiB tmpfs; needs root (mount): skipped elsewhere
  const std::string dir = tmp("full");
  REQUIRE(std::system(("mkdir -p " + dir).c_str()) == 0);
  if (std::system(("mount -t tmpfs -o size=64k tmpfs " + dir + " 2>/dev/null").c_str()) != 0) {
    WARN("cannot mount a tmpfs here (not root?): full-disk test skipped");
    return;
  }
  const CommandResult r = scene(std::string(MAGSIM_SOURCE_DIR) + "/scenes/examples/two_balls.json --steps 1000 "
                                "--fps 1000 --no-render --out " + dir);
  const bool summary = std::ifstream(dir + "/summary.json").good();
  std::system(("umount " + dir).c_str());
  INFO(r.out);
  CHECK(r.code == 3);
  CHECK(r.out.find(".csv failed (No space left on device)") != std::string::npos);
  CHECK(!summary);
}

TEST_CASE("magsim-scene: a body faster than options.max_body_speed ends the run, exit 2, summary with the error", "[reliability]") {
  const std::string out = tmp("blow_up");
  const CommandResult r = scene(input("blow_up.json") + " --steps 50 --no-render --out " + out);
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(r.out.find("body 1 'ball_0': speed") != std::string::npos);
  std::ifstream f(out + "/summary.json");
  const std::string summary((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  CHECK(summary.find("\"error\": \"step ") != std::string::npos);
  CHECK(summary.find("exceeds options.max_body_speed") != std::string::npos);
  // 0 turns the guard off
  const CommandResult off = scene(input("blow_up_guard_off.json") + " --steps 50 --no-render --out " + tmp("blow_up_off"));
  INFO(off.out);
  CHECK(off.code == 0);
}

TEST_CASE("magsim-scene: a directory named like a scene file is a one-line error, exit 1", "[reliability]") {
  const std::string dir = tmp("dir.json");
  REQUIRE(std::system(("mkdir -p " + dir).c_str()) == 0);
  const CommandResult r = scene(dir + " --steps 1 --no-render --out " + tmp("dir_out"));
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("is a directory") != std::string::npos);
}

TEST_CASE("magsolve: two moments closer than half their radii are refused without --softening", "[reliability]") {
  // 1e-12 m apart: F = 4e41 N before (only exact coincidence was refused)
  const CommandResult r = solve(input("close_pair_magsolve.json"));
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("moments[1] and moments[2] are 1e-12 m apart, closer than 0.005 m") != std::string::npos);
  CHECK(r.out.find("--softening") != std::string::npos);
  CHECK(lines(r.out) == 1);
  // with softening the case is solved
  const CommandResult soft = solve(input("close_pair_magsolve.json") + " --softening 0.001");
  INFO(soft.out);
  CHECK(soft.code == 0);
  // touching spheres (2 radii apart) stay allowed
  CHECK(solve(example("touching_spheres.json")).code == 0);
}

TEST_CASE("magsolve: a non-finite torque is exit 2 naming it, never printed as null", "[reliability]") {
  const CommandResult r = solve(input("infinite_torque_magsolve.json"));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(r.out.find("the torque of moments[0] is not finite") != std::string::npos);
  CHECK(r.out.find("null") == std::string::npos);
}

TEST_CASE("magsolve: converged means M = f(H), not only a small change per iteration", "[reliability]") {
  // a 1 A/m field: the dynamics change M by less than tol x Ms per iteration from the start
  // and stop after 4 iterations at |M| = 2.16 A/m, 30 % short of f(H) = 3.1 A/m
  const CommandResult r = solve(input("weak_field_magsolve.json") + " --method ours");
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("\"converged\": false") != std::string::npos);
  CHECK(r.out.find("\"criterion_met\": true") != std::string::npos);
  // Anderson solves M = f(H) itself: converged
  const CommandResult a = solve(input("weak_field_magsolve.json") + " --method anderson");
  INFO(a.out);
  CHECK(a.code == 0);
  CHECK(a.out.find("\"converged\": true") != std::string::npos);
  // the CSV header line says the same
  const CommandResult c = solve(input("weak_field_magsolve.json") + " --method ours --format csv");
  CHECK(c.out.find("converged=false criterion_met=true") != std::string::npos);
  CHECK(c.out.find("relative residual") != std::string::npos);  // the note on stderr
}

TEST_CASE("magsim-scene: magnitudes ODE cannot take are refused up front with the JSON path, exit 1", "[reliability]") {
  // each of these used to fail inside ODE on step 1 (dxNormalize4's assertion, inf/NaN
  // velocities) or in the magnetics; see engine/limits.hpp
  struct Case {
    const char* file;
    const char* says;
  };
  const Case cases[] = {
      {"mass_1e-300", "bodies[1].mass: must be 0 (density x volume) or in [1e-12, 1e+12] kg"},
      {"mass_1e300", "bodies[1].mass: must be 0 (density x volume) or in [1e-12, 1e+12] kg"},
      {"density_1e-300", "body 1 'ball_0': mass 5.23599e-307 kg (density x volume) is outside"},
      {"Ms_1e300", "bodies[1].moments[0].Ms: magnitude 1e+300 A/m exceeds 1e+08 A/m"},
      {"Ms_-1e300", "bodies[1].moments[0].Ms: must be > 0"},
      {"gravity_1e300", "options.gravity: magnitude 1e+300 m/s^2 exceeds"},
      {"gravity_-1e300", "options.gravity: magnitude 1e+300 m/s^2 exceeds"},
      {"velocity_1e300", "bodies[1].velocity: magnitude 1e+300 m/s exceeds 1e+06 m/s"},
      {"velocity_-1e300", "bodies[1].velocity: magnitude 1e+300 m/s exceeds 1e+06 m/s"},
      {"angular_velocity_1e300", "bodies[1].angular_velocity: magnitude 1e+300 rad/s exceeds"},
      {"shape_offset_1e300", "bodies[1].shapes[0].offset: magnitude 1e+300 m exceeds 1e+06 m"},
      {"shape_offset_-1e300", "bodies[1].shapes[0].offset: magnitude 1e+300 m exceeds 1e+06 m"},
      {"moment_offset_1e300", "bodies[1].moments[0].offset: magnitude 1e+300 m exceeds 1e+06 m"},
      {"moment_offset_-1e300", "bodies[1].moments[0].offset: magnitude 1e+300 m exceeds 1e+06 m"},
      {"position_1e300", "bodies[1].position: magnitude 1e+300 m exceeds"},
      {"moment_1e300", "bodies[0].moments[0].moment: magnitude 1e+300 A·m^2 exceeds 1e+12"},
      {"volume_1e300", "bodies[1].moments[0].volume: magnitude 1e+300 m^3 exceeds 1000 m^3"},
      {"size_1e300", "bodies[1].shapes[0].size: magnitude 1e+300 m exceeds"},
      {"H0_1e300", "H0: magnitude 1e+300 A/m exceeds 1e+12 A/m"},
  };
  for (const Case& c : cases) {
    const std::string out = tmp(std::string("magnitude_") + c.file);
    const CommandResult r = scene(input(std::string("magnitudes/") + c.file + ".json") + " --steps 5 --no-render --out " + out);
    INFO(c.file << ": " << r.out);
    CHECK(r.code == 1);
    CHECK(r.out.find(c.says) != std::string::npos);
    CHECK(lines(r.out) == 1);
    CHECK(!std::ifstream(out + "/summary.json").good());
  }
  // registry scenes go through the same limits (Simulation's validation)
  const CommandResult s = scene("balls_up --strength 1e300 --steps 1 --no-render --out " + tmp("strength"));
  INFO(s.out);
  CHECK(s.code == 1);
  CHECK(s.out.find("moments[0].moment: magnitude 2.97e+301") != std::string::npos);  // 29.7 A·m² × 1e300
}

TEST_CASE("magsim-scene: options.threads has the --threads cap", "[reliability]") {
  const CommandResult r = scene(input("threads_too_many.json") + " --steps 1 --no-render --out " + tmp("threads_file"));
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("options.threads: at most") != std::string::npos);
  CHECK(r.out.find("got 1000") != std::string::npos);
}

TEST_CASE("magsim-scene: an output folder that cannot be made is an I/O error, exit 3", "[reliability]") {
  const std::string file = tmp("not_a_dir");
  { std::ofstream(file) << "x"; }
  const CommandResult r = scene("balls_up --count 5 --steps 1 --no-render --out " + file + "/sub");
  INFO(r.out);
  CHECK(r.code == 3);
  CHECK(r.out.find("cannot create the directory") != std::string::npos);
  const CommandResult f = scene("balls_up --count 5 --steps 1 --no-render --out " + file);
  INFO(f.out);
  CHECK(f.code == 3);
  CHECK(f.out.find("exists and is not a directory") != std::string::npos);
}

TEST_CASE("magsim-scene: a degenerate camera is an error naming it, not blank frames", "[reliability]") {
  struct Case {
    const char* file;
    const char* says;
  };
  const Case cases[] = {
      {"camera_eye_is_target", "camera: eye [0.1, 0.2, 0.3] and target [0.1, 0.2, 0.3] are the same point"},
      {"camera_up_zero", "camera: up must not be zero"},
      {"camera_up_parallel", "camera: up [0, 0, 1] is parallel to the view direction"},
  };
  for (const Case& c : cases) {
    const CommandResult r = scene(input(std::string(c.file) + ".json") + " --steps 1 --no-render --out " + tmp(c.file));
    INFO(c.file << ": " << r.out);
    CHECK(r.code == 1);
    CHECK(r.out.find(c.says) != std::string::npos);
  }
}

TEST_CASE("magsim-scene: the issue's other blow-ups end in exit 2 with the error in summary.json", "[reliability]") {
  // a ball inside a 1e4 A·m² magnet (2,700 m/s, exit 0 before) and two balls 1e-12 m apart
  for (const char* name : {"ball_inside_magnet", "balls_1e-12_apart"}) {
    const std::string out = tmp(name);
    const CommandResult r = scene(input(std::string(name) + ".json") + " --steps 300 --no-render --out " + out);
    INFO(name << ": " << r.out);
    CHECK(r.code == 2);
    CHECK(r.out.find("body 1 'ball_0': speed") != std::string::npos);
    std::ifstream f(out + "/summary.json");
    const std::string summary((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    CHECK(summary.find("exceeds options.max_body_speed") != std::string::npos);
  }
}

TEST_CASE("magsolve: a long Newton reference reports its progress on stderr", "[reliability]") {
  // 500 induced moments (the bound is 3153): each Newton step is reported, stdout stays JSON
  const std::string path = tmp("n500.json");
  {
    std::ofstream f(path);
    f << "{\"external_field\": [0, 0, 1000], \"moments\": [";
    for (int i = 0; i < 500; ++i)
      f << (i ? "," : "") << "{\"position\": [" << 0.02 * (i % 25) << ", " << 0.02 * (i / 25)
        << ", 0], \"volume\": 5e-7, \"Ms\": 1.6e6, \"kind\": \"induced\"}";
    f << "]}";
  }
  const CommandResult r = solve(path + " --method anderson");
  CHECK(r.code == 0);
  CHECK(r.out.find("Newton reference for 500 induced moments") != std::string::npos);
  CHECK(r.out.find("Newton reference step 1, relative residual") != std::string::npos);
  // small cases stay quiet
  const CommandResult small = solve(example("touching_spheres.json"));
  CHECK(small.out.find("Newton reference") == std::string::npos);
}

// ---- the third round: never damage, never hang, never die on a signal ----------------------

// A bound on address space for the runs that must stay small ("ulimit -v"); empty under
// AddressSanitizer, which reserves terabytes of shadow address space at start-up.
#if defined(__SANITIZE_ADDRESS__)
const std::string kAddressLimit = "";
#else
const std::string kAddressLimit = "ulimit -v 1500000; ";
#endif

TEST_CASE("a scene file or magsolve case that is a FIFO or a device is refused at once, exit 1", "[reliability]") {
  const std::string fifo = tmp("fifo.json"), zero = tmp("zero.json");
  REQUIRE(::mkfifo(fifo.c_str(), 0644) == 0);
  REQUIRE(::symlink("/dev/zero", zero.c_str()) == 0);
  struct Case {
    std::string path;
    const char* says;
  };
  for (const Case& c : {Case{fifo, "is a FIFO, not a regular file"}, Case{zero, "is a character device, not a regular file"},
                        Case{"/dev/zero", "is a character device, not a regular file"}}) {
    for (const bool solver : {true, false}) {
      if (!solver && c.path == "/dev/zero") continue;  // magsim-scene reads FILE.json only
      // before: a FIFO blocked for ever, /dev/zero was read until memory ran out
      const std::string bin = kAddressLimit + "timeout 20 " + (solver ? MAGSOLVE_BIN : MAGSIM_SCENE_BIN);
      const CommandResult r = magsim::test::run_command(
          bin, c.path + (solver ? "" : " --steps 1 --no-render --out " + tmp("nonregular_out")));
      INFO((solver ? "magsolve " : "magsim-scene ") << c.path << ": exit " << r.code << ": " << r.out);
      CHECK(r.code == 1);
      CHECK(r.out.find(c.says) != std::string::npos);
      CHECK(lines(r.out) == 1);
    }
  }
  CHECK(scene("--help").out.find("larger than 1 GiB") != std::string::npos);
  CHECK(solve("--help").out.find("larger than 1 GiB") != std::string::npos);
}

TEST_CASE("JSON nested deeper than 64 levels is refused in both tools, fast and in little memory", "[reliability]") {
  auto nested = [](int levels) { return std::string(levels, '[') + std::string(levels, ']'); };
  const std::string ok = tmp("depth64.json"), deep = tmp("depth65.json"), deep_case = tmp("depth65_case.json");
  write_text(ok, "{\"bodies\": [], \"comment\": " + nested(63) + "}");  // 64 levels with the outer object
  write_text(deep, "{\"bodies\": [], \"comment\": " + nested(64) + "}");
  write_text(deep_case, "{\"moments\": " + nested(64) + "}");
  CHECK(scene(ok + " --steps 1 --no-render --out " + tmp("depth_out")).code == 0);
  const CommandResult s = scene(deep + " --steps 1 --no-render --out " + tmp("depth_out"));
  INFO(s.out);
  CHECK(s.code == 1);
  CHECK(s.out.find("nested deeper than 64 levels") != std::string::npos);
  CHECK(lines(s.out) == 1);
  const CommandResult m = solve(deep_case);
  INFO(m.out);
  CHECK(m.code == 1);
  CHECK(m.out.find("nested deeper than 64 levels") != std::string::npos);
  // 100,000 levels (200 KB) with 1.5 GB of address space: the path kept at every level needed
  // gigabytes before (bad_alloc, exit 2)
  const std::string huge = tmp("depth_huge.json");
  write_text(huge, nested(100000));
  for (const bool solver : {true, false}) {
    const CommandResult r = magsim::test::run_command(
        kAddressLimit + "timeout 60 " + (solver ? MAGSOLVE_BIN : MAGSIM_SCENE_BIN),
        huge + (solver ? "" : " --steps 1 --no-render --out " + tmp("depth_huge_out")));
    INFO((solver ? "magsolve: " : "magsim-scene: ") << r.out);
    CHECK(r.code == 1);
    CHECK(r.out.find("nested deeper than 64 levels") != std::string::npos);
  }
}

TEST_CASE("a valid document followed by a NUL byte and junk is refused in both tools", "[reliability]") {
  // nlohmann's lexer takes a NUL for the end of the text: the junk was never read
  const std::string nul_scene = tmp("nul_junk.json"), nul_case = tmp("nul_junk_case.json");
  write_text(nul_scene, std::string("{\"bodies\": []}\0junk", 19));
  write_text(nul_case, text_of(example("touching_spheres.json")) + std::string("\0{junk", 6));
  const CommandResult s = scene(nul_scene + " --steps 1 --no-render --out " + tmp("nul_out"));
  INFO(s.out);
  CHECK(s.code == 1);
  CHECK(s.out.find("malformed JSON: a NUL byte at byte offset 14") != std::string::npos);
  CHECK(lines(s.out) == 1);
  const CommandResult m = solve(nul_case);
  INFO(m.out);
  CHECK(m.code == 1);
  CHECK(m.out.find("a NUL byte") != std::string::npos);
}

TEST_CASE("OMP_NUM_THREADS: above 4x the cores or not a thread count is refused in one line, exit 1", "[reliability]") {
  for (const char* value : {"100000", "0", "abc", "-1", "", "4,"}) {
    for (const bool solver : {true, false}) {
      const std::string env = std::string("OMP_NUM_THREADS='") + value + "' ";
      const CommandResult r = solver ? magsim::test::run_command(env + MAGSOLVE_BIN, example("touching_spheres.json"))
                                     : magsim::test::run_command(env + MAGSIM_SCENE_BIN,
                                                                 "balls_up --count 5 --steps 1 --no-render --out " +
                                                                     tmp("omp"));
      INFO((solver ? "magsolve" : "magsim-scene") << " OMP_NUM_THREADS='" << value << "': exit " << r.code << ": " << r.out);
      CHECK(r.code == 1);
      CHECK(r.out.find("OMP_NUM_THREADS") != std::string::npos);
      CHECK(r.out.find(std::string(value).size() > 3 ? "more than the" : "must be a thread count in [1, ") != std::string::npos);
    }
  }
  // a count within the cap runs
  CHECK(magsim::test::run_command("OMP_NUM_THREADS=1 " + std::string(MAGSOLVE_BIN), example("touching_spheres.json")).code == 0);
}

TEST_CASE("MAGSIM_KERNEL: only auto or portable is taken, anything else is refused in one line, exit 1", "[reliability]") {
  for (const char* value : {"Portable", "avx512", ""}) {
    for (const bool solver : {true, false}) {
      const std::string env = std::string("MAGSIM_KERNEL='") + value + "' ";
      const CommandResult r = solver ? magsim::test::run_command(env + MAGSOLVE_BIN, example("touching_spheres.json"))
                                     : magsim::test::run_command(env + MAGSIM_SCENE_BIN,
                                                                 "balls_up --count 5 --steps 1 --no-render --out " +
                                                                     tmp("kernel"));
      INFO((solver ? "magsolve" : "magsim-scene") << " MAGSIM_KERNEL='" << value << "': exit " << r.code << ": " << r.out);
      CHECK(r.code == 1);
      CHECK(r.out.find("MAGSIM_KERNEL='" + std::string(value) + "': must be auto or portable") != std::string::npos);
      CHECK(lines(r.out) == 1);
    }
  }
  for (const char* value : {"auto", "portable"})
    CHECK(magsim::test::run_command(std::string("MAGSIM_KERNEL=") + value + " " + MAGSOLVE_BIN,
                                    example("touching_spheres.json")).code == 0);
}

TEST_CASE("a closed pipe: magsolve's results are an I/O error (exit 3), a scene run is not killed", "[reliability]") {
  const std::string err = tmp("pipe_err.txt");
  const Ended m = run_into_closed_pipe(std::string("exec ") + MAGSOLVE_BIN + " " + example("touching_spheres.json") + " 2>" + err);
  INFO("magsolve: " << (m.signaled ? "killed by signal " : "exit ") << m.code << ": " << text_of(err));
  CHECK(!m.signaled);
  CHECK(m.code == 3);
  CHECK(text_of(err).find("writing the results to stdout failed (Broken pipe)") != std::string::npos);
  CHECK(lines(text_of(err)) == 1);
  // magsim-scene's lines (progress, the closing line) go to stderr, here the closed pipe:
  // lost, and the run completes
  const std::string out = tmp("pipe_scene");
  const Ended s = run_into_closed_pipe(std::string("exec ") + MAGSIM_SCENE_BIN + " balls_up --count 5 --steps 20 --no-render --out " +
                                       out + " 2>&1");
  INFO("magsim-scene: " << (s.signaled ? "killed by signal " : "exit ") << s.code);
  CHECK(!s.signaled);
  CHECK(s.code == 0);
  const auto summary = nlohmann::json::parse(text_of(out + "/summary.json"));
  CHECK(summary["steps"] == 20);
  check_whole_rows(out + "/states.csv", 11);
}

TEST_CASE("magsim-scene: a file size limit (SIGXFSZ) is an I/O error, exit 3", "[reliability]") {
  const std::string out = tmp("fsize");
  // 100 blocks of 512 bytes (dash): states.csv passes it within the first frames
  const CommandResult r = magsim::test::run_command(std::string("ulimit -f 100; ") + MAGSIM_SCENE_BIN,
                                                    "balls_up --steps 50 --fps 1000 --no-render --threads 1 --out " + out);
  INFO(r.out);
  CHECK(r.code == 3);
  CHECK(r.out.find("(File too large)") != std::string::npos);
  CHECK(nlohmann::json::parse(text_of(out + "/summary.json"))["error"].get<std::string>().find("File too large") !=
        std::string::npos);
}

TEST_CASE("flags: an empty --write-scene or --out and non-decimal integers are refused, exit 1", "[reliability]") {
  const std::string out = tmp("empty_write_scene");
  const CommandResult w = scene("balls_up --count 3 --steps 1 --no-render --out " + out + " --write-scene ''");
  INFO(w.out);
  CHECK(w.code == 1);
  CHECK(w.out.find("--write-scene: needs a non-empty path") != std::string::npos);
  CHECK(kind_at(out) == 0);  // no run instead
  const CommandResult o = scene("balls_up --count 3 --steps 1 --no-render --out ''");
  INFO(o.out);
  CHECK(o.code == 1);
  CHECK(o.out.find("--out: needs a non-empty path") != std::string::npos);
  // CLI11 read 0x10 as 16 and 010 as 8
  for (const char* flags : {"--steps 0x10", "--steps 010", "--steps 1e1", "--width 0x100", "--count 0x5", "--threads 01",
                            "--bh-threshold 0x10"}) {
    const CommandResult f = scene(std::string("balls_up --count 3 --no-render --out ") + tmp("hex") + " " + flags);
    INFO(flags << ": " << f.out);
    CHECK(f.code == 1);
    CHECK(f.out.find("must be a whole decimal number") != std::string::npos);
  }
  for (const char* flags : {"--max-iter 0x10", "--max-iter 010"}) {
    const CommandResult f = solve(example("touching_spheres.json") + " " + flags);
    INFO(flags << ": " << f.out);
    CHECK(f.code == 1);
    CHECK(f.out.find("--max-iter: must be a whole decimal number") != std::string::npos);
  }
}

TEST_CASE("both tools: --help into a full disk is exit 3", "[reliability]") {
  for (const char* bin : {MAGSIM_SCENE_BIN, MAGSOLVE_BIN}) {
    const CommandResult r = magsim::test::run_command(std::string("{ ") + bin, "--help 2>&1 > /dev/full; }");
    INFO(bin << ": " << r.out);
    CHECK(r.code == 3);
    CHECK(r.out.find("writing the help to stdout failed (No space left on device)") != std::string::npos);
  }
}

TEST_CASE("flags: errors are one line, ranges in %g", "[reliability]") {
  struct Case {
    const char* flags;
    const char* says;
  };
  for (const Case& c : {Case{"--strength -1", "--strength: must be a number > 0, got -1"},
                        Case{"--dt-m -1", "--dt-m: must be a number in [1e-09, 1e-06], got -1"},
                        Case{"--rolling-friction -1", "--rolling-friction: must be a number >= 0 and finite, got -1"},
                        Case{"--dt 1", "--dt: must be a number in (0, 0.1], got 1"},
                        Case{"--fps 0", "--fps: must be a number in [0.001, 1e+09], got 0"},
                        Case{"--bogus", "--bogus"}, Case{"--steps 0", "--steps: must be in [1, 10000000], got 0"}}) {
    const CommandResult r = scene(std::string("balls_up --count 3 --no-render --out ") + tmp("wording") + " " + c.flags);
    INFO(c.flags << ": " << r.out);
    CHECK(r.code == 1);
    CHECK(r.out.find(c.says) != std::string::npos);
    CHECK(lines(r.out) == 1);
    CHECK(r.out.size() < 200);  // DBL_MAX printed as 309 digits before
  }
  const CommandResult m = solve(example("touching_spheres.json") + " --residual-tol -1");
  INFO(m.out);
  CHECK(m.code == 1);
  CHECK(m.out.find("--residual-tol: must be a number > 0, got -1") != std::string::npos);
  CHECK(lines(m.out) == 1);
}

TEST_CASE("magsim-scene --write-scene: only a regular file is replaced, through a unique temporary file", "[reliability]") {
  static int pass = 0;  // each SECTION runs the test case anew: a folder of its own
  const std::string dir = tmp("write_scene_targets_" + std::to_string(pass++));
  REQUIRE(std::system(("mkdir -p " + dir).c_str()) == 0);
  auto write = [&](const std::string& name) { return scene("balls_up --count 3 --write-scene " + dir + "/" + name); };
  SECTION("a FIFO, a directory or a device node is refused and left as it is") {
    REQUIRE(::mkfifo((dir + "/fifo.json").c_str(), 0644) == 0);
    REQUIRE(::mkdir((dir + "/dir.json").c_str(), 0755) == 0);
    for (const char* name : {"fifo.json", "dir.json"}) {
      const mode_t before = kind_at(dir + "/" + name);
      const CommandResult r = write(name);
      INFO(name << ": " << r.out);
      CHECK(r.code == 1);
      CHECK(r.out.find("not a regular file; it is not replaced") != std::string::npos);
      CHECK(lines(r.out) == 1);
      CHECK(kind_at(dir + "/" + name) == before);
    }
    // a character device (root only: mknod); the program is aimed at a copy of /dev/null's node
    if (::mknod((dir + "/null.json").c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0) {
      const CommandResult r = write("null.json");
      INFO(r.out);
      CHECK(r.code == 1);
      CHECK(r.out.find("is a character device") != std::string::npos);
      CHECK(kind_at(dir + "/null.json") == S_IFCHR);
    } else {
      WARN("cannot mknod here (not root?): the device-node case is skipped");
    }
  }
  SECTION("a symlink is written through to its regular target; one to a FIFO or nowhere is refused") {
    write_text(dir + "/target.json", "old");
    REQUIRE(::chmod((dir + "/target.json").c_str(), 0640) == 0);
    REQUIRE(::symlink("target.json", (dir + "/link.json").c_str()) == 0);
    const CommandResult r = write("link.json");
    INFO(r.out);
    CHECK(r.code == 0);
    CHECK(kind_at(dir + "/link.json") == S_IFLNK);
    CHECK(text_of(dir + "/target.json").find("\"bodies\"") != std::string::npos);
    struct stat st {};
    REQUIRE(::stat((dir + "/target.json").c_str(), &st) == 0);
    CHECK((st.st_mode & 0777) == 0640);  // the file's permissions are kept
    REQUIRE(::mkfifo((dir + "/fifo2").c_str(), 0644) == 0);
    REQUIRE(::symlink("fifo2", (dir + "/to_fifo.json").c_str()) == 0);
    REQUIRE(::symlink("nowhere.json", (dir + "/dangling.json").c_str()) == 0);
    for (const char* name : {"to_fifo.json", "dangling.json"}) {
      const CommandResult b = write(name);
      INFO(name << ": " << b.out);
      CHECK(b.code == 1);
      CHECK(lines(b.out) == 1);
      CHECK(kind_at(dir + "/" + name) == S_IFLNK);
    }
    CHECK(kind_at(dir + "/fifo2") == S_IFIFO);
    CHECK(kind_at(dir + "/nowhere.json") == 0);
  }
  SECTION("the user's own x.json.tmp is not touched, and no temporary file is left") {
    write_text(dir + "/x.json.tmp", "mine");
    const CommandResult r = write("x.json");
    INFO(r.out);
    CHECK(r.code == 0);
    CHECK(text_of(dir + "/x.json.tmp") == "mine");
    CHECK(text_of(dir + "/x.json").find("\"bodies\"") != std::string::npos);
    const CommandResult ls = magsim::test::run_command("ls -A", dir);
    CHECK(ls.out == "x.json\nx.json.tmp\n");
  }
}

TEST_CASE("magsim-scene: an output name in --out that is a FIFO is refused, not deleted", "[reliability]") {
  const std::string dir = tmp("out_fifo");
  REQUIRE(std::system(("mkdir -p " + dir).c_str()) == 0);
  REQUIRE(::mkfifo((dir + "/states.csv").c_str(), 0644) == 0);
  const CommandResult r = scene("balls_up --count 3 --steps 1 --no-render --out " + dir);
  INFO(r.out);
  CHECK(r.code == 3);
  CHECK(r.out.find("states.csv is not a regular file") != std::string::npos);
  CHECK(kind_at(dir + "/states.csv") == S_IFIFO);
}

TEST_CASE("scene files: control characters in a body name are refused, or escaped in error lines", "[reliability]") {
  // NUL cut the name in states.csv; ESC reached the terminal
  const std::string name = tmp("nul_name.json");
  write_text(name, R"({"bodies": [{"name": "ok", "shapes": [{"size": 0.01}]},
                                 {"name": "a\u0000b\u001b[31m", "shapes": [{"size": 0.01}]}]})");
  const CommandResult n = scene(name + " --steps 1 --no-render --out " + tmp("nul_name_out"));
  INFO(n.out);
  CHECK(n.code == 1);
  CHECK(n.out.find("bodies[1].name: must not contain control characters") != std::string::npos);
  CHECK(n.out.find("(got \"a\\x00b\\x1b[31m\")") != std::string::npos);
  CHECK(lines(n.out) == 1);
  // tab and line breaks stay allowed (states.csv quotes them); an error line escapes them
  std::string blow = text_of(input("blow_up.json"));
  blow.replace(blow.find("\"ball_0\""), 8, R"("ball\n\tzero")");
  const std::string blow_path = tmp("blow_up_named.json");
  write_text(blow_path, blow);
  const CommandResult b = scene(blow_path + " --steps 50 --no-render --out " + tmp("blow_up_named"));
  INFO(b.out);
  CHECK(b.code == 2);
  CHECK(b.out.find("body 1 'ball\\n\\tzero': speed") != std::string::npos);
}

TEST_CASE("scene files: a finite quaternion of any size is normalised, below norm 1e-12 the error says so", "[reliability]") {
  // [1e300, 1e300, 0, 0] was refused as "not finite": its norm overflowed
  const std::string big = tmp("big_quaternion.json"), tiny = tmp("tiny_quaternion.json");
  write_text(big, R"({"bodies": [{"orientation": [1e300, 1e300, 0, 0], "shapes": [{"size": 0.01}]}]})");
  write_text(tiny, R"({"bodies": [{"orientation": [1e-13, 0, 0, 0], "shapes": [{"size": 0.01}]}]})");
  const std::string q_out = tmp("big_quaternion_out");
  const CommandResult q = scene(big + " --steps 1 --no-render --out " + q_out);
  INFO(q.out);
  CHECK(q.code == 0);
  CHECK(text_of(q_out + "/states.csv").find("0,0,0,body_0,0,0,0,0.7071067812,0.7071067812,0,0\n") != std::string::npos);
  const CommandResult t = scene(tiny + " --steps 1 --no-render --out " + tmp("tiny_quaternion_out"));
  INFO(t.out);
  CHECK(t.code == 1);
  CHECK(t.out.find("bodies[0].orientation: must be a quaternion [w, x, y, z] of norm >= 1e-12 (got norm 1e-13)") !=
        std::string::npos);
}

TEST_CASE("magsim-scene: a dangling --out symlink is named as one, exit 3", "[reliability]") {
  // "File exists" before
  const std::string link = tmp("dangling_out");
  REQUIRE(::symlink((link + "_target").c_str(), link.c_str()) == 0);
  const CommandResult d = scene("balls_up --count 3 --steps 1 --no-render --out " + link);
  INFO(d.out);
  CHECK(d.code == 3);
  CHECK(d.out.find("is a symbolic link to " + link + "_target, which does not exist") != std::string::npos);
  CHECK(lines(d.out) == 1);
}

TEST_CASE("magsim-scene: SIGTERM, SIGINT or SIGHUP mid-run ends with whole CSV rows, an interrupted summary, exit 128 + signal", "[reliability]") {
  for (const int sig : {SIGTERM, SIGINT, SIGHUP}) {
    const std::string out = tmp("signal_" + std::to_string(sig));
    const pid_t pid = spawn(long_run(out));
    // a few frames in, and mid-way through writing more
    const bool running = wait_until([&] { return size_of(out + "/states.csv") > 200000; });
    ::kill(pid, sig);
    REQUIRE(running);
    const Ended e = wait_for(pid);
    INFO("signal " << sig << ": " << (e.signaled ? "killed by signal " : "exit ") << e.code);
    CHECK(!e.signaled);
    CHECK(e.code == 128 + sig);
    const auto summary = nlohmann::json::parse(text_of(out + "/summary.json"));
    CHECK(summary["interrupted"] == true);
    CHECK(summary["signal"] == (sig == SIGTERM ? "SIGTERM" : sig == SIGINT ? "SIGINT" : "SIGHUP"));
    CHECK(summary["error"].is_null());
    CHECK(summary["steps"].get<long>() < 100000);
    CHECK(summary["frames"].get<long>() == summary["steps"].get<long>() + 1);  // a frame a step, from step 0
    check_whole_rows(out + "/states.csv", 11);
    check_whole_rows(out + "/moments.csv", 16);
  }
}

TEST_CASE("magsim-scene: a second run into an output folder in use is refused, exit 1, and leaves the first's files", "[reliability]") {
  const std::string out = tmp("locked");
  const pid_t pid = spawn(long_run(out));
  const bool running = wait_until([&] { return size_of(out + "/states.csv") > 0; });
  const CommandResult second = running ? scene("balls_up --count 5 --steps 1 --no-render --out " + out) : CommandResult{};
  const bool first_files = size_of(out + "/states.csv") > 0;
  ::kill(pid, SIGTERM);
  const Ended first = wait_for(pid);
  REQUIRE(running);
  INFO(second.out);
  CHECK(second.code == 1);
  CHECK(second.out.find("another run is writing into this folder") != std::string::npos);
  CHECK(lines(second.out) == 1);
  CHECK(first_files);
  CHECK(!first.signaled);
  CHECK(nlohmann::json::parse(text_of(out + "/summary.json"))["steps_requested"] == 100000);  // the first run's
  // the lock ends with the run that held it
  CHECK(scene("balls_up --count 5 --steps 1 --no-render --out " + out).code == 0);
}

// the PNG frames after a failed write: exit 3 (not 2), summary.json naming the error, and no
// frame cut short under its name (render/png_io.cpp writes a temporary file and renames it)
void check_png_write_failure(const std::string& out, const CommandResult& r, const char* why) {
  INFO(r.out);
  CHECK(r.code == 3);
  CHECK(r.out.find("frame_000000.png") != std::string::npos);
  CHECK(r.out.find(why) != std::string::npos);
  std::ifstream f(out + "/summary.json");
  REQUIRE(f.good());
  const auto summary = nlohmann::json::parse(f);
  CHECK(summary["error"].get<std::string>().find("writing frames") != std::string::npos);
  CHECK(summary["error"].get<std::string>().find(why) != std::string::npos);
  std::size_t frames = 0, temporaries = 0;
  for (const auto& e : std::filesystem::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    frames += name.rfind("frame_", 0) == 0;
    temporaries += name.rfind(".frame_", 0) == 0;
    if (name.rfind("frame_", 0) == 0) {  // a frame left must be whole: its IEND chunk at the end
      const std::string png = text_of(e.path().string());
      CHECK(png.size() > 12);
      CHECK(png.compare(png.size() - 8, 4, "IEND") == 0);
    }
  }
  CHECK(frames == 0);  // the first frame failed
  CHECK(temporaries == 0);
}

TEST_CASE("magsim-scene: a PNG frame that cannot be written is exit 3 with the error in summary.json, no truncated frame", "[reliability]") {
  const std::string two_balls = std::string(MAGSIM_SOURCE_DIR) + "/scenes/examples/two_balls.json";
  SECTION("a file size limit (ulimit -f): the 100 KB frame passes 50 KB, the 6 KB summary does not") {
    const std::string out = tmp("png_fsize");
    // 100 blocks of 512 bytes (dash); before: exit 2, no summary.json, a 51200-byte frame_000000.png
    const CommandResult r = magsim::test::run_command(std::string("ulimit -f 100; ") + MAGSIM_SCENE_BIN,
                                                      two_balls + " --steps 1 --threads 1 --out " + out);
    if (r.out.find("built without the renderer") != std::string::npos) return;
    check_png_write_failure(out, r, "File too large");
  }
  SECTION("a full disk: a 64 KiB tmpfs (needs root to mount: skipped elsewhere)") {
    const std::string dir = tmp("png_full");
    REQUIRE(std::system(("mkdir -p " + dir).c_str()) == 0);
    if (std::system(("mount -t tmpfs -o size=64k tmpfs " + dir + " 2>/dev/null").c_str()) != 0) {
      WARN("cannot mount a tmpfs here (not root?): the full-disk PNG case is skipped");
      return;
    }
    struct Unmount {  // also when a REQUIRE ends the section
      std::string dir;
      ~Unmount() { std::system(("umount " + dir).c_str()); }
    } unmount{dir};
    const CommandResult r = scene(two_balls + " --steps 1 --threads 1 --out " + dir);
    if (r.out.find("built without the renderer") == std::string::npos) check_png_write_failure(dir, r, "No space left on device");
  }
}

// ---- class 10: one range per option, shared by flag and scene file --------------------------

namespace {

// magsim-scene's exit for `args` (--write-scene: read and checked, never run)
int scene_exit(const std::string& args) { return scene(args).code; }

std::string g17(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

}  // namespace

TEST_CASE("one range per option: each flag and its scene-file key accept and refuse the same values at the bounds", "[reliability]") {
  const std::string two_balls = std::string(MAGSIM_SOURCE_DIR) + "/scenes/examples/two_balls.json";
  const std::string base = tmp("ranges_base.json"), file = tmp("ranges_file.json"), written = tmp("ranges_written.json"),
                    reread = tmp("ranges_reread.json");
  REQUIRE(scene_exit(two_balls + " --write-scene " + base) == 0);
  const nlohmann::json scene_json = nlohmann::json::parse(text_of(base));
  const double cores = std::max(1u, std::thread::hardware_concurrency());
  std::size_t checked = 0;
  for (const magsim::scenes::OptionRange& r : magsim::scenes::kOptionRanges) {
    std::vector<double> values;
    const double step = r.integer ? 1.0 : 0.0;
    auto below = [&](double x) { return r.integer ? x - step : std::nextafter(x, -DBL_MAX); };
    auto above = [&](double x) { return r.integer ? x + step : std::nextafter(x, DBL_MAX); };
    values = {r.lo, below(r.lo), above(r.lo)};
    if (r.hi != DBL_MAX) values.insert(values.end(), {r.hi, below(r.hi), above(r.hi)});
    for (const double v : values) {
      // the machine's cap on threads holds for flag and file alike
      const bool want = r.contains(v) && !(std::string(r.key) == "threads" && v > 4 * cores);
      const std::string text = r.integer ? std::to_string(static_cast<long long>(v)) : g17(v);
      const int flag = scene_exit(two_balls + " " + r.flag + " " + text + " --write-scene " + written);
      nlohmann::json j = scene_json;
      nlohmann::json* at = &j["options"];
      const std::string key = r.key;
      const std::size_t dot = key.find('.');
      if (dot != std::string::npos) at = &(*at)[key.substr(0, dot)];
      const std::string leaf = dot == std::string::npos ? key : key.substr(dot + 1);
      if (r.integer) (*at)[leaf] = static_cast<long long>(v);
      else (*at)[leaf] = v;
      write_text(file, j.dump(1));
      const int from_file = scene_exit(file + " --write-scene " + reread);
      INFO(r.flag << " " << text << " / options." << r.key << ": flag exit " << flag << ", file exit " << from_file
                  << ", range " << r.text());
      CHECK(flag == (want ? 0 : 1));
      CHECK(from_file == (want ? 0 : 1));
      // what the flag accepted, the scene file it wrote takes back
      if (flag == 0) CHECK(scene_exit(written + " --write-scene " + reread) == 0);
      ++checked;
    }
  }
  CHECK(checked >= 18 * 3);
}

TEST_CASE("summary.json's options, pasted into a scene file, are accepted and repeat the run", "[reliability]") {
  const std::string two_balls = std::string(MAGSIM_SOURCE_DIR) + "/scenes/examples/two_balls.json";
  // flags at the edges of their ranges: before, --tol 0.9999999 was taken by the flag and
  // refused in the file (0.999999 at most)
  const std::string flags = " --tol 0.9999999 --max-iter 1000000 --dt 0.0005 --softening 0.001 --quickstep-w 1.9 --threads 1"
                            " --steps 40 --no-render";
  const std::string out = tmp("options_first"), again = tmp("options_again"), file = tmp("options_scene.json");
  REQUIRE(scene_exit(two_balls + flags + " --out " + out) == 0);
  const auto first = nlohmann::json::parse(text_of(out + "/summary.json"));
  REQUIRE(scene_exit(two_balls + " --write-scene " + file) == 0);  // the scene without the flags
  auto j = nlohmann::json::parse(text_of(file));
  j["options"] = first["options"];
  write_text(file, j.dump(1));
  const CommandResult r = scene(file + " --steps 40 --no-render --out " + again);
  INFO(r.out);
  REQUIRE(r.code == 0);
  const auto second = nlohmann::json::parse(text_of(again + "/summary.json"));
  CHECK(second["options"] == first["options"]);
  CHECK(second["state_hash"] == first["state_hash"]);
}

TEST_CASE("both tools: a max_iter beyond its range is refused with the range, as a flag and in a scene file", "[reliability]") {
  // before: --method ours --max-iter 1000000000 ran one silent step of about 2.7 hours
  const CommandResult f = scene("balls_up --method ours --max-iter 1000000000 --steps 1 --no-render --out " + tmp("maxiter"));
  INFO(f.out);
  CHECK(f.code == 1);
  CHECK(f.out.find("--max-iter: must be an integer in [1, 1000000], got 1000000000") != std::string::npos);
  CHECK(lines(f.out) == 1);
  const std::string file = tmp("maxiter.json");
  write_text(file, R"({"options": {"magnetics": {"max_iter": 1000000000}}, "bodies": []})");
  const CommandResult s = scene(file + " --steps 1 --no-render --out " + tmp("maxiter_file"));
  INFO(s.out);
  CHECK(s.code == 1);
  CHECK(s.out.find("options.magnetics.max_iter: must be in [1, 1000000] (got 1000000000)") != std::string::npos);
  const CommandResult m = solve(example("touching_spheres.json") + " --max-iter 1000000000");
  INFO(m.out);
  CHECK(m.code == 1);
  CHECK(m.out.find("[1, 1000000]") != std::string::npos);
  CHECK(lines(m.out) == 1);
}

// ---- class 5: memory estimated up front ------------------------------------------------------

TEST_CASE("magsim-scene: a --count whose scene will not fit in memory is refused at once, exit 1, one line", "[reliability]") {
  // before: 1e8 balls climbed past 4 GB and ended in bad_alloc (exit 2)
  const CommandResult r = magsim::test::run_command(kAddressLimit + "timeout 60 " + MAGSIM_SCENE_BIN,
                                                    "balls_up --count 100000000 --steps 1 --no-render --out " + tmp("count_huge"));
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("balls_up --count 100000000: needs about") != std::string::npos);
  CHECK(r.out.find("GB of memory") != std::string::npos);
  CHECK(lines(r.out) == 1);
  CHECK(!std::ifstream(tmp("count_huge") + "/summary.json").good());  // refused before the folder is touched
  // --write-scene is refused the same way (it would build the scene)
  CHECK(scene("balls_up --count 100000000 --write-scene " + tmp("count_huge.json")).code == 1);
#if !defined(__SANITIZE_ADDRESS__)
  // an address-space limit counts too: 500000 balls (about 5 GB) under 1.5 GB
  const CommandResult v = magsim::test::run_command(kAddressLimit + MAGSIM_SCENE_BIN,
                                                    "balls_up --count 500000 --steps 1 --no-render --out " + tmp("count_as"));
  INFO(v.out);
  CHECK(v.code == 1);
  CHECK(v.out.find("the address-space limit") != std::string::npos);
#endif
}

// ---- class 4: parsing in linear time ------------------------------------------------------------

TEST_CASE("scene files: the SAX parser keeps array indices and duplicate keys over 160,000 bodies", "[reliability]") {
  // no timing check here (timings are benchmarks' business); the parser that replaced the
  // callback parser (quadratic in the body count) must still name the body of a duplicate key
  const std::string file = tmp("many_bodies.json");
  std::string text = "{\"bodies\": [";
  for (int i = 0; i < 160000; ++i) text += "{\"position\": [0, 0, 1]},";
  text += "{\"position\": [0, 0, 1], \"position\": [0, 0, 2]}]}";
  write_text(file, text);
  const CommandResult r = scene(file + " --steps 1 --no-render --out " + tmp("many_bodies"));
  INFO(r.out.substr(0, 300));
  CHECK(r.code == 1);
  CHECK(r.out.find("bodies[160000].position: duplicate key") != std::string::npos);
  CHECK(lines(r.out) == 1);
}
