// magnetics/near_field.cpp — the near-field pair model (near_field.hpp): the coupling table,
// the widened gap, the pair list, and the model's field, energy and forces.
#include "magnetics/near_field.hpp"
#include "magnetics/det_math.hpp"

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

// The table's nodes in x = ln g: first, last and step (computed once: every field evaluation
// reads them for every near pair)
struct TableAxis {
  double x0, xn, h;
};
const TableAxis& table_axis() {
  static const TableAxis t{dmath::log(kTableGapMin), dmath::log(kTableGapMax),
                           (dmath::log(kTableGapMax) - dmath::log(kTableGapMin)) / (kTableNodes - 1)};
  return t;
}
double table_step() { return table_axis().h; }

// Value and derivative in x of the spline (y, m) at x = ln G. Beyond the last node x_n:
// v = v_n e^{λ(x − x_n)}, λ = v'_n / v_n (a power law in G, C¹ at x_n: the table's corrections
// fall as G^−6 there); held at v_n if the end did not fall.
void spline_eval(const std::vector<double>& y, const std::vector<double>& m, double x,
                 double* v, double* dv) {
  const double h = table_axis().h, x0 = table_axis().x0, xn = table_axis().xn;
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
  else if (o.curve != Curve::Tanh && o.curve != Curve::Iron)
    e << "curve must be tanh or iron, got " << kCurveNames.name(o.curve);
  return e.str();
}

// g_e = g_m + g_s ln(1 + e^x), x = (g − g_m)/g_s (a softplus, finite for any x)
double pair_effective_gap(double g, double* dge_dg) {
  const double x = (g - kPairContactGap) / kPairSmoothGap;
  const double sp = x > 0 ? x + dmath::log1p(dmath::exp(-x)) : dmath::log1p(dmath::exp(x));
  if (dge_dg) *dge_dg = x > 0 ? 1.0 / (1.0 + dmath::exp(-x)) : dmath::exp(x) / (1.0 + dmath::exp(x));
  return kPairContactGap + kPairSmoothGap * sp;
}

