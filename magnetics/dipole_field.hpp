// magnetics/dipole_field.hpp — the dipole field (eq. 1) and its Jacobian at every moment.
#pragma once

#include "magnetics/moments.hpp"

namespace magsim::mag {

struct FieldOptions {
  /// Softening length ε (m): |r|² → |r|² + ε² in the field and, consistently, in its
  /// Jacobian. 0 = off (exact point dipoles). A fraction of a moment's radius is typical.
  double softening = 0.0;
};

/// Packed copies of the sources (flat arrays for the kernel) — per-solve scratch.
struct FieldWorkspace {
  std::vector<double> sx, sy, sz, smx, smy, smz;  ///< (ns) source position (m), moment (A·m²)
  std::vector<std::int32_t> sindex, sgroup;       ///< (ns) moment index, group id
};

/// Field of one dipole m at offset r = p − p_i (eq. 1, softened when eps2 > 0):
///   h = (1/4π) (3 r (r·m) − q m) / q^{5/2},  q = |r|² + ε².
Vec3 dipole_field(const Vec3& r, const Vec3& m, double eps2 = 0.0);
/// Its Jacobian ∂h/∂r (symmetric; trace-free when ε = 0):
///   J = (1/4π) [ 3 (I (r·m) + r mᵀ + m rᵀ) / q^{5/2} − 15 r rᵀ (r·m) / q^{7/2} ].
Mat3 dipole_jacobian(const Vec3& r, const Vec3& m, double eps2 = 0.0);

/// H_j = H0 + Σ_{i≠j} h(p_j − p_i, m_i) at every moment j (A/m). With J != nullptr also
/// J_j = ∂H_j/∂p_j with the sources held fixed, summed over sources in other groups only
/// (moments of one rigid body exert no force on each other). Moments with m_i = 0 are
/// skipped. Threaded over targets (OpenMP); the sum order is fixed, so results are
/// deterministic for a given thread count.
void compute_fields(const MomentSet& set, const FieldOptions& opt, std::vector<Vec3>* H,
                    std::vector<Mat3>* J, FieldWorkspace* ws);

/// The field (and optionally Jacobian) of all moments of `set` at an arbitrary point p,
/// excluding moment `skip` (−1: none). Used by tools and tests.
Vec3 field_at(const MomentSet& set, const Vec3& p, double eps2 = 0.0, int skip = -1,
              Mat3* J = nullptr);

}  // namespace magsim::mag
