// magnetics/barnes_hut.hpp — Barnes–Hut far-field approximation of compute_fields
// (FieldSolver::BarnesHut, or FieldSolver::Auto from FieldOptions::auto_threshold moments).
//
// An octree of the moments; each cell carries its dipole moment and the quadrupole- and
// octupole-order terms about its |m|-weighted centre, so that eq. 1 (and its Jacobian)
// summed over a far cell is its Taylor series cut after (b/R)^order. Near cells are summed
// exactly, and so are the self-exclusion (a moment never feels itself) and the same-group
// exclusion from J (see barnes_hut.cpp).
//
// Stated error bound (defaults: θ = 0.3, order 2, leaves ≤ 64, target groups ≤ 32),
// measured against the direct sum by tools/bench_kernel and tests/magnetics/barnes_hut_test:
// relative field error RMS ≤ 1e-3 and max ≤ 2e-2 over all targets (RMS = √(Σ|ΔH_j|²/Σ|H_j|²),
// max = max_j |ΔH_j|/|H_j|). Measured: dense piles of touching balls under a magnet,
// 1,000–100,000 balls: RMS 7e-5 … 6.6e-4, max 5e-4 … 1.5e-2 (growing slowly with N, as more
// scales of cells contribute); sparse clouds: RMS ≤ 6e-5, max ≤ 2.4e-3 even with every ball
// magnetized at random. The max is reached at the few balls where neighbouring fields cancel
// (|H| small). J: RMS ≤ 2e-3. Larger θ trades accuracy for speed: the RMS error grows about
// as θ^5 (θ^4 with bh_order = 1); θ = 0.5 gives RMS ≈ 2e-3 on piles.
#pragma once

#include "magnetics/dipole_field.hpp"

namespace magsim::mag {

/// Octree, multipoles and per-thread scratch; reused across calls.
struct BarnesHutWorkspace;
/// A new, empty workspace (owned by FieldWorkspace::bh).
BarnesHutWorkspace* new_barnes_hut_workspace();

/// What the last Barnes–Hut evaluation did (for benchmarks).
struct BarnesHutStats {
  int nodes = 0, groups = 0;          ///< octree cells, target groups
  double near_pairs_per_target = 0;   ///< exact pair terms per target (padding included)
  double far_cells_per_target = 0;    ///< cell expansions per target (padding included)
  double build_s = 0, eval_s = 0;     ///< tree + multipoles, lists + sums (s, wall)
  double lists_s = 0;                 ///< of eval_s: building the lists (s, summed over threads)
};
/// The statistics of the last Barnes–Hut evaluation with this workspace (zeros if none).
BarnesHutStats barnes_hut_stats(const FieldWorkspace& ws);

/// H (and J) at every moment as compute_fields does, far cells approximated. Called by
/// compute_fields when the options select Barnes–Hut.
void barnes_hut_fields(const MomentSet& set, const FieldOptions& opt, std::vector<Vec3>* H,
                       std::vector<Mat3>* J, BarnesHutWorkspace* ws);

}  // namespace magsim::mag
