// engine/options_table.cpp — the table of run options (options_table.hpp). An option is one
// entry here: MEMBER(path) names the member and makes its path the scene-file key, so the two
// cannot drift apart. The value after it is the option's one default: the member's initialiser
// (scene_desc.hpp, magnetization_types.hpp, fields.hpp, near_field.hpp) must equal it, which
// tests/engine/options_table_test.cpp checks for every entry. Ranges are those the scene file
// has always taken; each lies within mag::validate's (tests/engine/options_table_test.cpp).
#include "engine/options_table.hpp"

#include "engine/limits.hpp"

#include <algorithm>
#include <cstdlib>
#include <set>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace magsim::engine {

// A member added to one of the three structs must be declared in the table below; then
// update the size here (x86-64, GCC/Clang).
static_assert(sizeof(mag::FieldOptions) == 72, "FieldOptions changed: declare the new member in options_table()");
static_assert(sizeof(mag::DynamicsOptions) == 176, "DynamicsOptions changed: declare the new member in options_table()");
static_assert(sizeof(SimOptions) == 440, "SimOptions changed: declare the new member in options_table()");

std::string number_text(double x) {
  char b[40];
  if (x == std::floor(x) && std::abs(x) < 1e5) {  // 1000, not 1e3
    std::snprintf(b, sizeof b, "%.0f", x);
    return b;
  }
  for (int p = 1; p <= 17; ++p) {
    std::snprintf(b, sizeof b, "%.*g", p, x);
    if (std::strtod(b, nullptr) == x) break;
  }
  std::string s = b;
  const std::size_t e = s.find('e');
  if (e == std::string::npos) return s;
  std::string exp = s.substr(e + 1);
  const bool neg = exp[0] == '-';
  if (exp[0] == '-' || exp[0] == '+') exp.erase(0, 1);
  exp.erase(0, std::min(exp.find_first_not_of('0'), exp.size() - 1));
  return s.substr(0, e + 1) + (neg ? "-" : "") + exp;
}

std::string value_text(const OptionValue& v, OptionKind kind) {
  switch (kind) {
    case OptionKind::Number: return number_text(std::get<double>(v));
    case OptionKind::Integer: return std::to_string(static_cast<long long>(std::get<double>(v)));
    case OptionKind::Bool: return std::get<bool>(v) ? "true" : "false";
    case OptionKind::Name: return "\"" + std::get<std::string>(v) + "\"";
    case OptionKind::Vector: {
      const Vec3& x = std::get<Vec3>(v);
      return "[" + number_text(x.x()) + ", " + number_text(x.y()) + ", " + number_text(x.z()) + "]";
    }
  }
  return {};
}

OptionValue OptionSpec::parse(const std::string& text) const {
  switch (kind) {
    case OptionKind::Number:
    case OptionKind::Integer: {
      char* end = nullptr;
      const double x = std::strtod(text.c_str(), &end);
      if (text.empty() || *end != '\0') throw std::invalid_argument("expected a number, got '" + text + "'");
      return x;
    }
    case OptionKind::Bool:
      if (text == "on" || text == "true") return true;
      if (text == "off" || text == "false") return false;
      throw std::invalid_argument("expected on or off, got '" + text + "'");
    case OptionKind::Name: return text;
    case OptionKind::Vector: break;
  }
  throw std::invalid_argument("a vector has no one-word form");
}

