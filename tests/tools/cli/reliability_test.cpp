// tests/tools/cli/reliability_test.cpp — "never a crash, never a silent success":
// inputs that used to abort, segfault, run out of memory or exit 0 with nothing useful
// done now end in a one-line error and the documented exit code (0 done, 1 bad input or
// flags, 2 run failed, 3 I/O error).
//
// This file: one-line errors and exit codes for bad input, bad flags and failed runs.
// The others: reliability_system_test.cpp (FIFOs, signals, full disks, pipes, resource
// limits) and reliability_limits_test.cpp (option ranges, memory, parsing time).
#include "tests/tools/cli/reliability.hpp"

#include <catch2/catch.hpp>

using namespace magsim::test::reliability;

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
