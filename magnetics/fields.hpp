// magnetics/fields.hpp — the dipole fields (eq. 1) and their Jacobians at every moment: the
// field options, the workspace, and the dispatch between the exact direct sum
// (dipole_field.hpp) and the Barnes–Hut approximation (barnes_hut.hpp).
// The driver above its kernels: it fills their own options from FieldOptions, and neither
// kernel includes this header.
#pragma once

#include "magnetics/barnes_hut.hpp"
#include "magnetics/moments.hpp"
#include "magnetics/near_field.hpp"
#include "magnetics/source_buffer.hpp"

#include <memory>
#include <string>
#include <vector>

namespace magsim::mag {

/// How compute_fields sums the dipole fields.
enum class FieldSolver : std::uint8_t {
  Direct,     ///< exact O(N·S) sum (SIMD, threaded)
  BarnesHut,  ///< octree far-field approximation (magnetics/barnes_hut.hpp), error set by θ
  Auto        ///< Direct below auto_threshold moments, Barnes–Hut from there on
};
inline constexpr NameTable<FieldSolver, 3> kFieldSolverNames{
    {{FieldSolver::Direct, "direct"}, {FieldSolver::BarnesHut, "barnes-hut"}, {FieldSolver::Auto, "auto"}}};

struct FieldOptions {
  /// Softening length ε (m): |r|² → |r|² + ε² in the field and, consistently, in its
  /// Jacobian. 0 = off (exact point dipoles). A fraction of a moment's radius is typical.
  double softening = 0.0;
  /// Bounded pair interaction: a pair of moments closer than the sum of their interaction
  /// radii (MomentSet::radius) is evaluated at that separation along its direction, in the
  /// field, its Jacobian and so the forces: an overlap the contact solver leaves cannot
  /// raise the magnetic pull above its value at contact (positive feedback otherwise: the
  /// pair force grows as 1/|r|⁴ and steeper). Exact for every pair at or beyond contact.
  /// No effect where every radius is 0 (magsolve, the experiments' point moments).
  /// Off by default: inside an overlap the force is frozen at its contact value, which is not
  /// a gradient, and in balls_up's resting pile that pumped energy (README, "Benchmarks").
  bool bounded_pairs = false;
  /// Auto (the default): the exact direct sum below auto_threshold moments, Barnes–Hut
  /// (relative field error RMS ≤ 1e-3) from there on. Direct forces the exact sum.
  FieldSolver solver = FieldSolver::Auto;
  /// Barnes–Hut opening angle θ ∈ [0, 1]: a cell of radius b (about its expansion centre)
  /// at distance R from a group of targets of radius b_t is used whole when b < θ (R − b_t).
  /// 0 = never (the direct sum, through the tree). 0.3: relative field error RMS ≤ 1e-3,
  /// max ≤ 2e-2 on piles and clouds (barnes_hut.hpp).
  double bh_theta = 0.3;
  /// Auto uses Barnes–Hut from this many moments on: 2,000 keeps the exact sum for the
  /// scenes and experiments up to that size and takes Barnes–Hut for sakura_tree (2,508
  /// moments); the crossover measured in the engine: README, "Benchmarks".
  int auto_threshold = 2000;
  /// Barnes–Hut leaf size (at most this many moments per octree leaf), ≥ 1. Cells of a few
  /// moments are poor multipoles; leaves of 64 are both faster and ~10× more accurate than
  /// leaves of 16 on dense piles.
  int bh_leaf_size = 64;
  /// Barnes–Hut target group size: targets that share one interaction list, ≥ 1.
  int bh_group_size = 32;
  /// Barnes–Hut expansion order of a cell about its centre: 1 = dipole + quadrupole-order
  /// term, 2 = also the octupole-order term (error ∝ (b/R)^(order+1) per cell).
  int bh_order = 2;
  /// Barnes–Hut near field (the exact pair sums over near leaves, most of its time) in
  /// single precision, positions relative to the target group's centre: adds < 2e-6 to the
  /// relative RMS of H and J (barnes_hut.hpp). Only with θ > 0 (θ = 0 promises the
  /// direct sum and stays in double). false: the near field in double — and the far cells
  /// too (bh_far_float applies only with bh_near_float), so false is the all-double sum.
  bool bh_near_float = true;
  /// With bh_near_float (and θ > 0): the far-cell Taylor sums in single precision too
  /// (cell data relative to the target group's centre, scaled; partial sums added in
  /// double): adds < 1e-5 to the relative RMS of H and J (barnes_hut.hpp).
  /// false: far cells in double (the near field as bh_near_float says).
  bool bh_far_float = true;
  /// The near-field model of touching induced spheres (near_field.hpp): dipole (none) or
  /// pair. compute_fields adds its field; compute_forces its forces (classic force only).
  NearFieldOptions near_field;
};

/// A solver's name in kFieldSolverNames.
inline const char* field_solver_name(FieldSolver s) { return kFieldSolverNames.name(s); }
/// Parses a solver name (kFieldSolverNames); returns false (and leaves *out alone) on an
/// unknown name.
inline bool parse_field_solver(const std::string& name, FieldSolver* out) {
  return kFieldSolverNames.parse(name, out);
}
/// Empty when the field options are usable, else a one-line reason.
std::string validate(const FieldOptions& opt);

/// Packed copies of the sources (flat arrays for the kernel) — per-solve scratch.
struct FieldWorkspace {
  FieldWorkspace() = default;
  FieldWorkspace(FieldWorkspace&&) noexcept = default;
  FieldWorkspace& operator=(FieldWorkspace&&) noexcept = default;
  /// A copy takes the packed arrays but not the tree (scratch; rebuilt on first use).
  FieldWorkspace(const FieldWorkspace& o);
  FieldWorkspace& operator=(const FieldWorkspace& o);

