// tools/cli/magsolve.cpp — the magnetics core as a command-line tool: solves one configuration
// of moments and prints, per moment, M, H, the Zeeman force and the classic force, plus the
// iterations taken, whether the dynamics converged and e_M against the ground truth (eq. 12).
//
// Exit codes (the same in magsim-scene): 0 done, 1 bad input or flags, 2 the solve failed
// (non-finite solution), 3 I/O error (the output could not be written).
#include "magnetics/curves.hpp"
#include "magnetics/forces.hpp"
#include "magnetics/ground_truth.hpp"
#include "scenes/json_reader.hpp"
#include "scenes/json_unique_keys.hpp"
#include "scenes/options_json.hpp"
#include "scenes/text_file.hpp"
#include "tools/cli/cli_common.hpp"
#include "tools/cli/option_flags.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <numeric>
#include <stdexcept>

using magsim::mag::Vec3;
namespace mag = magsim::mag;
using nlohmann::json;

namespace {

using magsim::tools::kBadInput;
using magsim::tools::kIoError;
using magsim::tools::kOk;
using magsim::tools::kRunFailed;
using magsim::tools::one_line;

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The case file, read with the scene files' checked reader (scenes/json_reader.hpp): every
// error is "<file>: <json path>: <what>". "magnetics" (optional) is a scene file's
// options.magnetics, read by the same from_json (scenes/options_json.hpp).
mag::MomentSet parse_moments(const magsim::scenes::JsonReader& r, const json& doc) {
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
  return set;
}

// Two moments closer than this fraction of the sum of their sizes are refused without
// --softening: the dipole sum grows as 1/r⁴ (two moments 1e-12 m apart gave F = 4e41 N), and
// closer than this the two spheres' centres lie inside each other.
constexpr double kMinSeparation = 0.5;

// A moment's size: the radius of the sphere of its volume.
double moment_radius(double volume) { return std::cbrt(3.0 * volume / (4.0 * 3.14159265358979323846)); }

// Refuses the first pair (in index order of the closer moment) closer than kMinSeparation ×
// (a_i + a_j). A sweep along x sorted, so 10^5 spread-out moments cost no 10^10 pairs.
void check_separations(const mag::MomentSet& set) {
  const std::size_t n = set.size();
  std::vector<double> a(n);
  double a_max = 0.0;
  for (std::size_t j = 0; j < n; ++j) a_max = std::max(a_max, a[j] = moment_radius(set.volume[j]));
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t p, std::size_t q) { return set.position[p].x() < set.position[q].x(); });
  std::size_t best_i = n, best_j = n;
  double best_d = 0.0, best_min = 0.0;
  for (std::size_t s = 0; s < n; ++s) {
    const std::size_t i = order[s];
    for (std::size_t t = s + 1; t < n; ++t) {
      const std::size_t j = order[t];
      if (set.position[j].x() - set.position[i].x() >= kMinSeparation * (a[i] + a_max)) break;
      const double d = (set.position[j] - set.position[i]).norm();
      const double dmin = kMinSeparation * (a[i] + a[j]);
      if (d >= dmin) continue;
      const std::size_t lo = std::min(i, j), hi = std::max(i, j);
      if (best_i == n || lo < best_i || (lo == best_i && hi < best_j)) {
        best_i = lo;
        best_j = hi;
        best_d = d;
        best_min = dmin;
      }
    }
  }
  if (best_i == n) return;
  char apart[64];
  if (best_d == 0.0)
    std::snprintf(apart, sizeof apart, "at the same point");
  else
    std::snprintf(apart, sizeof apart, "%.6g m apart", best_d);
  char msg[400];
  std::snprintf(msg, sizeof msg,
                "moments[%zu] and moments[%zu] are %s, closer than %.6g m = %g x the sum of "
                "their radii (%.6g + %.6g m, spheres of their volumes); the dipole field diverges "
                "there: give --softening EPS to allow it",
                best_i, best_j, apart, best_min, kMinSeparation, a[best_i], a[best_j]);
  throw InputError(msg);
}

