// magnetics/coenergy.cpp — the co-energy U* (formulas in coenergy.hpp).
#include "magnetics/coenergy.hpp"
#include "magnetics/det_math.hpp"

#include <algorithm>
#include <cmath>

namespace magsim::mag {

double curve_energy_density(Curve c, double Mnorm, double Ms) {
  const double x = std::min(Mnorm / Ms, 1.0);
  if (c == Curve::Kim) return Ms * Ms * x * x / 6.0;  // eq. 7: Ψ = |M|²/6
  if (c == Curve::Iron) {
    // f⁻¹ = Ms(atanh(x)/χ + x/3): Ψ = Ms²[x atanh x + ½ ln(1 − x²)]/χ + Ms² x²/6 = (3/χ) Ψ_tanh + Ms² x²/6
    return 3.0 / kIronChi * curve_energy_density(Curve::Tanh, Mnorm, Ms) + Ms * Ms * x * x / 6.0;
  }
  // eq. 10: Ψ = (Ms²/6)[(1 + x) ln(1 + x) + (1 − x) ln(1 − x)]; the series below x = 1e-3
  // (Ψ = (Ms²/6)(x² + x⁴/6 + x⁶/15 + …)) keeps the relative error at 1e-16 where log1p cancels
  if (x < 1e-3) {
    const double x2 = x * x;
    return Ms * Ms / 6.0 * x2 * (1.0 + x2 / 6.0);
  }
  const double tail = x < 1.0 ? (1.0 - x) * dmath::log1p(-x) : 0.0;  // (1 − x) ln(1 − x) → 0
  return Ms * Ms / 6.0 * ((1.0 + x) * dmath::log1p(x) + tail);
}

// U* = μ0 Σ_induced V Ψ(M) − ½ μ0 Σ m·(H − H0) − μ0 Σ m·H0
double magnetic_coenergy(const MomentDesc& set, const Magnetization& mz, Curve curve,
                         const std::vector<Vec3>& H) {
  if (H.size() != set.size()) return 0.0;
  double stored = 0.0, pairs = 0.0, uniform = 0.0;
  for (std::size_t j = 0; j < set.size(); ++j) {
    const Vec3 mj = moment(set, mz, j);
    if (set.kind[j] == MomentKind::Induced)
      stored += set.volume[j] * curve_energy_density(curve, mz.M[j].norm(), set.Ms[j]);
    pairs += mj.dot(H[j] - set.H0);
    uniform += mj.dot(set.H0);
  }
  return kMu0 * (stored - 0.5 * pairs - uniform);
}

}  // namespace magsim::mag
