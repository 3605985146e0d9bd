// magnetics/dipole_field.hpp — the dipole field (eq. 1) and its Jacobian: the formulas for one
// dipole, and the exact direct sum over all moments.
// A kernel below the field dispatcher (fields.hpp, which picks this sum or Barnes–Hut): it
// takes its own small options and knows nothing of FieldOptions or Barnes–Hut.
#pragma once

#include "magnetics/moments.hpp"
#include "magnetics/source_buffer.hpp"

#include <vector>

namespace magsim::mag {

/// Field of one dipole m at offset r = p − p_i (eq. 1, softened when eps2 > 0):
///   h = (1/4π) (3 r (r·m) − q m) / q^{5/2},  q = |r|² + ε².
Vec3 dipole_field(const Vec3& r, const Vec3& m, double eps2 = 0.0);
/// Its Jacobian ∂h/∂r (symmetric; trace-free when ε = 0):
///   J = (1/4π) [ 3 (I (r·m) + r mᵀ + m rᵀ) / q^{5/2} − 15 r rᵀ (r·m) / q^{7/2} ].
Mat3 dipole_jacobian(const Vec3& r, const Vec3& m, double eps2 = 0.0);

/// Bounded pairs (FieldOptions::bounded_pairs): r → r·R/|r| where |r| < R, else r.
Vec3 bounded_separation(const Vec3& r, double R);

/// What the direct sum takes of the field options (compute_fields fills it from
/// FieldOptions, which documents both).
struct DirectSumOptions {
  double softening = 0.0;  ///< softening length ε (m), 0 = exact point dipoles
  bool bounded = false;    ///< sum as bounded pairs (pairs_bounded of fields.hpp)
};

/// The exact direct sum of compute_fields (fields.hpp): H_j = H0 + Σ_{i≠j} h(p_j − p_i, m_i)
/// and, with J != nullptr, J_j summed over sources in other groups only, at the moments
/// *targets (H, J resized to targets->size()), or at every moment when targets is nullptr
/// (resized to set.size()). Moments with m_i = 0 are skipped. *src receives the packed
/// nonzero sources (scratch, reused across calls). Threaded over targets (OpenMP) in a fixed
/// sum order, so results do not depend on the thread count.
void direct_sum_fields(const MomentDesc& set, const Magnetization& mz,
                       const DirectSumOptions& opt, const std::vector<int>* targets,
                       std::vector<Vec3>* H, std::vector<Mat3>* J, detail::SourceBuffer* src);

/// The field (and optionally Jacobian) of all moments of `set` at an arbitrary point p,
/// excluding moment `skip` (−1: none). Used by tools and tests.
Vec3 field_at(const MomentSet& set, const Vec3& p, double eps2 = 0.0, int skip = -1,
              Mat3* J = nullptr);

}  // namespace magsim::mag
