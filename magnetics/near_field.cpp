// magnetics/near_field.cpp — the near-field pair model (near_field.hpp): the coupling table,
// the widened gap, the pair list, and the model's field, energy and forces.
#include "magnetics/near_field.hpp"
#include "magnetics/det_math.hpp"

#include "magnetics/dipole_field.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

namespace magsim::mag {

namespace {
#include "magnetics/near_field_table.inc"

constexpr double kMuMin = 10.0, kMuMax = 10000.0;

// Natural cubic spline second derivatives of y on a uniform grid (step h).
std::vector<double> spline_second(const std::vector<double>& y, double h) {
  const int n = static_cast<int>(y.size());
  std::vector<double> m(n, 0.0), c(n, 0.0), d(n, 0.0);
  // tridiagonal: m_{k-1} + 4 m_k + m_{k+1} = 6 (y_{k+1} − 2 y_k + y_{k−1}) / h², m_0 = m_{n−1} = 0
  for (int k = 1; k < n - 1; ++k) {
    const double rhs = 6.0 * (y[k + 1] - 2.0 * y[k] + y[k - 1]) / (h * h);
    const double denom = 4.0 - (k > 1 ? c[k - 1] : 0.0);
    c[k] = 1.0 / denom;
    d[k] = (rhs - (k > 1 ? d[k - 1] : 0.0)) / denom;
  }
  for (int k = n - 2; k >= 1; --k) m[k] = d[k] - c[k] * m[k + 1];
  return m;
}

double table_step() {
  return (dmath::log(kTableGapMax) - dmath::log(kTableGapMin)) / (kTableNodes - 1);
}

// Value and derivative in x of the spline (y, m) at x = ln G. Beyond the last node x_n:
// v = v_n e^{λ(x − x_n)}, λ = v'_n / v_n (a power law in G, C¹ at x_n: the table's corrections
// fall as G^−6 there); held at v_n if the end did not fall.
void spline_eval(const std::vector<double>& y, const std::vector<double>& m, double x,
                 double* v, double* dv) {
  const double h = table_step();
  const double x0 = dmath::log(kTableGapMin);
  const double xn = dmath::log(kTableGapMax);
  if (x > xn) {
    double vn = 0, dvn = 0;
    spline_eval(y, m, xn, &vn, &dvn);
    const double lam = (vn != 0 && dvn / vn < 0) ? dvn / vn : 0.0;
    *v = vn * dmath::exp(lam * (x - xn));
    *dv = lam * *v;
    return;
  }
  double s = (x - x0) / h;
  int k = static_cast<int>(std::floor(s));
  k = std::clamp(k, 0, kTableNodes - 2);
  const double t = s - k, u = 1.0 - t;
  *v = u * y[k] + t * y[k + 1] + h * h / 6.0 * ((u * u * u - u) * m[k] + (t * t * t - t) * m[k + 1]);
  *dv = (y[k + 1] - y[k]) / h + h / 6.0 * (-(3.0 * u * u - 1.0) * m[k] + (3.0 * t * t - 1.0) * m[k + 1]);
}

}  // namespace

std::string validate(const NearFieldOptions& o) {
  std::ostringstream e;
  if (!(o.mu_r >= kMuMin && o.mu_r <= kMuMax))
    e << "near-field mu_r must be in [" << kMuMin << ", " << kMuMax << "] (the table's span), got "
      << o.mu_r;
  return e.str();
}

// g_e = g_m + g_s ln(1 + e^x), x = (g − g_m)/g_s (a softplus, finite for any x)
double pair_effective_gap(double g, double* dge_dg) {
  const double x = (g - kPairContactGap) / kPairSmoothGap;
  const double sp = x > 0 ? x + dmath::log1p(dmath::exp(-x)) : dmath::log1p(dmath::exp(x));
  if (dge_dg) *dge_dg = x > 0 ? 1.0 / (1.0 + dmath::exp(-x)) : dmath::exp(x) / (1.0 + dmath::exp(x));
  return kPairContactGap + kPairSmoothGap * sp;
}

PairCouplingTable::PairCouplingTable(double mu_r) : mu_r_(mu_r) {
  // row r and weight w of μr between the tabulated ones, linear in ln μr
  int r = 0;
  while (r < kTableMuCount - 2 && mu_r > kTableMu[r + 1]) ++r;
  const double w = std::clamp(
      (dmath::log(mu_r) - dmath::log(kTableMu[r])) / (dmath::log(kTableMu[r + 1]) - dmath::log(kTableMu[r])),
      0.0, 1.0);
  par_.resize(kTableNodes);
  perp_.resize(kTableNodes);
  for (int k = 0; k < kTableNodes; ++k) {
    par_[k] = (1.0 - w) * kTableAxial[r][k] + w * kTableAxial[r + 1][k];
    perp_[k] = (1.0 - w) * kTableTransverse[r][k] + w * kTableTransverse[r + 1][k];
  }
  par2_ = spline_second(par_, table_step());
  perp2_ = spline_second(perp_, table_step());
}

// G = g_e(g) + s κ h^q (PHYSICS.md, "The near field"): dG/dg = dg_e/dg, dG/dh = s κ q h^{q−1}
double pair_widened_gap(double g, double h, double* dG_dg, double* dG_dh, double s) {
  double dge = 0;
  const double ge = pair_effective_gap(g, &dge);
  const double w = h > 0 ? s * kPairWidenScale * dmath::pow(h, kPairWidenPower) : 0.0;
  if (dG_dg) *dG_dg = dge;
  if (dG_dh) *dG_dh = h > 0 ? kPairWidenPower * w / h : 0.0;
  return ge + w;
}

// Δt(g, h, s) = spline(ln G(g, h, s)); ∂Δt/∂g = spline'(x) (∂G/∂g)/G, and so for h and s
// (∂G/∂s = κ h^q)
PairCoupling PairCouplingTable::at(double g, double h, double s) const {
  double dGg = 0, dGh = 0;
  const double G = pair_widened_gap(g, h, &dGg, &dGh, s);
  const double dGs = h > 0 ? kPairWidenScale * dmath::pow(h, kPairWidenPower) : 0.0;
  const double x = dmath::log(G);
  PairCoupling c;
  double d = 0;
  spline_eval(par_, par2_, x, &c.par, &d);
  c.dpar = d * dGg / G;
  c.dpar_dh = d * dGh / G;
  c.dpar_ds = d * dGs / G;
  spline_eval(perp_, perp2_, x, &c.perp, &d);
  c.dperp = d * dGg / G;
  c.dperp_dh = d * dGh / G;
  c.dperp_ds = d * dGs / G;
  return c;
}

namespace {
// 1 − (10 s³ − 15 s⁴ + 6 s⁵), s = (g − g_full)/(g_cut − g_full) ∈ [0, 1]
double quintic_step(double g, double g_full, double g_cut, double* dS_dg) {
  const double w = g_cut - g_full;
  const double s = (g - g_full) / w;
  if (s <= 0) {
    if (dS_dg) *dS_dg = 0;
    return 1.0;
  }
  if (s >= 1) {
    if (dS_dg) *dS_dg = 0;
    return 0.0;
  }
  if (dS_dg) *dS_dg = -30.0 * s * s * (1.0 - s) * (1.0 - s) / w;
  return 1.0 - s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
}
}  // namespace

double pair_switch(double g, double* dS_dg) { return quintic_step(g, kPairFullGap, kPairCutoffGap, dS_dg); }

double pair_count_switch(double g, double* dS_dg) {
  return quintic_step(g, kPairCountFullGap, kPairCountCutoffGap, dS_dg);
}

const PairCouplingTable& NearFieldWorkspace::table_for(double mu_r) {
  if (table.empty() || table[0].mu_r() != mu_r) {
    table.clear();
    table.emplace_back(mu_r);
  }
  return table[0];
}

void find_near_pairs(const MomentDesc& set, NearFieldWorkspace* ws) {
  const std::size_t n = set.size();
  ws->cached = false;
  ws->pairs.clear();
  ws->a.assign(n, 0.0);
  ws->perm.clear();
  for (std::size_t j = 0; j < n; ++j)
    if (set.kind[j] == MomentKind::Permanent) ws->perm.push_back(static_cast<int>(j));
  // moments per group: a sphere is the only moment of its body
  std::unordered_map<std::int32_t, int> count;
  for (std::size_t j = 0; j < n; ++j)
    if (set.group[j] >= 0) ++count[set.group[j]];
  double amax = 0;
  for (std::size_t j = 0; j < n; ++j) {
    if (set.kind[j] != MomentKind::Induced || !(set.volume[j] > 0)) continue;
    if (set.group[j] >= 0 && count[set.group[j]] != 1) continue;
    const double a = dmath::cbrt(3.0 * set.volume[j] / (4.0 * kPi));
    const double rad = j < set.radius.size() ? set.radius[j] : 0.0;
    if (rad > 0 && std::abs(rad - a) > 1e-6 * a) continue;
    ws->a[j] = a;
    amax = std::max(amax, a);
  }
  if (amax == 0) return;
  // uniform grid of cells one cut-off distance wide; neighbours are in the 27 cells around
  const double cell = (2.0 + kPairCutoffGap) * amax;
  auto key = [](long long x, long long y, long long z) {
    return ((x & 0x1FFFFF) << 42) | ((y & 0x1FFFFF) << 21) | (z & 0x1FFFFF);
  };
  ws->cells.clear();
  std::vector<long long> cx(n), cy(n), cz(n);
  for (std::size_t j = 0; j < n; ++j) {
    if (ws->a[j] == 0) continue;
    cx[j] = static_cast<long long>(std::floor(set.position[j].x() / cell));
    cy[j] = static_cast<long long>(std::floor(set.position[j].y() / cell));
    cz[j] = static_cast<long long>(std::floor(set.position[j].z() / cell));
    ws->cells.emplace_back(key(cx[j], cy[j], cz[j]), static_cast<int>(j));
  }
  std::sort(ws->cells.begin(), ws->cells.end());
  for (std::size_t j = 0; j < n; ++j) {
    if (ws->a[j] == 0) continue;
    const double aj = ws->a[j];
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          const long long k = key(cx[j] + dx, cy[j] + dy, cz[j] + dz);
          auto it = std::lower_bound(ws->cells.begin(), ws->cells.end(), std::make_pair(k, -1));
          for (; it != ws->cells.end() && it->first == k; ++it) {
            const int i = it->second;
            if (i <= static_cast<int>(j)) continue;
            if (std::abs(ws->a[i] - aj) > 1e-9 * aj) continue;  // identical spheres only
            const double d = (set.position[i] - set.position[j]).norm();
            if (d < (2.0 + kPairCutoffGap) * aj) ws->pairs.push_back({static_cast<int>(j), i});
          }
        }
  }
  std::sort(ws->pairs.begin(), ws->pairs.end(),
            [](const NearPair& p, const NearPair& q) { return p.i != q.i ? p.i < q.i : p.j < q.j; });
  // n_i = Σ_k S_c(g_ik): every contact is a near pair (kPairCountCutoffGap < kPairCutoffGap)
  ws->count.assign(n, 0.0);
  for (const NearPair& p : ws->pairs) {
    const double g = (set.position[p.i] - set.position[p.j]).norm() / ws->a[p.i] - 2.0;
    const double c = pair_count_switch(g);
    ws->count[p.i] += c;
    ws->count[p.j] += c;
  }
}

