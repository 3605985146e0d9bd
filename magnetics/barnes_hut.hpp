// magnetics/barnes_hut.hpp — Barnes–Hut far-field approximation of compute_fields
// (FieldSolver::BarnesHut, or FieldSolver::Auto from FieldOptions::auto_threshold moments).
//
// An octree of the moments; each cell carries its dipole moment and the quadrupole- and
// octupole-order terms about a fixed centre (its sources' centre weighted by their largest
// possible moments V Ms, or |m| for permanent ones — independent of the magnetizations), so
// that eq. 1 (and its Jacobian) summed over a far cell is its Taylor series cut after
// (b/R)^order. Near cells are summed exactly, and so are the self-exclusion (a moment never
// feels itself) and the same-group exclusion from J (see barnes_hut.cpp). The tree and the
// interaction lists are kept in the workspace and reused while positions, groups, the set of
// nonzero moments and V Ms / |m_perm| stay bitwise the same (only the moments changed, as
// in the magnetization solvers' sweeps): such a call redoes the multipoles and the sums only,
// and gives bitwise what a fresh evaluation gives.
//
// Error bound (defaults: θ = 0.3, order 2, leaves ≤ 64, target groups ≤ 32; checked by
// tests/magnetics/barnes_hut_test): relative field error RMS ≤ 1e-3 over all targets
// (√(Σ|ΔH_j|²/Σ|H_j|²)), max_j |ΔH_j|/|H_j| ≤ 2e-2 on piles and clouds (larger only where
// |H_j| nearly cancels, e.g. flat sheets); J: RMS ≤ 2e-3. The single-precision near field and
// far cells (bh_near_float, bh_far_float) add < 2e-6 and < 1e-5 RMS. Measured figures and
// speeds: README.md, "Benchmarks".
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
  double tree_s = 0;                  ///< of build_s: the tree (0 when reused)
  bool reused_tree = false;           ///< the cached tree served (same geometry)
  bool reused_lists = false;          ///< the cached interaction lists served
  double lists_s = 0;                 ///< of eval_s: building the lists (s, summed over threads)
};
/// The statistics of the last Barnes–Hut evaluation with this workspace (zeros if none).
BarnesHutStats barnes_hut_stats(const FieldWorkspace& ws);

/// Drops the cached octree and interaction lists, so that the next evaluation builds them
/// anew (benchmarks time the fresh build with it; results are the same either way).
void barnes_hut_forget_geometry(FieldWorkspace* ws);

/// H (and J) at every moment as compute_fields does, far cells approximated. Called by
/// compute_fields when the options select Barnes–Hut.
void barnes_hut_fields(const MomentDesc& set, const Magnetization& mz, const FieldOptions& opt,
                       std::vector<Vec3>* H, std::vector<Mat3>* J, BarnesHutWorkspace* ws);
inline void barnes_hut_fields(const MomentSet& set, const FieldOptions& opt, std::vector<Vec3>* H,
                              std::vector<Mat3>* J, BarnesHutWorkspace* ws) {
  barnes_hut_fields(set, set, opt, H, J, ws);
}

}  // namespace magsim::mag
