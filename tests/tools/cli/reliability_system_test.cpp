// tests/tools/cli/reliability_system_test.cpp — "never damage, never hang, never die on a
// signal": magsolve and magsim-scene against FIFOs and devices as input, deep or
// NUL-terminated JSON, closed pipes, full disks and file size limits, symlinks and
// FIFOs among the outputs, interrupting signals and a second run into a folder in use.
#include "tests/tools/cli/reliability.hpp"

#include <catch2/catch.hpp>

using namespace magsim::test::reliability;

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

TEST_CASE("MAGSIM_KERNEL: only auto, portable or generic is taken, anything else is refused in one line, exit 1", "[reliability]") {
  for (const char* value : {"Portable", "avx512", ""}) {
    for (const bool solver : {true, false}) {
      const std::string env = std::string("MAGSIM_KERNEL='") + value + "' ";
      const CommandResult r = solver ? magsim::test::run_command(env + MAGSOLVE_BIN, example("touching_spheres.json"))
                                     : magsim::test::run_command(env + MAGSIM_SCENE_BIN,
                                                                 "balls_up --count 5 --steps 1 --no-render --out " +
                                                                     tmp("kernel"));
      INFO((solver ? "magsolve" : "magsim-scene") << " MAGSIM_KERNEL='" << value << "': exit " << r.code << ": " << r.out);
      CHECK(r.code == 1);
      CHECK(r.out.find("MAGSIM_KERNEL='" + std::string(value) + "': must be auto, portable or generic") != std::string::npos);
      CHECK(lines(r.out) == 1);
    }
  }
  for (const char* value : {"auto", "portable", "generic"})
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