namespace {
// Everything one pair's energy, field and forces need.
struct PairGeometry {
  Vec3 rhat;
  double rho = 0, a = 0, g = 0;
  double A = 0, B = 0, dA = 0, dB = 0;  // Δt∥/a³, Δt⊥/a³ at G and d/dρ
  double hA = 0, hB = 0;                 // ∂A/∂h, ∂B/∂h
  double nA = 0, nB = 0;                 // ∂A/∂ν, ∂B/∂ν
  double S = 0, dS = 0;                  // switch and dS/dρ
  double w = 1, dw = 0;                  // ν^−β and d/dν
  double dSc = 0;                        // dS_c/dρ of the pair's own gap
  Vec3 Hhat = Vec3::Zero();              // direction of H_app
  double Ms = 0;
  Mat3 Japp = Mat3::Zero();              // ∂H_app/∂x at the midpoint
  Vec3 mid = Vec3::Zero();
};

PairGeometry geometry(const MomentDesc& set, const PairCouplingTable& tab,
                      const NearFieldWorkspace& ws, const NearPair& p, bool with_jacobian) {
  PairGeometry q;
  const Vec3 r = set.position[p.i] - set.position[p.j];
  q.rho = r.norm();
  q.a = ws.a[p.i];
  q.rhat = r / q.rho;
  q.g = q.rho / q.a - 2.0;
  double dS_dg = 0;
  q.S = pair_switch(q.g, &dS_dg);
  q.dS = dS_dg / q.a;
  // ν = 1 + (n_i + n_j)/2 − S_c(g): the other contacts of the pair's two balls
  const double Sc = pair_count_switch(q.g, &dS_dg);
  q.dSc = dS_dg / q.a;
  const double nu = std::max(1.0, 1.0 + 0.5 * (ws.count[p.i] + ws.count[p.j]) - Sc);
  q.w = dmath::pow(nu, -kPairShareCoupling);
  q.dw = -kPairShareCoupling * q.w / nu;
  const double sh = dmath::pow(nu, kPairShareWiden), dsh = kPairShareWiden * sh / nu;
  // H_app: the permanent moments' field and H0 at the midpoint
  q.mid = 0.5 * (set.position[p.i] + set.position[p.j]);
  Vec3 H = set.H0;
  for (const int k : ws.perm) {
    const Vec3& m = set.m_perm[k];
    H += dipole_field(q.mid - set.position[k], m);
    if (with_jacobian) q.Japp += dipole_jacobian(q.mid - set.position[k], m);
  }
  q.Ms = 0.5 * (set.Ms[p.i] + set.Ms[p.j]);
  const double Hn = H.norm();
  if (Hn > 0) q.Hhat = H / Hn;
  const PairCoupling c = tab.at(q.g, q.Ms > 0 ? Hn / q.Ms : 0.0, sh);
  const double a3 = q.a * q.a * q.a;
  q.A = c.par / a3;
  q.B = c.perp / a3;
  q.dA = c.dpar / (a3 * q.a);
  q.dB = c.dperp / (a3 * q.a);
  q.hA = c.dpar_dh / a3;
  q.hB = c.dperp_dh / a3;
  q.nA = c.dpar_ds * dsh / a3;
  q.nB = c.dperp_ds * dsh / a3;
  return q;
}

}  // namespace

