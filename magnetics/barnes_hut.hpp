// magnetics/barnes_hut.hpp — Barnes–Hut far-field approximation of the dipole sums, the
// kernel compute_fields (fields.hpp) runs for FieldSolver::BarnesHut, or for FieldSolver::Auto
// from FieldOptions::auto_threshold moments. It takes its own options (BarnesHutOptions,
// filled by the dispatcher) and includes nothing of fields.hpp.
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
// far cells (near_float, far_float) add < 2e-6 and < 1e-5 RMS. Measured figures and
// speeds: README.md, "Benchmarks".
#pragma once

#include "magnetics/moments.hpp"

#include <vector>

namespace magsim::mag {

/// What Barnes–Hut takes of the field options. compute_fields fills it from FieldOptions,
/// which documents each one; the defaults here are FieldOptions' defaults.
struct BarnesHutOptions {
  double softening = 0.0;  ///< softening length ε (m), FieldOptions::softening
  bool bounded = false;    ///< sum as bounded pairs (pairs_bounded of fields.hpp)
  double theta = 0.3;      ///< opening angle θ ∈ [0, 1], FieldOptions::bh_theta
  int leaf_size = 64;      ///< moments per octree leaf at most, FieldOptions::bh_leaf_size
  int group_size = 32;     ///< targets per interaction list, FieldOptions::bh_group_size
  int order = 2;           ///< expansion order 1 or 2, FieldOptions::bh_order
  bool near_float = true;  ///< near field in single precision, FieldOptions::bh_near_float
  bool far_float = true;   ///< far cells in single precision, FieldOptions::bh_far_float
};

/// Octree, multipoles and per-thread scratch; reused across calls.
struct BarnesHutWorkspace;
/// A new, empty workspace (owned by FieldWorkspace::bh through BarnesHutWorkspaceDeleter).
BarnesHutWorkspace* new_barnes_hut_workspace();
/// Deletes a workspace of new_barnes_hut_workspace (the type is complete only here).
struct BarnesHutWorkspaceDeleter {
  void operator()(BarnesHutWorkspace* p) const;
};

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
BarnesHutStats barnes_hut_stats(const BarnesHutWorkspace& ws);

/// Drops the cached octree and interaction lists, so that the next evaluation builds them
/// anew (benchmarks time the fresh build with it; results are the same either way).
void barnes_hut_forget_geometry(BarnesHutWorkspace* ws);

/// H (and J) at every moment as compute_fields does, far cells approximated. Called by
/// compute_fields when the options select Barnes–Hut.
void barnes_hut_fields(const MomentDesc& set, const Magnetization& mz,
                       const BarnesHutOptions& opt, std::vector<Vec3>* H, std::vector<Mat3>* J,
                       BarnesHutWorkspace* ws);
inline void barnes_hut_fields(const MomentSet& set, const BarnesHutOptions& opt,
                              std::vector<Vec3>* H, std::vector<Mat3>* J, BarnesHutWorkspace* ws) {
  barnes_hut_fields(set, set, opt, H, J, ws);
}

}  // namespace magsim::mag