PairCouplingTable::PairCouplingTable(double mu_r, Curve curve)
    : mu_r_(mu_r), curve_(curve), widen_(pair_widening(curve)) {
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

PairWidening pair_widening(Curve c) {
  if (c == Curve::Iron) return {kPairWidenScaleIron, kPairWidenPowerIron, kPairWidenShareIron};
  return {kPairWidenScale, kPairWidenPower};
}

// w = κ h^q; G = (1 − λ) g_e + B, B = (a⁴ + w⁴)^{1/4} = big s^{1/4}, a = λ g_e,
// s = 1 + r⁴, r = small/big ≤ 1: dG/dg_e = (1 − λ) + λ (a/B)³, dG/dh = (w/B)³ κ q h^{q−1},
// (big/B)³ = s^{1/4}/s and (small/B)³ = r³ s^{1/4}/s
double pair_blended_gap(const PairWidening& k, double ge, double h, double* dG_dge, double* dG_dh) {
  const double w = h > 0 ? k.scale * dmath::pow(h, k.power) : 0.0;
  const double dw = h > 0 ? k.power * w / h : 0.0;
  if (k.share == 0.0) {  // the sum, bit for bit
    *dG_dge = 1.0;
    *dG_dh = dw;
    return ge + w;
  }
  const double a = k.share * ge;  // > 0: g_e ≥ g_m
  const bool a_big = a >= w;
  const double big = a_big ? a : w, r = (a_big ? w : a) / big, r2 = r * r;
  const double s = 1.0 + r2 * r2, root = std::sqrt(std::sqrt(s));
  const double c_big = root / s, c_small = r2 * r * root / s;
  *dG_dge = (1.0 - k.share) + k.share * (a_big ? c_big : c_small);
  *dG_dh = (a_big ? c_small : c_big) * dw;
  return (1.0 - k.share) * ge + big * root;
}

double pair_widened_gap(double g, double h, double* dG_dg, double* dG_dh, Curve c) {
  double dge = 0, dGge = 0, dGh = 0;
  const double G = pair_blended_gap(pair_widening(c), pair_effective_gap(g, &dge), h, &dGge, &dGh);
  if (dG_dg) *dG_dg = dGge * dge;
  if (dG_dh) *dG_dh = dGh;
  return G;
}

// h = ζ/(3 √(1 − ζ²)), dh/dζ = (1 − ζ²)^{−3/2}/3
double pair_flux_field(double zeta, double* dh_dzeta) {
  constexpr double kZetaMax = 1.0 - 1e-9;
  const double z = std::clamp(zeta, 0.0, kZetaMax);
  const double c = 1.0 - z * z, r = std::sqrt(c);
  if (dh_dzeta) *dh_dzeta = zeta < kZetaMax ? 1.0 / (3.0 * c * r) : 0.0;
  return z / (3.0 * r);
}

// Δt(g, h) = spline(ln G(g, h)); ∂Δt/∂g = spline'(x) (∂G/∂g)/G, and so for h
PairCoupling PairCouplingTable::at(double g, double h) const {
  double dge = 0;
  const double ge = pair_effective_gap(g, &dge);
  return at_effective(ge, dge, h);
}

// G as pair_widened_gap, from g_e and dg_e/dg
PairCoupling PairCouplingTable::at_effective(double ge, double dge_dg, double h) const {
  double dGge = 0, dGh = 0;
  const double G = pair_blended_gap(widen_, ge, h, &dGge, &dGh);
  const double dGg = dGge * dge_dg;
  const double x = dmath::log(G);
  PairCoupling c;
  double d = 0;
  spline_eval(par_, par2_, x, &c.par, &d);
  c.dpar = d * dGg / G;
  c.dpar_dh = d * dGh / G;
  spline_eval(perp_, perp2_, x, &c.perp, &d);
  c.dperp = d * dGg / G;
  c.dperp_dh = d * dGh / G;
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

const PairCouplingTable& NearFieldWorkspace::table_for(const NearFieldOptions& opt) {
  if (table.empty() || table[0].mu_r() != opt.mu_r || table[0].curve() != opt.curve) {
    table.clear();
    table.emplace_back(opt.mu_r, opt.curve);
  }
  return table[0];
}

void find_near_pairs(const MomentDesc& set, NearFieldWorkspace* ws) {
  const std::size_t n = set.size();
  ws->cached = false;
  ws->pairs.clear();
  ws->a.assign(n, 0.0);
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
bool same_description(const MomentDesc& a, const MomentDesc& b) {
  return a.position == b.position && a.volume == b.volume && a.radius == b.radius &&
         a.group == b.group && a.kind == b.kind && a.Ms == b.Ms;
}

PairStatic static_of(const MomentDesc& set, const NearFieldWorkspace& ws, const NearPair& p) {
  PairStatic q;
  const Vec3 r = set.position[p.i] - set.position[p.j];
  q.rho = r.norm();
  q.a = ws.a[p.i];
  q.rhat = r / q.rho;
  q.g = q.rho / q.a - 2.0;
  q.ge = pair_effective_gap(q.g, &q.dge);
  double dS_dg = 0;
  q.S = pair_switch(q.g, &dS_dg);
  q.dS = dS_dg / q.a;
  // ν = 1 + (n_i + n_j)/2 − S_c(g): the other contacts of the pair's two balls
  const double Sc = pair_count_switch(q.g, &dS_dg);
  q.dSc = dS_dg / q.a;
  const double nu = std::max(1.0, 1.0 + 0.5 * (ws.count[p.i] + ws.count[p.j]) - Sc);
  q.w = dmath::pow(nu, -kPairShareCoupling);
  q.dw = -kPairShareCoupling * q.w / nu;
  return q;
}

// The pair geometry of `set`, rebuilt only when its description changed
const std::vector<PairStatic>& statics_of(const MomentDesc& set, NearFieldWorkspace* ws) {
  if (ws->cached && same_description(ws->key, set)) return ws->statics;
  find_near_pairs(set, ws);
  ws->statics.clear();
  for (const NearPair& p : ws->pairs) ws->statics.push_back(static_of(set, *ws, p));
  ws->key = set;
  ws->cached = true;
  return ws->statics;
}

// One pair at given moments: W = (A − B) P + B Q (E = −μ0 S w W), A, B = Δt∥, Δt⊥ / a³ at
// G(g, h(ζ̄)), P = (m_i·r̂)(m_j·r̂), Q = m_i·m_j, ζ̄ = (ζ_i + ζ_j)/2, ζ = |m|/(V Ms).
struct PairState {
  double A = 0, B = 0, dA = 0, dB = 0;  // and their ρ-derivatives
  double W = 0, Wh = 0;                 // W and ∂W/∂h
  double hz = 0, zeta = 0;              // dh/dζ̄, ζ̄
};

PairState state_of(const PairStatic& q, const PairCouplingTable& tab, const Vec3& mi, const Vec3& mj,
                   double ci, double cj) {
  // ci, cj = 1/(V Ms) of each ball
  PairState s;
  s.zeta = 0.5 * (mi.norm() * ci + mj.norm() * cj);
  const double h = pair_flux_field(s.zeta, &s.hz);
  const PairCoupling c = tab.at_effective(q.ge, q.dge, h);
  const double a3 = q.a * q.a * q.a;
  s.A = c.par / a3;
  s.B = c.perp / a3;
  s.dA = c.dpar / (a3 * q.a);
  s.dB = c.dperp / (a3 * q.a);
  const double P = mi.dot(q.rhat) * mj.dot(q.rhat), Q = mi.dot(mj);
  s.W = (s.A - s.B) * P + s.B * Q;
  s.Wh = (c.dpar_dh - c.dperp_dh) / a3 * P + c.dperp_dh / a3 * Q;
  return s;
}

// −(1/μ0) ∂E/∂m_i = S w [(A − B)(m_j·r̂) r̂ + B m_j + W_h (dh/dζ̄) ½ m̂_i/(V_i Ms_i)], and so for j
void pair_field(const PairStatic& q, const PairCouplingTable& tab, const Vec3& mi, const Vec3& mj,
                double ci, double cj, Vec3* Hi, Vec3* Hj) {
  const PairState s = state_of(q, tab, mi, mj, ci, cj);
  const double k = q.S * q.w, sat = 0.5 * k * s.Wh * s.hz;
  *Hi = k * ((s.A - s.B) * mj.dot(q.rhat) * q.rhat + s.B * mj);
  *Hj = k * ((s.A - s.B) * mi.dot(q.rhat) * q.rhat + s.B * mi);
  const double ni = mi.norm(), nj = mj.norm();
  if (ni > 0) *Hi += sat * ci / ni * mi;
  if (nj > 0) *Hj += sat * cj / nj * mj;
}

double inv_vms(const MomentDesc& set, int j) { return 1.0 / (set.volume[j] * set.Ms[j]); }
}  // namespace

void near_field_jacobian(const MomentDesc& set, const Magnetization& mz, const NearFieldOptions& opt,
                         NearFieldWorkspace* ws, std::vector<NearBlock>* out) {
  out->clear();
  if (opt.model != NearField::Pair) return;
  const std::vector<PairStatic>& st = statics_of(set, ws);
  const PairCouplingTable& tab = ws->table_for(opt);
  for (std::size_t n = 0; n < st.size(); ++n) {
    const int i = ws->pairs[n].i, j = ws->pairs[n].j;
    const int ids[2] = {i, j};
    const double ci = inv_vms(set, i), cj = inv_vms(set, j);
    Mat3 D[2][2];
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 3; ++c) {
        const double e = 1e-6 * set.Ms[ids[b]], V = set.volume[ids[b]];
        Vec3 m[2][2] = {{moment(set, mz, i), moment(set, mz, j)}, {moment(set, mz, i), moment(set, mz, j)}};
        m[0][b][c] += e * V;
        m[1][b][c] -= e * V;
        Vec3 Hp[2], Hm[2];
        pair_field(st[n], tab, m[0][0], m[0][1], ci, cj, &Hp[0], &Hp[1]);
        pair_field(st[n], tab, m[1][0], m[1][1], ci, cj, &Hm[0], &Hm[1]);
        for (int a = 0; a < 2; ++a) D[a][b].col(c) = (Hp[a] - Hm[a]) / (2 * e);
      }
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) out->push_back({ids[a], ids[b], D[a][b]});
  }
}