std::string OptionSpec::assign(SimOptions& o, const std::string& text) const {
  OptionValue v;
  try {
    v = parse(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  if (std::string e = error(v); !e.empty()) return e;
  set(o, v);
  return {};
}

std::string OptionSpec::error(const OptionValue& v) const {
  switch (kind) {
    case OptionKind::Number:
    case OptionKind::Integer: return range.error(std::get<double>(v));
    case OptionKind::Bool: return {};
    case OptionKind::Name: {
      const std::string& s = std::get<std::string>(v);
      std::string list;
      for (const std::string& n : names) {
        if (n == s) return {};
        list += (list.empty() ? "" : ", ") + n;
      }
      return "unknown " + what + " '" + s + "' (" + list + ")";
    }
    case OptionKind::Vector: {
      const Vec3& x = std::get<Vec3>(v);
      auto fmt = [](double d) {
        std::ostringstream s;
        s << d;
        return s.str();
      };
      if (!x.allFinite()) return "must be finite (got [" + fmt(x.x()) + ", " + fmt(x.y()) + ", " + fmt(x.z()) + "])";
      if (x.stableNorm() > range.hi)  // limits.hpp: the scene file's wording
        return "magnitude " + fmt(x.stableNorm()) + " " + unit + " exceeds " + fmt(range.hi) + " " + unit +
               " (engine/limits.hpp: beyond it the rigid-body or magnetics arithmetic overflows)";
      return {};
    }
  }
  return {};
}

std::string OptionSpec::values_text() const {
  switch (kind) {
    case OptionKind::Number:
    case OptionKind::Integer: return range.what();
    case OptionKind::Bool: return "true or false";
    case OptionKind::Name: {
      std::string s;
      for (const std::string& n : names) s += (s.empty() ? "" : ", ") + ("\"" + n + "\"");
      return s;
    }
    case OptionKind::Vector: return "[x, y, z] of length <= " + number_text(range.hi);
  }
  return {};
}

namespace {

// ---- how the entries below are written -------------------------------------------------------

// MEMBER(magnetics.field.bh_theta): the key "magnetics.field.bh_theta" and its accessor
#define MEMBER(path) #path, [](auto& o) -> auto& { return o.path; }

// ranges: [lo, hi]; (lo, hi]; (lo, hi); >= lo; > lo; any finite number; integers in [lo, hi]
OptionRange closed(double lo, double hi) { return {false, lo, hi, false, false}; }
OptionRange open_closed(double lo, double hi) { return {false, lo, hi, true, false}; }
OptionRange open_open(double lo, double hi) { return {false, lo, hi, true, true}; }
OptionRange at_least(double lo) { return {false, lo, DBL_MAX, false, false}; }
OptionRange above(double lo) { return {false, lo, DBL_MAX, true, false}; }
OptionRange finite() { return {}; }
OptionRange ints(double lo, double hi) { return {true, lo, hi, false, false}; }

// An entry under construction: .was("old_key"), .flag("--flag"), .switch_flag("--flag").
struct Entry {
  OptionSpec s;
  Entry& was(const char* old_key) {
    s.old_key = old_key;
    return *this;
  }
  Entry& flag(const char* f) {
    s.flag = f;
    return *this;
  }
  Entry& switch_flag(const char* f) {
    s.flag = f;
    s.flag_switch = true;
    return *this;
  }
};

Entry make(const char* key, OptionKind kind, const char* unit, OptionRange range, const char* doc) {
  Entry e;
  e.s.key = key;
  e.s.kind = kind;
  e.s.unit = unit;
  e.s.range = range;
  e.s.doc = doc;
  return e;
}

// a double or int member in `range`
template <class Ref>
Entry number(const char* key, Ref ref, double def, OptionRange range, const char* unit, const char* doc) {
  Entry e = make(key, range.integer ? OptionKind::Integer : OptionKind::Number, unit, range, doc);
  e.s.def = def;
  e.s.get = [ref](const SimOptions& o) -> OptionValue { return static_cast<double>(ref(o)); };
  e.s.set = [ref](SimOptions& o, const OptionValue& v) {
    using T = std::remove_reference_t<decltype(ref(o))>;
    ref(o) = static_cast<T>(std::get<double>(v));
  };
  return e;
}

template <class Ref>
Entry boolean(const char* key, Ref ref, bool def, const char* doc) {
  Entry e = make(key, OptionKind::Bool, "", {}, doc);
  e.s.def = def;
  e.s.get = [ref](const SimOptions& o) -> OptionValue { return static_cast<bool>(ref(o)); };
  e.s.set = [ref](SimOptions& o, const OptionValue& v) { ref(o) = std::get<bool>(v); };
  return e;
}

// an enum member, spelled by `table` (which outlives every use: a global)
template <class Ref, class E, std::size_t N>
Entry named(const char* key, Ref ref, E def, const mag::NameTable<E, N>& table, const char* what, const char* doc) {
  Entry e = make(key, OptionKind::Name, "", {}, doc);
  e.s.def = std::string(table.name(def));
  e.s.names = table.names();
  e.s.what = what;
  e.s.get = [ref, &table](const SimOptions& o) -> OptionValue { return std::string(table.name(ref(o))); };
  e.s.set = [ref, &table](SimOptions& o, const OptionValue& v) { table.parse(std::get<std::string>(v), &ref(o)); };
  return e;
}

template <class Ref>
Entry vector(const char* key, Ref ref, const Vec3& def, double max_length, const char* unit, const char* doc) {
  Entry e = make(key, OptionKind::Vector, unit, at_least(0), doc);
  e.s.def = def;
  e.s.range.hi = max_length;
  e.s.get = [ref](const SimOptions& o) -> OptionValue { return Vec3(ref(o)); };
  e.s.set = [ref](SimOptions& o, const OptionValue& v) { ref(o) = std::get<Vec3>(v); };
  return e;
}

std::vector<OptionSpec> build() {
  const Entry entries[] = {
      // ---- magnetics (mag::DynamicsOptions) ----
      named(MEMBER(magnetics.method), mag::Method::Anderson, mag::kMethodNames, "method",
            "the magnetization method: anderson = M = f(H(M)) converged every sub-step, with the classic "
            "force, -grad of the co-energy U*; ours = the paper as printed: theta dynamics eqs. 8-11 and "
            "eq. 4, which has no energy; kim2018 = the baseline")
          .was("method").flag("--method"),
      number(MEMBER(magnetics.dt), 1e-7, closed(1e-9, 1e-6), "s",
            "magnetization time step dt_m, e.g. 1e-7").flag("--dt-m"),
      number(MEMBER(magnetics.beta), 5.0, above(0), "m/(A s)", "beta of eq. 8"),
      number(MEMBER(magnetics.alpha), 0.2, closed(1e-12, 1), "", "LLG damping constant alpha (Kim 2018)"),
      number(MEMBER(magnetics.gamma_c_max), 1.0, closed(1.0 / 3.0, 1e12), "", "upper bound of gamma_C in eq. 11"),
      boolean(MEMBER(magnetics.adaptive_gamma_bound), true,
              "raise the bound to gamma_C at the solution, so that the fixed point stays M = f(H)"),
      number(MEMBER(magnetics.adaptive_gamma_cap), 2.5, above(0), "", "limit of the raised bound"),
      number(MEMBER(magnetics.tol), 1e-4, open_open(0, 1), "",
            "magnetization convergence tolerance: converged when the criterion < tol")
          .flag("--tol"),
      named(MEMBER(magnetics.criterion), mag::DynamicsOptions::Criterion::Residual, mag::kCriterionNames, "criterion",
            "what tol bounds: residual = max |M - f(H)|/Ms, change = max |dM|/Ms over one sweep"),
      // a bound on the work per solve: at ~10 us an iteration (balls_up), 1e6 iterations are
      // about 10 s a step; 1e9 was a silent 2.7-hour step
      number(MEMBER(magnetics.max_iter), 100, ints(1, 1000000), "",
             "magnetization iteration cap per solve (a hit is counted in summary.json)")
          .flag("--max-iter"),
      number(MEMBER(magnetics.min_pair_angle), 1e-6, closed(1e-300, 0.0099999), "rad",
             "floor of the half-angle between the sub-magnetizations M1 and M2"),
      named(MEMBER(magnetics.theta_integrator), mag::ThetaIntegrator::Exact, mag::kThetaIntegratorNames,
            "theta integrator",
            "how ours integrates eq. 8: exact = closed form, euler = the paper's explicit step"),
      number(MEMBER(magnetics.anderson_depth), 5, ints(0, 50), "",
             "anderson: past residuals in the least-squares mixing (0 = plain Picard iteration)"),
      number(MEMBER(magnetics.anderson_damping), 1.0, closed(1e-300, 1), "", "anderson: damping of the mixing"),
      number(MEMBER(magnetics.anderson_restart_growth), 2.0, above(1), "",
             "anderson: the history is dropped when the residual grows by more than this factor"),
      // ---- magnetics.field (mag::FieldOptions) ----
      number(MEMBER(magnetics.field.softening), 0.0, closed(0, 0.1), "m",
             "dipole softening length eps: |r|^2 -> |r|^2 + eps^2 in every field, Jacobian and force")
          .was("magnetics.softening").flag("--softening"),
      boolean(MEMBER(magnetics.field.bounded_pairs), false,
              "evaluate a pair of moments no closer than the sum of their interaction radii")
          .was("magnetics.bounded_pairs").flag("--bounded-pairs"),
      named(MEMBER(magnetics.field.solver), mag::FieldSolver::Auto, mag::kFieldSolverNames, "field solver",
            "how the dipole fields are summed, for the magnetization and the forces alike; auto = the "
            "exact direct sum below auto_threshold (--bh-threshold) moments, Barnes-Hut from there on")
          .was("field_solver").flag("--field-solver"),
      number(MEMBER(magnetics.field.bh_theta), 0.3, open_closed(0, 1), "",
             "Barnes-Hut opening angle; smaller = more accurate and slower")
          .was("bh_theta").flag("--bh-theta"),
      number(MEMBER(magnetics.field.auto_threshold), 2000, ints(0, 1000000000), "",
             "auto: moments (permanent ones included) from which Barnes-Hut is used")
          .was("bh_threshold").flag("--bh-threshold"),
      number(MEMBER(magnetics.field.bh_leaf_size), 64, ints(1, 1000000), "",
            "Barnes-Hut: most moments per octree leaf")
          .was("bh_leaf_size"),
      number(MEMBER(magnetics.field.bh_group_size), 32, ints(1, 1000000), "",
             "Barnes-Hut: targets that share one interaction list")
          .was("bh_group_size"),
      number(MEMBER(magnetics.field.bh_order), 2, ints(1, 2), "",
             "Barnes-Hut expansion order of a cell: 1 = the quadrupole-order term, 2 = also the octupole-order one")
          .was("bh_order"),
      boolean(MEMBER(magnetics.field.bh_near_float), true,
            "Barnes-Hut near field in single precision (false: double)")
          .was("bh_near_float"),
      boolean(MEMBER(magnetics.field.bh_far_float), true,
              "with bh_near_float: the Barnes-Hut far cells in single precision too (false: double)")
          .was("bh_far_float"),
      named(MEMBER(magnetics.field.near_field.model), mag::NearField::Dipole, mag::kNearFieldNames,
            "near-field model",
            "near field of touching iron balls: dipole = one point dipole each; pair = exact two-sphere "
            "couplings for pairs closer than a gap of 2 radii, at a wider gap as the balls' flux saturates the contact and "
            "weaker where a chain's contacts share the flux "
            "(magnetics/near_field.hpp); pair needs the classic force")
          .was("near_field").flag("--near-field"),
      number(MEMBER(magnetics.field.near_field.mu_r), 1000.0, closed(10, 10000), "",
             "initial relative permeability of the induced material, read by the pair model (iron: 1000)")
          .was("near_field_mu_r").flag("--near-field-mu-r"),
      named(MEMBER(magnetics.field.near_field.curve), mag::Curve::Tanh, mag::kCurveOptionNames, "curve",
            "the balls' curve M = f(H) for methods anderson and exact: tanh = eq. 10, Ms tanh(3H/Ms); "
            "iron = a sphere of bulk iron, mu_r,initial 1000 (0.80x tanh's moment at 0.3 Ms; magnetics/types.hpp); "
            "the pair model's widening is fitted per curve")
          .flag("--curve"),
      // ---- forces and the energy guard ----
      boolean(MEMBER(reaction_symmetric_forces), false,
              "apply the Zeeman forces pairwise antisymmetrized: momentum is conserved (needed with dynamic magnets)"),
      boolean(MEMBER(balance_magnetic_torque), false,
              "cancel the net torque that eq. 4's reaction-symmetric forces leave (they sum to zero, their "
              "torques do not), by the least forces that do, where the torque arises; needs "
              "reaction_symmetric_forces")
          .flag("--balance-magnetic-torque"),
      named(MEMBER(force_model), mag::ForceModel::Method, mag::kForceModelNames, "force model",
            "force on induced moments: method = the method's own (classic for anderson, exact and kim2018, "
            "eq. 4 for ours, ours-realigned and damping-llg); zeeman = eq. 4, not the gradient of any energy; "
            "classic = eqs. 13-14, -grad U* with converged magnetizations; zeeman-total = eq. 4 as the "
            "gradient of the system's Zeeman energy: conservative")
          .flag("--force-model"),
      boolean(MEMBER(energy_guard), true,
              "retake a rigid step in twice the sub-steps when E = K + U_g + U* rises by more than the "
              "tolerance (unavailable for eq. 4 (zeeman), which has no energy: never applied there, "
              "summary.json energy.guard says so)")
          .flag("--energy-guard"),
      number(MEMBER(energy_guard_tolerance), 1e-3, at_least(0), "",
             "the guard's tolerance relative to the step's K_start + K_end + |U*_start|")
          .flag("--energy-guard-tolerance"),
      number(MEMBER(energy_guard_floor), 1e-6, at_least(0), "J", "the guard's absolute tolerance per step")
          .flag("--energy-guard-floor"),
      number(MEMBER(energy_guard_max_substeps), 32, ints(1, 64), "", "most sub-steps the guard retakes a frame in")
          .flag("--energy-guard-max-substeps"),
      // ---- the rigid step ----
      number(MEMBER(dt), 1e-3, open_closed(0, 0.1), "s", "rigid (frame) step dt_r").flag("--dt"),
      number(MEMBER(max_substeps), 1, ints(1, 64), "",
             "most rigid sub-steps per frame; a frame is split when bodies touching each other move fast "
             "or bodies in contact are pressed hard by the magnetic force (1 = never)")
          .flag("--max-substeps"),
      number(MEMBER(substep_reach), 0.25, above(0), "",
             "fraction of the smallest dynamic shape radius a body may cover per sub-step")
          .flag("--substep-reach"),
      boolean(MEMBER(substep_load), true,
              "also split a frame by the magnetic acceleration a of bodies in contact, a h^2 <= reach * "
              "r_min per sub-step")
          .flag("--substep-load"),
      vector(MEMBER(gravity), Vec3(0, 0, -9.81), limits::kMaxGravity, "m/s^2", "gravitational acceleration"),
      boolean(MEMBER(ground), true, "an infinite static plane z = 0"),
      // ---- contacts ----
      number(MEMBER(friction), 0.5, at_least(0), "", "Coulomb friction coefficient mu (0 = frictionless)"),
      number(MEMBER(rolling_friction), 0.0, at_least(0), "m",
             "rolling resistance rho: contacts with the ground and static bodies resist rolling with a "
             "torque <= rho * normal force (0 = none)")
          .flag("--rolling-friction"),
      number(MEMBER(rolling_friction_bodies), 0.0, at_least(0), "m",
             "the same between two dynamic bodies (a ball rolling on a ball) (0 = none)")
          .flag("--rolling-friction-bodies"),
      number(MEMBER(eddy_conductivity), 0.0, at_least(0), "S/m",
             "electrical conductivity sigma of the induced bodies: eddy-current loss where their flux "
             "density changes in their own frame (iron 1e7; 0 = none)")
          .flag("--eddy-conductivity"),
      number(MEMBER(restitution), 0.0, closed(0, 1), "", "bounce"),
      number(MEMBER(erp), 0.2, closed(0, 1), "", "ODE error reduction parameter"),
      number(MEMBER(cfm), 1e-9, at_least(0), "", "ODE constraint force mixing"),
      number(MEMBER(quickstep_iterations), 20, ints(1, 100000), "",
            "ODE QuickStep (contact solver) iterations per rigid step")
          .flag("--quickstep-iterations"),
      number(MEMBER(quickstep_w), 1.3, open_open(0, 2), "", "ODE QuickStep over-relaxation W").flag("--quickstep-w"),
      number(MEMBER(max_contacts), 4, ints(1, 64), "", "contacts per pair of shapes"),
      named(MEMBER(space), SpaceKind::SweepAndPrune, kSpaceNames, "broad phase",
            "ODE broad phase (sap = sweep and prune); the contacts are sorted into a fixed order, so every "
            "choice gives the same run")
          .flag("--space"),
      boolean(MEMBER(auto_disable), false,
            "let ODE put resting bodies to sleep (woken when their magnetic load changes)")
          .switch_flag("--auto-disable"),
      boolean(MEMBER(sleep), false,
              "sleeping islands: bodies joined by contacts that have all been still (sleep_speed) for sleep_time "
              "leave the rigid step, their moments stay field sources with M frozen; woken by a touch, by a "
              "change of the field at a moment beyond sleep_field_tolerance, or by the user (off under auto_disable)")
          .flag("--sleep"),
      number(MEMBER(sleep_speed), 0.02, above(0), "m/s",
             "a body is still while its mean velocities over the last sleep_time/2 give |v| + |omega| r_body "
             "below this (omega left out for spheres with centred induced moments)")
          .flag("--sleep-speed"),
      number(MEMBER(sleep_time), 0.1, above(0), "s", "how long every body of an island must be still before it sleeps")
          .flag("--sleep-time"),
      number(MEMBER(sleep_field_tolerance), 0.02, above(0), "",
             "a sleeping island wakes when the field at one of its moments moves by more than this fraction of "
             "its value when the island fell asleep (at least this fraction of 0.01 Ms)")
          .flag("--sleep-field-tolerance"),
      number(MEMBER(linear_damping), 0.0, at_least(0), "1/s", "velocity decay rate c: v <- v e^(-c dt) per step"),
      number(MEMBER(angular_damping), 0.0, at_least(0), "1/s", "the same for the angular velocity"),
      number(MEMBER(surface_layer), 0.0, at_least(0), "m",
            "ODE contact surface layer: the resting penetration allowed"),
      number(MEMBER(max_correcting_velocity), 0.0, at_least(0), "m/s",
             "cap on the velocity ODE pushes penetrating bodies apart with (0 = unlimited)"),
      number(MEMBER(contact_margin), -1.0, finite(), "m",
             "speculative contact distance: shapes this close get a contact that lets them close the gap "
             "in one step but not pass it (< 0 = 1/4 of the smallest shape radius, 0 = off)"),
      // ---- the run ----
      // also at most 4 x the cores (the machine's: compile_model and magsim-scene check it apart)
      number(MEMBER(threads), 0, ints(0, 1000000000), "",
             "OpenMP threads for the magnetics, at most 4 x the cores (0: sized to the free cores)")
          .flag("--threads"),
      number(MEMBER(max_body_speed), 1000.0, at_least(0), "m/s",
             "blow-up guard: a dynamic body faster than this ends the run with an error (0 = off)"),
  };
  std::vector<OptionSpec> t;
  std::set<std::string> keys, flags;
  for (const Entry& e : entries) {
    // every key, old key and flag once: a clash is a mistake in the table, found at start-up
    for (const std::string& k : {e.s.key, e.s.old_key})
      if (!k.empty() && !keys.insert(k).second) throw std::logic_error("options_table: key '" + k + "' twice");
    if (!e.s.flag.empty() && !flags.insert(e.s.flag).second)
      throw std::logic_error("options_table: flag '" + e.s.flag + "' twice");
    t.push_back(e.s);
  }
  return t;
}

#undef MEMBER

}  // namespace

const std::vector<OptionSpec>& options_table() {
  static const std::vector<OptionSpec> table = build();
  return table;
}

const OptionSpec& option_spec(const std::string& key) {
  for (const OptionSpec& s : options_table())
    if (s.key == key) return s;
  throw std::logic_error("option_spec: no option '" + key + "'");
}

}  // namespace magsim::engine