json vec_json(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

// The Newton reference holds the dense 3N x 3N interaction matrix T, the Jacobian and its
// LU factors (N induced moments): three matrices of doubles. Above this bound magsolve
// refuses up front instead of dying in bad_alloc or paging for hours.
constexpr double kReferenceBytesMax = 2.0 * 1024 * 1024 * 1024;
double reference_bytes(std::size_t induced) {
  const double n3 = 3.0 * static_cast<double>(induced);
  return 3.0 * n3 * n3 * sizeof(double);
}

// from this many induced moments the Newton reference reports each step on stderr
constexpr std::size_t kProgressMoments = 500;

int run(int argc, char** argv) {
  CLI::App app{
      "magsolve — solve one configuration of induced and permanent magnetic moments.\n"
      "Prints per moment M (A/m), H (A/m), the Zeeman force F (eq. 4) and the classic force\n"
      "F_classic (eq. 13) in newtons, the force of --force-model with --near-field as F_model,\n"
      "the iterations taken, convergence, and e_M (eq. 12) against the Newton ground truth of\n"
      "the method's curve (eq. 10; eq. 7 for kim2018; --curve iron for anderson and exact)."};
  std::string path, format = "json", force_model_name = "classic";
  double residual_tol = 1e-3;
  // The magnetics flags are the table's (magsim-scene's spellings and ranges); magsolve's older
  // spellings stay as aliases. Its starting point is its own, not the engine's: one configuration
  // solved from scratch by the paper's method to 1e-6 within 999 sweeps; the case's
  // "magnetics", then the flags, override it.
  magsim::tools::OptionFlags::Offer offer;
  offer.keys = {"magnetics.method", "magnetics.dt", "magnetics.tol", "magnetics.max_iter",
                "magnetics.field.softening", "magnetics.field.near_field.model",
                "magnetics.field.near_field.mu_r", "magnetics.field.near_field.curve"};
  offer.older = {{"magnetics.dt", {"--dt"}}, {"magnetics.field.near_field.mu_r", {"--mu-r"}}};
  offer.defaults.magnetics.method = mag::Method::Ours;
  offer.defaults.magnetics.tol = 1e-6;
  offer.defaults.magnetics.max_iter = 999;
  offer.source = "the case's ";
  magsim::tools::OptionFlags flags;
  app.add_option("case", path,
                 "CASE.json: {\"external_field\": [Hx,Hy,Hz], \"moments\": [...], \"magnetics\": {...}} "
                 "(magnetics: a scene file's options.magnetics; the flags below override it)")
      ->required();
  flags.add(&app, "Options", offer);
  app.add_option("--residual-tol", residual_tol,
                 "\"converged\" needs the iteration to stop (--tol) and every induced moment's "
                 "|M - f(H)| <= this x max(|M|, |f(H)|)")
      ->check(magsim::tools::PositiveNumber)->capture_default_str();
  app.add_option("--force-model", force_model_name,
                 "the force printed as F_model: " + mag::kForceModelNames.list("|") +
                     " (method: the method's own pairing; classic is the engine's default, -grad U*)")
      ->capture_default_str();
  app.add_option("--format", format, "json|csv")->check(CLI::IsMember({"json", "csv"}))
      ->capture_default_str();
  app.footer(magsim::tools::exit_codes_footer(
      "bad input or flags", "the solve failed", "the output could not be written",
      "The Newton reference needs three dense 3N x 3N matrices for N induced moments; above 2 GiB "
      "(N > 3153) magsolve refuses the case (exit 1). So it does a CASE that is not a regular file "
      "or is larger than 1 GiB, and OMP_NUM_THREADS above 4 x the cores.\n" +
      std::string(magsim::tools::kMagsimKernelHelp)));
  if (const int code = magsim::tools::parse_command_line(app, argc, argv, "magsolve: "); code >= 0) return code;
  if (const std::string e = magsim::tools::omp_num_threads_error(); !e.empty()) {
    std::fprintf(stderr, "magsolve: %s\n", e.c_str());
    return kBadInput;
  }
  if (const std::string e = magsim::tools::magsim_kernel_error(); !e.empty()) {
    std::fprintf(stderr, "magsolve: %s\n", e.c_str());
    return kBadInput;
  }

  if (!std::isfinite(residual_tol)) {
    std::fprintf(stderr, "magsolve: --residual-tol: must be a finite number > 0\n");
    return kBadInput;
  }
  mag::DynamicsOptions opt = offer.defaults.magnetics;
  try {  // a name the table lacks is refused before the case is read
    mag::DynamicsOptions probe = opt;
    flags.apply(&probe);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "magsolve: %s\n", e.what());
    return kBadInput;
  }
  mag::ForceModel model_choice = mag::ForceModel::Classic;
  if (!mag::kForceModelNames.parse(force_model_name, &model_choice)) {
    std::fprintf(stderr, "magsolve: %s\n", mag::kForceModelNames.unknown("--force-model", force_model_name).c_str());
    return kBadInput;
  }
  mag::ForceModel force_model = model_choice;  // resolved below, once the method is known
  mag::MomentSet set;
  try {
    std::string text;
    try {
      text = magsim::scenes::read_text_file(path);  // regular files only, at most 1 GiB
    } catch (const magsim::scenes::InputFileError& e) {
      throw InputError(e.what());
    }
    json doc;
    try {
      doc = magsim::scenes::parse_unique_keys(text);
    } catch (const magsim::scenes::JsonStructureError& e) {  // a duplicate key, too deep, a NUL
      throw InputError(e.what());
    } catch (const json::exception& e) {  // syntax errors and numbers out of range
      throw InputError(std::string("malformed JSON: ") + e.what());
    }
    const magsim::scenes::JsonReader r(path);
    r.keys(doc, "", {"external_field", "moments", "magnetics"});
    if (doc.contains("magnetics")) magsim::scenes::from_json(r, doc["magnetics"], "magnetics", &opt);
    flags.apply(&opt);  // flags given on the command line override the case's "magnetics"
    force_model = mag::resolve_force_model(model_choice, opt.method);
    if (const std::string e = mag::validate(opt); !e.empty()) {
      std::fprintf(stderr, "magsolve: %s\n", e.c_str());
      return kBadInput;
    }
    if (opt.field.near_field.model == mag::NearField::Pair && force_model != mag::ForceModel::Classic) {
      std::fprintf(stderr, "magsolve: --near-field pair needs --force-model classic (got %s): the pair "
                           "model corrects U*, whose gradient is the classic force\n",
                   mag::kForceModelNames.name(force_model));
      return kBadInput;
    }
    set = parse_moments(r, doc);
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
    if (opt.field.softening == 0.0) check_separations(set);
  } catch (const InputError& e) {
    std::fprintf(stderr, "magsolve: %s: %s\n", one_line(path).c_str(), one_line(e.what()).c_str());
    return kBadInput;
  } catch (const std::runtime_error& e) {  // JsonReader: "<file>: <json path>: <what>"
    std::fprintf(stderr, "magsolve: %s\n", one_line(e.what()).c_str());
    return kBadInput;
  }

  // ground truth of the method's curve
  const mag::Curve curve = mag::curve_of(opt);
  mag::MomentSet gt = set;
  // long solves say what they are doing: the Newton reference factors a dense 3N x 3N
  // matrix per step (N = 3153: ~9 GB of arithmetic per step), on stderr
  std::size_t n_induced = 0;
  for (std::size_t j = 0; j < set.size(); ++j) n_induced += set.kind[j] == mag::MomentKind::Induced;
  const bool progress = n_induced >= kProgressMoments;
  const auto tr = std::chrono::steady_clock::now();
  if (progress)
    std::fprintf(stderr, "magsolve: Newton reference for %zu induced moments (dense %zux%zu, %.2f GiB)...\n",
                 n_induced, 3 * n_induced, 3 * n_induced, reference_bytes(n_induced) / (1 << 30));
  const mag::ExactStats gts = mag::solve_exact(
      &gt, curve, opt.field, 1e-12, 60, [&](int step, double residual) {
        if (!progress) return;
        std::fprintf(stderr, "magsolve: Newton reference step %d, relative residual %.3g, %.1f s\n", step,
                     residual, std::chrono::duration<double>(std::chrono::steady_clock::now() - tr).count());
      });

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
  std::vector<Vec3> F, tau, Fc, Fm, taum;
  mag::compute_forces(set, force_model, curve, opt.field, &ws, &Fm, &taum);
  mag::compute_forces(set, mag::ForceModel::Zeeman, curve, opt.field, &ws, &F, &tau, &Fc);
  const double eM = mag::magnetization_error(set, gt.M);

  // nothing non-finite is printed (JSON would show null) or passes as success: name the first
  // moment and quantity that is not finite
  for (std::size_t j = 0; j < set.size(); ++j) {
    const char* what = !set.M[j].allFinite()  ? "magnetization M"
                       : !ws.H[j].allFinite() ? "field H"
                       : !F[j].allFinite()    ? "force F"
                       : !Fc[j].allFinite()   ? "classic force F_classic"
                       : !Fm[j].allFinite()   ? "model force F_model"
                       : !tau[j].allFinite()  ? "torque"
                                              : nullptr;
    if (what) {
      std::fprintf(stderr, "magsolve: %s: the %s of moments[%zu] is not finite (the moments too close "
                           "or too strong? try --softening); nothing printed\n", path.c_str(), what, j);
      return kRunFailed;
    }
  }
  if (!std::isfinite(eM)) {
    std::fprintf(stderr, "magsolve: %s: e_M against the Newton reference is not finite (the reference "
                         "failed: residual %g); nothing printed\n", path.c_str(), gts.residual);
    return kRunFailed;
  }

  // Honest convergence. The dynamics stop when M changes by less than --tol x Ms in one
  // iteration; in a weak field (|H| << Ms) that happens long before M reaches f(H) (a 1 A/m
  // field: M = 2.16 A/m, "converged" after 4 iterations, e_M = 0.30). So "converged" also
  // asks the fixed point itself: every induced moment's |M − f(H)| at most
  // --residual-tol x max(|M|, |f(H)|) — M along H and at the curve's magnitude.
  double residual = 0.0;
  std::size_t worst = 0;
  for (std::size_t j = 0; j < set.size(); ++j) {
    if (set.kind[j] != mag::MomentKind::Induced) continue;
    const Vec3 f = mag::curve_M(curve, ws.H[j], set.Ms[j]);
    const double scale = std::max(f.norm(), set.M[j].norm());
    const double r = scale > 0 ? (set.M[j] - f).norm() / scale : 0.0;
    if (r > residual) {
      residual = r;
      worst = j;
    }
  }
  const bool stopped = converged;  // the iteration's own criterion was met
  converged = stopped && residual <= residual_tol;
  if (stopped && !converged)
    std::fprintf(stderr, "magsolve: note: the iteration stopped (change below --tol) but M is not yet "
                         "f(H): relative residual %.3g at moments[%zu] > --residual-tol %g; "
                         "\"converged\": false\n", residual, worst, residual_tol);

  errno = 0;  // the cause of a failed write below
  if (format == "json") {
    json out;
    out["method"] = mag::method_name(opt.method);
    out["iterations"] = iterations;
    out["converged"] = converged;
    out["criterion_met"] = stopped;
    out["residual"] = {{"max", residual}, {"moment", worst}, {"tol", residual_tol}};
    out["e_M"] = eM;
    out["force_model"] = mag::kForceModelNames.name(force_model);
    out["near_field"] = mag::kNearFieldNames.name(opt.field.near_field.model);
    if (opt.field.near_field.model == mag::NearField::Pair) out["mu_r"] = opt.field.near_field.mu_r;
    out["wall_ms"] = wall_ms;
    out["ground_truth"] = {{"curve", std::string(mag::kCurveNames.name(curve)) +
                                                     (curve == mag::Curve::Tanh ? " (eq. 10)" : curve == mag::Curve::Kim ? " (eq. 7)" : " (a bulk-iron sphere)")},
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
                {"F_classic", vec_json(Fc[j])},
                {"F_model", vec_json(Fm[j])}};
      if (!ind) {
        m["torque"] = vec_json(tau[j]);
        m["torque_model"] = vec_json(taum[j]);
      }
      out["moments"].push_back(m);
    }
    std::cout << out.dump(2) << "\n";
  } else {
    std::printf("# method=%s iterations=%d converged=%s criterion_met=%s residual=%.6e e_M=%.6e\n",
                mag::method_name(opt.method), iterations, converged ? "true" : "false",
                stopped ? "true" : "false", residual, eM);
    std::printf("index,kind,Mx,My,Mz,Hx,Hy,Hz,Fx,Fy,Fz,Fcx,Fcy,Fcz,Fmx,Fmy,Fmz\n");
    for (std::size_t j = 0; j < set.size(); ++j) {
      const Vec3 &M = set.M[j], &H = ws.H[j];
      std::printf("%zu,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
                  "%.17g,%.17g,%.17g\n",
                  j, set.kind[j] == mag::MomentKind::Induced ? "induced" : "permanent", M.x(),
                  M.y(), M.z(), H.x(), H.y(), H.z(), F[j].x(), F[j].y(), F[j].z(), Fc[j].x(),
                  Fc[j].y(), Fc[j].z(), Fm[j].x(), Fm[j].y(), Fm[j].z());
    }
  }
  // a full disk or a closed pipe (EPIPE: SIGPIPE is ignored) must not pass as success
  return magsim::tools::stdout_written("magsolve: ", "the results") ? kOk : kIoError;
}

}  // namespace

// Anything not caught above (e.g. std::bad_alloc) ends in one line and exit 2, not abort().
int main(int argc, char** argv) {
  magsim::tools::ignore_write_signals();
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "magsolve: error: %s\n", one_line(e.what()).c_str());
    return kRunFailed;
  }
}
