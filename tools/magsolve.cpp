// tools/magsolve.cpp — the magnetics core as a command-line tool: solves one configuration
// of moments and prints, per moment, M, H, the Zeeman force and the classic force, plus the
// iterations taken, whether the dynamics converged and e_M against the ground truth (eq. 12).
//
// Exit codes (the same in magsim-scene): 0 done, 1 bad input or flags, 2 the solve failed
// (non-finite solution), 3 I/O error (the output could not be written).
#include "magnetics/forces.hpp"
#include "magnetics/ground_truth.hpp"
#include "scenes/json_reader.hpp"
#include "scenes/json_unique_keys.hpp"
#include "scenes/options_json.hpp"
#include "tools/cli_common.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

using magsim::mag::Vec3;
namespace mag = magsim::mag;
using nlohmann::json;

namespace {

using magsim::tools::kBadInput;
using magsim::tools::kIoError;
using magsim::tools::kOk;
using magsim::tools::kRunFailed;

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The case file, read with the scene files' checked reader (scenes/json_reader.hpp): every
// error is "<file>: <json path>: <what>". "magnetics" (optional) is a scene file's
// options.magnetics, read by the same from_json (scenes/options_json.hpp).
mag::MomentSet parse_moments(const magsim::scenes::JsonReader& r, const json& doc, double softening) {
  mag::MomentSet set;
  if (doc.contains("external_field")) set.H0 = r.vec3(doc["external_field"], "external_field");
  if (!doc.contains("moments")) r.fail("moments", "missing (a non-empty array of moments)");
  const json& ms = doc["moments"];
  if (!ms.is_array() || ms.empty()) r.fail("moments", "must be a non-empty array");
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const std::string w = magsim::scenes::JsonReader::index("moments", i);
    const json& m = ms[i];
    r.object(m, w);
    if (!m.contains("kind") || !m["kind"].is_string()) r.fail(w + ".kind", "missing (\"induced\" or \"permanent\")");
    const std::string kind = m["kind"].get<std::string>();
    if (!m.contains("position")) r.fail(w + ".position", "missing");
    const Vec3 p = r.vec3(m["position"], w + ".position");
    if (!m.contains("volume")) r.fail(w + ".volume", "missing");
    const double V = r.positive(m["volume"], w + ".volume");
    if (kind == "induced") {
      r.keys(m, w, {"position", "volume", "Ms", "kind"});
      if (!m.contains("Ms")) r.fail(w + ".Ms", "missing");
      set.add_induced(p, V, r.positive(m["Ms"], w + ".Ms"));
    } else if (kind == "permanent") {
      r.keys(m, w, {"position", "volume", "moment", "kind"});
      if (!m.contains("moment")) r.fail(w + ".moment", "missing");
      set.add_permanent(p, V, r.vec3(m["moment"], w + ".moment"));
    } else {
      r.fail(w + ".kind", "must be \"induced\" or \"permanent\", got \"" + kind + "\"");
    }
  }
  if (softening == 0.0) {
    for (std::size_t i = 0; i < set.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (set.position[i] == set.position[j])
          r.fail("", "moments[" + std::to_string(j) + "] and moments[" + std::to_string(i) +
                         "] are at the same point; give --softening EPS to allow it");
  }
  return set;
}

json vec_json(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

// The whole file as text. A directory opens as an ifstream on Linux and throws
// std::ios_failure on the first read, so it is refused by name first.
std::string read_text(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError("is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot read file");
  std::ostringstream text;
  try {
    text << in.rdbuf();
  } catch (const std::exception& e) {
    throw InputError(std::string("cannot read file (") + e.what() + ")");
  }
  if (in.bad()) throw InputError("cannot read file");
  return text.str();
}

// The Newton reference holds the dense 3N x 3N interaction matrix T, the Jacobian and its
// LU factors (N induced moments): three matrices of doubles. Above this bound magsolve
// refuses up front instead of dying in bad_alloc or paging for hours.
constexpr double kReferenceBytesMax = 2.0 * 1024 * 1024 * 1024;
double reference_bytes(std::size_t induced) {
  const double n3 = 3.0 * static_cast<double>(induced);
  return 3.0 * n3 * n3 * sizeof(double);
}

int run(int argc, char** argv) {
  CLI::App app{
      "magsolve — solve one configuration of induced and permanent magnetic moments.\n"
      "Prints per moment M (A/m), H (A/m), the Zeeman force F (eq. 4) and the classic force\n"
      "F_classic (eq. 13) in newtons, the iterations taken, convergence, and e_M (eq. 12)\n"
      "against the Newton ground truth of the method's curve (eq. 10; eq. 7 for kim2018)."};
  std::string path, method_name = "ours", format = "json";
  double dt = 100e-9, tol = 1e-6, softening = 0.0;
  int max_iter = 999;
  app.add_option("case", path,
                 "CASE.json: {\"external_field\": [Hx,Hy,Hz], \"moments\": [...], \"magnetics\": {...}} "
                 "(magnetics: a scene file's options.magnetics; the flags below override it)")
      ->required();
  app.add_option("--method", method_name, magsim::scenes::method_list("|"))->capture_default_str();
  app.add_option("--dt", dt, "magnetization step Δt_m in seconds, [1e-9, 1e-6]")
      ->capture_default_str();
  app.add_option("--tol", tol, "converged when every |ΔM|/Ms < tol in one iteration")
      ->capture_default_str();
  app.add_option("--max-iter", max_iter, "iteration cap")->capture_default_str();
  app.add_option("--softening", softening, "softening length ε in metres (0 = off)")
      ->capture_default_str();
  app.add_option("--format", format, "json|csv")->check(CLI::IsMember({"json", "csv"}))
      ->capture_default_str();
  app.footer(magsim::tools::exit_codes_footer(
      "bad input or flags", "the solve failed", "the output could not be written",
      "The Newton reference needs three dense 3N x 3N matrices for N induced moments; above 2 GiB "
      "(N > 3153) magsolve refuses the case (exit 1)."));
  if (const int code = magsim::tools::parse_command_line(app, argc, argv); code >= 0) return code;

  mag::DynamicsOptions opt;
  if (!mag::parse_method(method_name, &opt.method)) {
    std::fprintf(stderr, "magsolve: unknown method '%s' (%s)\n", method_name.c_str(),
                 magsim::scenes::method_list().c_str());
    return kBadInput;
  }
  mag::MomentSet set;
  try {
    const std::string text = read_text(path);
    json doc;
    try {
      doc = magsim::scenes::parse_unique_keys(text);
    } catch (const magsim::scenes::DuplicateKeyError& e) {
      throw InputError(e.what());
    } catch (const json::exception& e) {  // syntax errors and numbers out of range
      throw InputError(std::string("malformed JSON: ") + e.what());
    }
    const magsim::scenes::JsonReader r(path);
    r.keys(doc, "", {"external_field", "moments", "magnetics"});
    if (doc.contains("magnetics")) magsim::scenes::from_json(r, doc["magnetics"], "magnetics", &opt);
    // flags given on the command line override the case's "magnetics"
    if (app.count("--dt")) opt.dt = dt;
    if (app.count("--tol")) opt.tol = tol;
    if (app.count("--max-iter")) opt.max_iter = max_iter;
    if (app.count("--softening")) opt.field.softening = softening;
    if (const std::string e = mag::validate(opt); !e.empty()) {
      std::fprintf(stderr, "magsolve: %s\n", e.c_str());
      return kBadInput;
    }
    set = parse_moments(r, doc, opt.field.softening);
    std::size_t induced = 0;
    for (std::size_t j = 0; j < set.size(); ++j) induced += set.kind[j] == mag::MomentKind::Induced;
    if (reference_bytes(induced) > kReferenceBytesMax) {
      char msg[256];
      std::snprintf(msg, sizeof msg,
                    "%zu induced moments: the Newton reference needs three dense %zux%zu matrices "
                    "(%.1f GiB), more than the %.0f GiB bound; use at most %zu induced moments",
                    induced, 3 * induced, 3 * induced, reference_bytes(induced) / (1 << 30),
                    kReferenceBytesMax / (1 << 30),
                    static_cast<std::size_t>(std::sqrt(kReferenceBytesMax / (3.0 * 9 * sizeof(double)))));
      throw InputError(msg);
    }
  } catch (const InputError& e) {
    std::fprintf(stderr, "magsolve: %s: %s\n", path.c_str(), e.what());
    return kBadInput;
  } catch (const std::runtime_error& e) {  // JsonReader: "<file>: <json path>: <what>"
    std::fprintf(stderr, "magsolve: %s\n", e.what());
    return kBadInput;
  }

  // ground truth of the method's curve
  const mag::Curve curve = mag::curve_of(opt.method);
  mag::MomentSet gt = set;
  const mag::ExactStats gts = mag::solve_exact(&gt, curve, opt.field);

  const auto t0 = std::chrono::steady_clock::now();
  int iterations = 0;
  bool converged = false;
  mag::MagWorkspace ws;
  if (opt.method == mag::Method::Exact) {
    set = gt;
    iterations = gts.newton_steps;
    converged = gts.converged;
  } else {
    const mag::RelaxStats st = mag::relax_magnetization(&set, opt, &ws);
    iterations = st.iterations;
    converged = st.converged;
  }
  const double wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::vector<Vec3> F, tau, Fc;
  mag::compute_forces(set, mag::ForceModel::Zeeman, curve, opt.field, &ws, &F, &tau, &Fc);
  const double eM = mag::magnetization_error(set, gt.M);

  bool finite = true;
  for (std::size_t j = 0; j < set.size(); ++j)
    finite = finite && set.M[j].allFinite() && ws.H[j].allFinite() && F[j].allFinite() &&
             Fc[j].allFinite();
  if (!finite) {
    std::fprintf(stderr, "magsolve: %s: the solution is not finite (moments too close? try "
                         "--softening)\n", path.c_str());
    return kRunFailed;
  }

  if (format == "json") {
    json out;
    out["method"] = mag::method_name(opt.method);
    out["iterations"] = iterations;
    out["converged"] = converged;
    out["e_M"] = eM;
    out["wall_ms"] = wall_ms;
    out["ground_truth"] = {{"curve", curve == mag::Curve::Tanh ? "tanh (eq. 10)" : "kim (eq. 7)"},
                           {"newton_steps", gts.newton_steps},
                           {"residual", gts.residual},
                           {"converged", gts.converged}};
    out["moments"] = json::array();
    for (std::size_t j = 0; j < set.size(); ++j) {
      const bool ind = set.kind[j] == mag::MomentKind::Induced;
      json m = {{"kind", ind ? "induced" : "permanent"},
                {"M", vec_json(set.M[j])},
                {"H", vec_json(ws.H[j])},
                {"F", vec_json(F[j])},
                {"F_classic", vec_json(Fc[j])}};
      if (!ind) m["torque"] = vec_json(tau[j]);
      out["moments"].push_back(m);
    }
    std::cout << out.dump(2) << "\n";
  } else {
    std::printf("# method=%s iterations=%d converged=%s e_M=%.6e\n", mag::method_name(opt.method),
                iterations, converged ? "true" : "false", eM);
    std::printf("index,kind,Mx,My,Mz,Hx,Hy,Hz,Fx,Fy,Fz,Fcx,Fcy,Fcz\n");
    for (std::size_t j = 0; j < set.size(); ++j) {
      const Vec3 &M = set.M[j], &H = ws.H[j];
      std::printf("%zu,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                  j, set.kind[j] == mag::MomentKind::Induced ? "induced" : "permanent", M.x(),
                  M.y(), M.z(), H.x(), H.y(), H.z(), F[j].x(), F[j].y(), F[j].z(), Fc[j].x(),
                  Fc[j].y(), Fc[j].z());
    }
  }
  // a full disk or a closed pipe must not pass as success: flush and check both streams
  std::cout.flush();
  const bool written = std::cout.good() && std::fflush(stdout) == 0 && !std::ferror(stdout);
  if (!written) {
    std::fprintf(stderr, "magsolve: writing the results to stdout failed (%s)\n",
                 errno ? std::strerror(errno) : "stream error");
    return kIoError;
  }
  return kOk;
}

}  // namespace

// Anything not caught above (e.g. std::bad_alloc) ends in one line and exit 2, not abort().
int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "magsolve: error: %s\n", e.what());
    return kRunFailed;
  }
}