namespace {
bool same_description(const MomentDesc& a, const MomentDesc& b) {
  return a.position == b.position && a.m_perm == b.m_perm && a.volume == b.volume &&
         a.radius == b.radius && a.group == b.group && a.kind == b.kind && a.Ms == b.Ms &&
         a.H0 == b.H0;
}

// K = S ν^−β ΔT(r) of every near pair, rebuilt only when the description or μr changed
const std::vector<NearCoupling>& couplings_of(const MomentDesc& set, const NearFieldOptions& opt,
                                              NearFieldWorkspace* ws) {
  if (ws->cached && ws->key_mu_r == opt.mu_r && same_description(ws->key, set)) return ws->couplings;
  find_near_pairs(set, ws);
  const PairCouplingTable& tab = ws->table_for(opt.mu_r);
  ws->couplings.clear();
  for (const NearPair& p : ws->pairs) {
    const PairGeometry q = geometry(set, tab, *ws, p, false);
    const Mat3 K = q.S * q.w * ((q.A - q.B) * (q.rhat * q.rhat.transpose()) + q.B * Mat3::Identity());
    ws->couplings.push_back({p.i, p.j, K});
  }
  ws->key = set;
  ws->key_mu_r = opt.mu_r;
  ws->cached = true;
  return ws->couplings;
}
}  // namespace