  /// the direct sum's nonzero sources, padded (pack order: moment index)
  detail::SourceBuffer src;
  /// Barnes–Hut tree and per-thread scratch, created on first use.
  std::unique_ptr<BarnesHutWorkspace, BarnesHutWorkspaceDeleter> bh;
  /// The near-field pair list and coupling table (NearField::Pair).
  NearFieldWorkspace near;
};

/// True when compute_fields sums `set` as bounded pairs (the option is on and some moment
/// has a radius > 0).
bool pairs_bounded(const MomentDesc& set, const FieldOptions& opt);

/// H_j = H0 + Σ_{i≠j} h(p_j − p_i, m_i) at every moment j (A/m). With J != nullptr also
/// J_j = ∂H_j/∂p_j with the sources held fixed, summed over sources in other groups only
/// (moments of one rigid body exert no force on each other). Moments with m_i = 0 are
/// skipped. Threaded over targets (OpenMP); the sum order is fixed, so results are
/// deterministic (for the direct sum and Barnes–Hut alike, whatever the thread count).
/// opt.solver picks the direct sum or the Barnes–Hut approximation.
void compute_fields(const MomentDesc& set, const Magnetization& mz, const FieldOptions& opt,
                    std::vector<Vec3>* H, std::vector<Mat3>* J, FieldWorkspace* ws);
inline void compute_fields(const MomentSet& set, const FieldOptions& opt, std::vector<Vec3>* H,
                           std::vector<Mat3>* J, FieldWorkspace* ws) {
  compute_fields(set, set, opt, H, J, ws);
}

/// The direct sum of compute_fields at the listed moments only (H, J sized like targets),
/// the dipoles alone: the near-field pair term, which acts on induced moments only, is not
/// added. Used at permanent moments (ZeemanTotal), to measure Barnes–Hut errors and to time
/// the direct kernel on a sample of targets.
void compute_fields_at(const MomentDesc& set, const Magnetization& mz, const FieldOptions& opt,
                       const std::vector<int>& targets, std::vector<Vec3>* H,
                       std::vector<Mat3>* J, FieldWorkspace* ws);
inline void compute_fields_at(const MomentSet& set, const FieldOptions& opt,
                              const std::vector<int>& targets, std::vector<Vec3>* H,
                              std::vector<Mat3>* J, FieldWorkspace* ws) {
  compute_fields_at(set, set, opt, targets, H, J, ws);
}

/// The solver compute_fields uses for n moments under opt (Auto resolved).
FieldSolver resolve_solver(const FieldOptions& opt, std::size_t n);

/// barnes_hut_stats of the workspace's Barnes–Hut part (zeros when it has none).
BarnesHutStats barnes_hut_stats(const FieldWorkspace& ws);
/// barnes_hut_forget_geometry of the workspace's Barnes–Hut part (nothing when it has none).
void barnes_hut_forget_geometry(FieldWorkspace* ws);

}  // namespace magsim::mag
