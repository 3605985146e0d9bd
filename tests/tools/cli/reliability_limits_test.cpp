// tests/tools/cli/reliability_limits_test.cpp — limits checked up front: one range per
// option shared by flag and scene file (and summary.json's options accepted back), the
// memory a --count needs, and scene files parsed in linear time.
#include "tests/tools/cli/reliability.hpp"
#include "engine/options_table.hpp"

#include <catch2/catch.hpp>

using namespace magsim::test::reliability;

// ---- one range per option, shared by flag and scene file ------------------------------------

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
  for (const magsim::engine::OptionSpec& spec : magsim::engine::options_table()) {
    const bool number = spec.kind == magsim::engine::OptionKind::Number || spec.kind == magsim::engine::OptionKind::Integer;
    if (spec.flag.empty() || !number) continue;
    const magsim::engine::OptionRange& r = spec.range;
    std::vector<double> values;
    const double step = r.integer ? 1.0 : 0.0;
    auto below = [&](double x) { return r.integer ? x - step : std::nextafter(x, -DBL_MAX); };
    auto above = [&](double x) { return r.integer ? x + step : std::nextafter(x, DBL_MAX); };
    values = {r.lo, below(r.lo), above(r.lo)};
    if (r.hi != DBL_MAX) values.insert(values.end(), {r.hi, below(r.hi), above(r.hi)});
    for (const double v : values) {
      // the machine's cap on threads holds for flag and file alike
      const bool want = r.contains(v) && !(spec.key == "threads" && v > 4 * cores);
      const std::string text = r.integer ? std::to_string(static_cast<long long>(v)) : g17(v);
      const int flag = scene_exit(two_balls + " " + spec.flag + " " + text + " --write-scene " + written);
      nlohmann::json j = scene_json;
      nlohmann::json* at = &j["options"];
      std::string key = spec.key;  // "magnetics.field.bh_theta": down the objects to the leaf
      for (std::size_t dot; (dot = key.find('.')) != std::string::npos; key.erase(0, dot + 1))
        at = &(*at)[key.substr(0, dot)];
      if (r.integer) (*at)[key] = static_cast<long long>(v);
      else (*at)[key] = v;
      write_text(file, j.dump(1));
      const int from_file = scene_exit(file + " --write-scene " + reread);
      INFO(spec.flag << " " << text << " / options." << spec.key << ": flag exit " << flag << ", file exit " << from_file
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

// ---- memory estimated up front ---------------------------------------------------------------

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

// ---- parsing in linear time ------------------------------------------------------------------

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
