// magnetics/force_laws.cpp — the one-moment force and energy formulas of force_laws.hpp.
#include "magnetics/force_laws.hpp"

#include "magnetics/curves.hpp"

namespace magsim::mag {

// eq. 4 (order of products derived, see header): F = μ0 V J [A (2M + H) + M]
Vec3 zeeman_force(Curve curve, double V, double Ms, const Vec3& M, const Vec3& H, const Mat3& J) {
  const Mat3 A = curve_dMdH(curve, H, Ms);
  return kMu0 * V * (J * zeeman_effective_magnetization(A, M, H));
}

// eqs. 3–4: E = −m·B = −μ0 V M·(M + H)
double zeeman_energy(Curve curve, double V, double Ms, const Vec3& H) {
  const Vec3 M = curve_M(curve, H, Ms);
  return -kMu0 * V * M.dot(M + H);
}

// eq. 13: F = μ0 (m·∇)H; with ∇×H = 0 this is μ0 J m (eq. 14 written out)
Vec3 classic_force(const Vec3& m, const Mat3& J) { return kMu0 * (J * m); }

}  // namespace magsim::mag