void near_field_couplings(const MomentDesc& set, const NearFieldOptions& opt,
                          NearFieldWorkspace* ws, std::vector<NearCoupling>* out) {
  out->clear();
  if (opt.model != NearField::Pair) return;
  *out = couplings_of(set, opt, ws);
}

void add_near_field(const MomentDesc& set, const Magnetization& mz, const NearFieldOptions& opt,
                    NearFieldWorkspace* ws, std::vector<Vec3>* H) {
  if (opt.model != NearField::Pair) return;
  for (const NearCoupling& c : couplings_of(set, opt, ws)) {
    (*H)[c.i] += c.K * moment(set, mz, c.j);
    (*H)[c.j] += c.K * moment(set, mz, c.i);
  }
}

// E_ij = −μ0 m_iᵀ K m_j,  K = S ν^−β ΔT
double near_field_energy(const MomentDesc& set, const Magnetization& mz,
                         const NearFieldOptions& opt, NearFieldWorkspace* ws) {
  if (opt.model != NearField::Pair) return 0.0;
  double E = 0;
  for (const NearCoupling& c : couplings_of(set, opt, ws))
    E -= kMu0 * moment(set, mz, c.i).dot(c.K * moment(set, mz, c.j));
  return E;
}

// E = −μ0 S(g) w W,  w = ν^−β,  W = (A − B) P + B Q,  P = (m_i·r̂)(m_j·r̂),  Q = m_i·m_j,
// A, B = Δt∥, Δt⊥ / a³ at G(g, h, ν); r = p_i − p_j, ρ = |r|, h = |H_app(x)|/Ms at x = (p_i + p_j)/2:
//   ∂W/∂r = [(∂A/∂ρ − ∂B/∂ρ) P + ∂B/∂ρ Q] r̂ + (A − B) ∇_r P,
//   ∇_r P = [(m_j·r̂)(m_i − (m_i·r̂) r̂) + (m_i·r̂)(m_j − (m_j·r̂) r̂)]/ρ,
//   ∇_x (S w W) = S w W_h J_app Ĥ / Ms,  W_h = (∂A/∂h − ∂B/∂h) P + ∂B/∂h Q  (J_app symmetric),
//   F_i = μ0 w [S ∂W/∂r + W dS/dρ r̂] + ½ μ0 ∇_x (S w W),  F_j = −μ0 w [S ∂W/∂r + W dS/dρ r̂] + ½ μ0 ∇_x (S w W),
//   permanent k (H_app ∋ h(x − p_k, m_k)):  F_k = −μ0 S w W_h/Ms J_k Ĥ,
//                                           τ_k = μ0 S w W_h/Ms m_k × h(x − p_k, Ĥ);
// through ν_p = 1 + (n_i + n_j)/2 − S_c(g_p), with Λ_p = ∂(S w W)/∂ν = S (w' W + w W_ν) and
// λ_b = ½ Σ_{p ∋ b} Λ_p: every near pair c = (k, l) (p's own gap cancels in ν_p) adds
//   F_k = μ0 (λ_k + λ_l − Λ_c) (dS_c/dρ) r̂_c,  F_l = −F_k.
void add_near_field_forces(const MomentDesc& set, const Magnetization& mz,
                           const NearFieldOptions& opt, NearFieldWorkspace* ws,
                           std::vector<Vec3>* F, std::vector<Vec3>* tau) {
  if (opt.model != NearField::Pair) return;
  couplings_of(set, opt, ws);  // the pair list of `set` (compute_fields has made it already)
  const PairCouplingTable& tab = ws->table_for(opt.mu_r);
  std::vector<double> Lam(ws->pairs.size(), 0.0), lam(set.size(), 0.0);
  std::vector<Vec3> rhat(ws->pairs.size());
  std::vector<double> dSc(ws->pairs.size(), 0.0);
  for (std::size_t n = 0; n < ws->pairs.size(); ++n) {
    const NearPair& p = ws->pairs[n];
    const PairGeometry q = geometry(set, tab, *ws, p, true);
    rhat[n] = q.rhat;
    dSc[n] = q.dSc;
    if (q.S == 0 && q.dS == 0) continue;
    const Vec3 mi = moment(set, mz, p.i), mj = moment(set, mz, p.j);
    const double ui = mi.dot(q.rhat), uj = mj.dot(q.rhat);
    const double P = ui * uj, Q = mi.dot(mj);
    const double W = (q.A - q.B) * P + q.B * Q;
    const Vec3 dP = (uj * (mi - ui * q.rhat) + ui * (mj - uj * q.rhat)) / q.rho;
    const Vec3 dW = ((q.dA - q.dB) * P + q.dB * Q) * q.rhat + (q.A - q.B) * dP;
    const double Wh = (q.hA - q.hB) * P + q.hB * Q;
    const double Wn = (q.nA - q.nB) * P + q.nB * Q;
    Lam[n] = q.S * (q.dw * W + q.w * Wn);
    lam[p.i] += 0.5 * Lam[n];
    lam[p.j] += 0.5 * Lam[n];
    const double kh = q.Ms > 0 ? q.S * q.w * Wh / q.Ms : 0.0;  // ∂(S w W)/∂|H_app|
    const Vec3 dx = kh * (q.Japp * q.Hhat);
    const Vec3 radial = q.w * (q.S * dW + W * q.dS * q.rhat);
    (*F)[p.i] += kMu0 * (radial + 0.5 * dx);
    (*F)[p.j] += kMu0 * (-radial + 0.5 * dx);
    if (kh == 0) continue;
    for (const int k : ws->perm) {
      const Vec3& mk = set.m_perm[k];
      const Vec3 rk = q.mid - set.position[k];
      (*F)[k] -= kMu0 * kh * (dipole_jacobian(rk, mk) * q.Hhat);
      if (tau) (*tau)[k] += kMu0 * kh * mk.cross(dipole_field(rk, q.Hhat));
    }
  }
  for (std::size_t n = 0; n < ws->pairs.size(); ++n) {
    if (dSc[n] == 0) continue;
    const NearPair& p = ws->pairs[n];
    const Vec3 f = kMu0 * (lam[p.i] + lam[p.j] - Lam[n]) * dSc[n] * rhat[n];
    (*F)[p.i] += f;
    (*F)[p.j] -= f;
  }
}

}  // namespace magsim::mag
