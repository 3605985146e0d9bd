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
// Stated error bound (defaults: θ = 0.3, order 2, leaves ≤ 64, target groups ≤ 32),
// measured against the direct sum by tools/bench_kernel and tests/magnetics/barnes_hut_test:
// relative field error RMS ≤ 1e-3 over all targets (RMS = √(Σ|ΔH_j|²/Σ|H_j|²)), and on piles
// and clouds max ≤ 2e-2 (max = max_j |ΔH_j|/|H_j|). Measured: dense piles of touching balls
// under a magnet, 2,500–100,000 balls: RMS 2.2e-4 … 8.6e-4, max 2e-3 … 1.8e-2 (growing
// slowly with N, as more scales of cells contribute); sparse clouds: RMS ≤ 6e-5, max ≤
// 2.7e-3 even with every ball magnetized at random. Flat sheets of balls under a magnet
// (2,500–100,000): RMS 1.6e-4 … 3.8e-4, but max 6e-2 … 0.5: there the in-plane field of the
// sheet nearly cancels the applied one at some balls (10,000 balls: 3 % above 2e-2, the worst
// at |H_j| < 0.2 % of the RMS |H|), while the absolute error stays ≤ 2.5e-3 × RMS |H|. The
// max is reached at such balls on piles too. J: RMS ≤ 2e-3. Larger θ trades accuracy for
// speed, steeply: θ = 0.4 gives RMS 7e-4 on a 2,500-ball pile, 3e-3 on a 10,000-ball one.
//
// Near field in single precision (FieldOptions::bh_near_float, the default, θ > 0; see
// barnes_hut.cpp): the figures above are unchanged to the digits quoted; against the
// double near field (the same tree and far cells) it adds, measured on piles and sheets of
// 2,500–10,000 balls (each its own body) and on softened letters: relative RMS 3e-7 … 8e-7
// for H, 6e-7 … 1.3e-6 for J (max 2e-6 … 1.6e-5 on piles; up to 1.3e-3 on a 10,000-ball
// sheet, at the balls where |H_j| nearly cancels, as for the far-field max). 1 thread, AVX-512
// (bench_kernel --stat min, reused geometry): the near pair kernel alone 2.0–2.3× faster
// (H+J 0.85 → 1.9e9 pairs/s); a whole evaluation 1.5–1.8× faster (10,000-ball pile H+J
// 33 → 18 ms, 6.6× the direct sum; sheet 12 → 7.8 ms, 15×), the far cells and the gather
// being the rest. θ = 0 keeps the near field (then the whole sum) in double.
//
// Far cells in single precision (FieldOptions::bh_far_float, the default; only with
// bh_near_float and θ > 0): each group's cells gathered as float, centres relative to the
// group's centre and every field scaled to a per-group power-of-two length unit (so no power
// of 1/R up to 1/R¹¹ overflows, whatever the units), the Taylor terms in float (16 lanes),
// partial sums added in double in a fixed order (bitwise the same for any thread count, fresh
// or reused). Against double far cells (the same float near field), measured with
// tools/bench_kernel --groups ball: relative RMS 1.5e-7 … 2.2e-7 for H and 2.2e-7 … 2.7e-7
// for J on piles of 2,500–10,000 balls (max 2.4e-6 … 4.2e-6), 2.4e-9 … 4e-9 (H) and
// < 6e-10 (J) on sheets (max up to 1e-5, where |H_j| nearly cancels); tests bound it at 1e-5
// RMS (measured 1e-11 … 4.5e-7, also for scenes scaled to nm and km). The figures against
// the direct sum above are unchanged to the digits quoted. Speed (AVX-512, bench_kernel
// --stat min, reused geometry, with a cheaper float gather of the near sources): a whole
// evaluation 1.1–1.25× faster than with double far cells (2,500-ball pile H 1.09 → 0.90 ms
// at 1 thread; 10,000-ball sheet H+J 7.7 → 6.1 ms, 18× the direct sum).
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
void barnes_hut_fields(const MomentSet& set, const FieldOptions& opt, std::vector<Vec3>* H,
                       std::vector<Mat3>* J, BarnesHutWorkspace* ws);

}  // namespace magsim::mag