void add_near_field(const MomentDesc& set, const Magnetization& mz, const NearFieldOptions& opt,
                    NearFieldWorkspace* ws, std::vector<Vec3>* H) {
  if (opt.model != NearField::Pair) return;
  const std::vector<PairStatic>& st = statics_of(set, ws);
  const PairCouplingTable& tab = ws->table_for(opt);
  for (std::size_t n = 0; n < st.size(); ++n) {
    const int i = ws->pairs[n].i, j = ws->pairs[n].j;
    Vec3 Hi, Hj;
    pair_field(st[n], tab, moment(set, mz, i), moment(set, mz, j), inv_vms(set, i), inv_vms(set, j), &Hi, &Hj);
    (*H)[i] += Hi;
    (*H)[j] += Hj;
  }
}

namespace {
// Σ over the near pairs of term(geometry, state at mz)
template <class Term>
double sum_over_pairs(const MomentDesc& set, const Magnetization& mz, const NearFieldOptions& opt,
                      NearFieldWorkspace* ws, Term term) {
  if (opt.model != NearField::Pair) return 0.0;
  const std::vector<PairStatic>& st = statics_of(set, ws);
  const PairCouplingTable& tab = ws->table_for(opt);
  double sum = 0;
  for (std::size_t n = 0; n < st.size(); ++n) {
    const int i = ws->pairs[n].i, j = ws->pairs[n].j;
    sum += term(st[n], state_of(st[n], tab, moment(set, mz, i), moment(set, mz, j), inv_vms(set, i), inv_vms(set, j)));
  }
  return sum;
}
}  // namespace

