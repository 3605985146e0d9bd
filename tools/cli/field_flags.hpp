// tools/cli/field_flags.hpp — bench's dipole-field flags: --field-solver (mag::kFieldSolverNames),
// --bh-theta θ, --bh-threshold N, --near-field (mag::kNearFieldNames), --near-field-mu-r μr, in
// the ranges of their options (engine/options_table.hpp; magsim-scene's flags of the same
// names come from that table). Flags not given leave the scene's FieldOptions as they are.
#pragma once

#include "magnetics/fields.hpp"
#include "tools/cli/cli_common.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace magsim::tools {

struct FieldFlags {
  std::string solver;
  double theta = mag::FieldOptions{}.bh_theta;
  int threshold = mag::FieldOptions{}.auto_threshold;
  CLI::Option* solver_opt = nullptr;
  CLI::Option* theta_opt = nullptr;
  CLI::Option* threshold_opt = nullptr;
  std::string near_field;
  double mu_r = mag::NearFieldOptions{}.mu_r;
  CLI::Option* near_opt = nullptr;
  CLI::Option* mu_r_opt = nullptr;

  void add(CLI::App* app, const std::string& solver_help) {
    solver_opt = app->add_option("--field-solver", solver, solver_help);
    theta_opt = app->add_option("--bh-theta", theta, "Barnes-Hut opening angle, in (0, 1]")
                    ->check(OptionCheck("magnetics.field.bh_theta"))
                    ->capture_default_str();
    threshold_opt = app->add_option("--bh-threshold", threshold, "auto: moments from which Barnes-Hut is used")
                        ->check(OptionCheck("magnetics.field.auto_threshold"))
                        ->capture_default_str();
    near_opt = app->add_option("--near-field", near_field,
                               "near field of touching iron balls: " + mag::kNearFieldNames.list("|") +
                                   " (pair: exact two-sphere couplings, faded as the contact saturates; "
                                   "classic force only). Default: the scene's (registry scenes: dipole)");
    mu_r_opt = app->add_option("--near-field-mu-r", mu_r,
                               "initial relative permeability of the iron, read by --near-field pair")
                   ->check(OptionCheck("magnetics.field.near_field.mu_r"))
                   ->capture_default_str();
  }
  bool has_solver() const { return solver_opt && solver_opt->count() > 0; }

  /// Parses a solver name; throws std::invalid_argument naming `flag`.
  static mag::FieldSolver parse(const std::string& name, const char* flag) {
    mag::FieldSolver s;
    if (!mag::parse_field_solver(name, &s))
      throw std::invalid_argument(std::string(flag) + ": " + mag::kFieldSolverNames.unknown("solver", name));
    return s;
  }

  /// Throws std::invalid_argument when --bh-theta is outside (0, 1] (θ = 0, the library's
  /// exact limit, is for tests: it is the direct sum at tree cost).
  void check() const {
    if (theta_opt && theta_opt->count() && !(theta > 0 && theta <= 1)) {
      char got[32];
      std::snprintf(got, sizeof got, "%g", theta);
      throw std::invalid_argument(std::string("--bh-theta: the Barnes-Hut opening angle must be in (0, 1], got ") + got);
    }
    mag::NearField m;
    if (near_opt && near_opt->count() && !mag::kNearFieldNames.parse(near_field, &m))
      throw std::invalid_argument(mag::kNearFieldNames.unknown("--near-field", near_field));
  }

  /// Applies the flags given on the command line to f (after check()).
  void apply(mag::FieldOptions* f) const {
    check();
    if (has_solver()) f->solver = parse(solver, "--field-solver");
    if (theta_opt && theta_opt->count()) f->bh_theta = theta;
    if (threshold_opt && threshold_opt->count()) f->auto_threshold = threshold;
    if (near_opt && near_opt->count()) mag::kNearFieldNames.parse(near_field, &f->near_field.model);
    if (mu_r_opt && mu_r_opt->count()) f->near_field.mu_r = mu_r;
  }
};

}  // namespace magsim::tools
