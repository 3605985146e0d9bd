// Tests for tools/cli/magsolve.cpp: the command line on good and bad input.
#include "tests/tools/cli/run_command.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <string>

namespace {

using Result = magsim::test::CommandResult;

Result run(const std::string& args) { return magsim::test::run_command(MAGSOLVE_BIN, args); }

std::string write_tmp(const std::string& name, const std::string& text) {
  const std::string path = magsim::test::scratch("magsolve_" + name);
  std::ofstream(path) << text;
  return path;
}

const char* kBall = R"({"position": [0, 0, 0], "volume": 5e-7, "Ms": 1.6e6, "kind": "induced"})";

}  // namespace

TEST_CASE("magsolve solves two touching spheres: 4/3 of the isolated moment", "[tools]") {
  const Result r = run(std::string(MAGSIM_SOURCE_DIR) +
                       "/tools/examples/touching_spheres.json --method exact");
  REQUIRE(r.code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["method"] == "exact");
  CHECK(j["converged"] == true);
  REQUIRE(j["moments"].size() == 2);
  CHECK(j["moments"][0]["M"][2].get<double>() == Approx(4000.0).epsilon(1e-5));
  for (const char* key : {"M", "H", "F", "F_classic"}) CHECK(j["moments"][1].contains(key));
}

TEST_CASE("magsolve: ours converges on the strong cluster, CSV output has a row per moment",
          "[tools]") {
  const Result r = run(std::string(MAGSIM_SOURCE_DIR) +
                       "/tools/examples/cluster_strong.json --method ours --format csv");
  REQUIRE(r.code == 0);
  CHECK(r.out.find("converged=true") != std::string::npos);
  std::size_t rows = 0;
  for (char c : r.out) rows += c == '\n';
  CHECK(rows == 2 + 37);  // comment, header, 36 balls + 1 magnet
}

TEST_CASE("magsolve rejects bad input with a one-line error and a non-zero exit", "[tools]") {
  struct Case {
    const char* name;
    std::string text;
    const char* expect;  // a piece of the message
  };
  const std::string b = kBall;
  const Case cases[] = {
      {"malformed", "{\"moments\": [", "malformed JSON"},
      {"missing_moments", "{}", "moments: missing"},
      {"missing_position",
       R"({"moments": [{"volume": 1e-6, "Ms": 1e6, "kind": "induced"}]})", "position"},
      {"nonfinite", R"({"moments": [{"position": [0, 0, 1e999], "volume": 1e-6, "Ms": 1e6, "kind": "induced"}]})",
       "overflow"},
      {"negative_volume",
       R"({"moments": [{"position": [0, 0, 0], "volume": -1e-6, "Ms": 1e6, "kind": "induced"}]})",
       "volume"},
      {"same_point", "{\"moments\": [" + b + "," + b + "]}", "same point"},
      {"bad_kind", R"({"moments": [{"position": [0, 0, 0], "volume": 1e-6, "kind": "soft"}]})",
       "kind"},
      {"unknown_key", R"({"moments": [], "extra": 1})", "unknown key"},
  };
  for (const Case& c : cases) {
    const Result r = run(write_tmp(c.name, c.text));
    INFO(c.name << ": exit " << r.code << ", said: " << r.out);
    CHECK(r.code != 0);
    CHECK(r.out.find(c.expect) != std::string::npos);
    CHECK(r.out.find("nan") == std::string::npos);
  }
  CHECK(run("/nonexistent/case.json").code != 0);
  const Result nope = run(write_tmp("ok", "{\"moments\": [" + std::string(kBall) + "]}") + " --method nope");
  CHECK(nope.code != 0);
  CHECK(nope.out.find("unknown method 'nope' (ours, ours-realigned, kim2018, damping-llg, exact, anderson)") !=
        std::string::npos);
  CHECK(run(write_tmp("ok2", "{\"moments\": [" + std::string(kBall) + "]}") + " --dt 1").code != 0);
  // the same point is fine with softening
  CHECK(run(write_tmp("soft", "{\"moments\": [" + b + "," + b + "]}") + " --softening 0.001")
            .code == 0);
}

TEST_CASE("magsolve: the case's \"magnetics\" is a scene file's options.magnetics, and flags override it", "[tools]") {
  const std::string two = std::string("{\"external_field\": [0, 0, 1000], \"moments\": [") + kBall +
                          R"(, {"position": [0, 0, 0.0101], "volume": 5e-7, "Ms": 1.6e6, "kind": "induced"}],)";
  const std::string path = write_tmp("magnetics", two + R"( "magnetics": {"max_iter": 2, "tol": 1e-12}})");
  const Result r = run(path + " --method ours");
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(nlohmann::json::parse(r.out)["iterations"] == 2);
  const Result o = run(path + " --method ours --max-iter 3");
  REQUIRE(o.code == 0);
  CHECK(nlohmann::json::parse(o.out)["iterations"] == 3);
  const Result bad = run(write_tmp("magnetics_bad", two + R"( "magnetics": {"dt_m": 1e-7}})"));
  CHECK(bad.code == 1);
  CHECK(bad.out.find("magnetics.dt_m: unknown key") != std::string::npos);
}
