// Tests for tools/bench/bench.cpp's --near-field-cost: both near fields are measured in one run
// and their ratio is written; the flag refuses --near-field beside it.
#include "tests/tools/cli/run_command.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>

namespace {

magsim::test::CommandResult run_bench(const std::string& args) {
  return magsim::test::run_command(BENCH_BIN, args);
}

}  // namespace

TEST_CASE("bench --near-field-cost: dipole and pair per scene in one run, and their ratio", "[tools]") {
  const std::string json_path = magsim::test::scratch("bench_cli_nfc") + "/nfc.json";
  const auto r = run_bench("--scenes balls_up --methods anderson --warmup 5 --steps 3 --scaling none "
                           "--threads 1 --near-field-cost --json " + json_path);
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::ifstream f(json_path);
  REQUIRE(f.good());
  const auto j = nlohmann::json::parse(f);
  REQUIRE(j["runs"].size() == 2);
  CHECK(j["runs"][0]["near_field"] == "dipole");
  CHECK(j["runs"][1]["near_field"] == "pair");
  const auto& q = j["near_field_cost"]["balls_up"]["anderson"];
  const double d = q["dipole_total_ms"].get<double>(), p = q["pair_total_ms"].get<double>();
  CHECK(d > 0);
  CHECK(p > 0);
  CHECK(q["pair_over_dipole"].get<double>() == Approx(p / d).epsilon(1e-12));
  CHECK(d == j["runs"][0]["timing_ms"]["total"]["median"].get<double>());
  CHECK(r.out.find("pair/dipole") != std::string::npos);
}

TEST_CASE("bench: --near-field-cost with --near-field is refused", "[tools]") {
  const auto r = run_bench("--near-field-cost --near-field pair --scaling none");
  CHECK(r.code == 2);
  CHECK(r.out.find("--near-field-cost") != std::string::npos);
}