// E_ij = −μ0 S w W
double near_field_energy(const MomentDesc& set, const Magnetization& mz,
                         const NearFieldOptions& opt, NearFieldWorkspace* ws) {
  return sum_over_pairs(set, mz, opt, ws,
                        [](const PairStatic& q, const PairState& s) { return -kMu0 * q.S * q.w * s.W; });
}

// ½ μ0 (m_i·H_i + m_j·H_j) of pair_field is −E_ij + ½ μ0 S w W_h (dh/dζ̄) ζ̄, so the excess
// E_ij + ½ μ0 Σ m·H_near is ½ μ0 S w W_h (dh/dζ̄) ζ̄ per pair
double near_field_coenergy_excess(const MomentDesc& set, const Magnetization& mz,
                                  const NearFieldOptions& opt, NearFieldWorkspace* ws) {
  return sum_over_pairs(set, mz, opt, ws, [](const PairStatic& q, const PairState& s) {
    return 0.5 * kMu0 * q.S * q.w * s.Wh * s.hz * s.zeta;
  });
}

// E = −μ0 S(g) w W at fixed moments (so fixed ζ̄ and h): r = p_i − p_j, ρ = |r|,
//   ∂W/∂r = [(∂A/∂ρ − ∂B/∂ρ) P + ∂B/∂ρ Q] r̂ + (A − B) ∇_r P,
//   ∇_r P = [(m_j·r̂)(m_i − (m_i·r̂) r̂) + (m_i·r̂)(m_j − (m_j·r̂) r̂)]/ρ,
//   F_i = μ0 w [S ∂W/∂r + W dS/dρ r̂],  F_j = −F_i;
// through ν_p = 1 + (n_i + n_j)/2 − S_c(g_p), with Λ_p = ∂(S w W)/∂ν = S w' W and
// λ_b = ½ Σ_{p ∋ b} Λ_p: every near pair c = (k, l) (p's own gap cancels in ν_p) adds
//   F_k = μ0 (λ_k + λ_l − Λ_c) (dS_c/dρ) r̂_c,  F_l = −F_k.
void add_near_field_forces(const MomentDesc& set, const Magnetization& mz,
                           const NearFieldOptions& opt, NearFieldWorkspace* ws,
                           std::vector<Vec3>* F, std::vector<Vec3>* /*tau*/) {
  if (opt.model != NearField::Pair) return;
  const std::vector<PairStatic>& st = statics_of(set, ws);
  const PairCouplingTable& tab = ws->table_for(opt);
  std::vector<double> Lam(st.size(), 0.0), lam(set.size(), 0.0);
  for (std::size_t n = 0; n < st.size(); ++n) {
    const PairStatic& q = st[n];
    const NearPair& p = ws->pairs[n];
    if (q.S == 0 && q.dS == 0) continue;
    const Vec3 mi = moment(set, mz, p.i), mj = moment(set, mz, p.j);
    const PairState s = state_of(q, tab, mi, mj, inv_vms(set, p.i), inv_vms(set, p.j));
    const double ui = mi.dot(q.rhat), uj = mj.dot(q.rhat);
    const double P = ui * uj, Q = mi.dot(mj);
    const Vec3 dP = (uj * (mi - ui * q.rhat) + ui * (mj - uj * q.rhat)) / q.rho;
    const Vec3 dW = ((s.dA - s.dB) * P + s.dB * Q) * q.rhat + (s.A - s.B) * dP;
    Lam[n] = q.S * q.dw * s.W;
    lam[p.i] += 0.5 * Lam[n];
    lam[p.j] += 0.5 * Lam[n];
    const Vec3 radial = kMu0 * q.w * (q.S * dW + s.W * q.dS * q.rhat);
    (*F)[p.i] += radial;
    (*F)[p.j] -= radial;
  }
  for (std::size_t n = 0; n < st.size(); ++n) {
    if (st[n].dSc == 0) continue;
    const NearPair& p = ws->pairs[n];
    const Vec3 f = kMu0 * (lam[p.i] + lam[p.j] - Lam[n]) * st[n].dSc * st[n].rhat;
    (*F)[p.i] += f;
    (*F)[p.j] -= f;
  }
}

}  // namespace magsim::mag
