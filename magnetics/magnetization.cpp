// magnetics/magnetization.cpp — one Jacobi sweep of the magnetization dynamics, and the
// loop that repeats it until every M has converged (paper Algorithm 1, first half).
//
// Each induced moment carries two sub-magnetizations of magnitude Ms; M = (M1 + M2)/2.
// All moments update from the fields of the previous iterate, so a sweep is one parallel
// loop after one field evaluation.
#include "magnetics/magnetization.hpp"
#include "magnetics/det_math.hpp"

#include "magnetics/anderson.hpp"
#include "magnetics/curves.hpp"
#include "magnetics/ground_truth.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace magsim::mag {

namespace {
constexpr double kHalfPi = 0.5 * kPi;
const double kSqrt3 = std::sqrt(3.0);
}  // namespace

std::string validate(const DynamicsOptions& o) {
  std::ostringstream e;
  if (!(o.dt >= 1e-9 && o.dt <= 1e-6)) e << "dt must be in [1e-9, 1e-6] s, got " << o.dt;
  else if (!(o.beta > 0 && std::isfinite(o.beta))) e << "beta must be > 0, got " << o.beta;
  else if (!(o.alpha > 0 && o.alpha <= 1)) e << "alpha must be in (0, 1], got " << o.alpha;
  else if (!(o.gamma_c_max >= 1.0 / 3.0 && std::isfinite(o.gamma_c_max)))
    e << "gamma_c_max must be >= 1/3 and finite, got " << o.gamma_c_max;
  else if (!(o.tol > 0 && o.tol < 1)) e << "tol must be in (0, 1), got " << o.tol;
  else if (o.max_iter < 1) e << "max_iter must be >= 1, got " << o.max_iter;
  else if (!(o.min_pair_angle > 0 && o.min_pair_angle < 1e-2))
    e << "min_pair_angle must be in (0, 0.01) rad, got " << o.min_pair_angle;
  else if (o.anderson_depth < 0 || o.anderson_depth > 50)
    e << "anderson_depth must be in [0, 50], got " << o.anderson_depth;
  else if (!(o.anderson_damping > 0 && o.anderson_damping <= 1))
    e << "anderson_damping must be in (0, 1], got " << o.anderson_damping;
  else if (!(o.anderson_restart_growth > 1 && std::isfinite(o.anderson_restart_growth)))
    e << "anderson_restart_growth must be > 1, got " << o.anderson_restart_growth;
  else if (const std::string c = curve_error(o.method, o.field.near_field.curve); !c.empty())
    e << "curve: " << c;
  else {
    const std::string f = validate(o.field);
    if (!f.empty()) return f;
  }
  return e.str();
}

// eq. 8–9: dθ/dt = −c Θ(θ), Θ = sin θ for θ < π/2, 2 − sin θ otherwise, c = β|H_eff|.
// Exact: on the upper branch G(θ) = (2/√3) atan((2 tan(θ/2) − 1)/√3) falls at rate c;
// on the sin branch tan(θ/2) falls as exp(−c t). θ therefore never reaches 0 in finite time.
double advance_theta(double theta, double c_dt, ThetaIntegrator integ) {
  if (!(c_dt > 0)) return theta;
  if (integ == ThetaIntegrator::Euler) {
    const double Th = theta < kHalfPi ? dmath::sin(theta) : 2.0 - dmath::sin(theta);
    return std::max(0.0, theta - c_dt * Th);
  }
  if (theta > kHalfPi) {
    const double s = dmath::sin(0.5 * theta), co = dmath::cos(0.5 * theta);
    const double G = 2.0 / kSqrt3 * dmath::atan2(2.0 * s - co, kSqrt3 * co);
    const double G_half = 2.0 / kSqrt3 * (kPi / 6.0);
    if (G - c_dt > G_half) {
      const double Gn = G - c_dt;
      const double u = 0.5 * (kSqrt3 * dmath::tan(0.5 * kSqrt3 * Gn) + 1.0);
      return 2.0 * dmath::atan(u);
    }
    c_dt -= G - G_half;
    theta = kHalfPi;
  }
  return 2.0 * dmath::atan(dmath::tan(0.5 * theta) * dmath::exp(-c_dt));
}

// eq. 11 (ours, damping-only LLG): H_eff = H − γ_C M, γ_C = min(atanh(x)/(3x), γ_max);
// eq. 5 (Kim 2018): H_eff = H − γ_D M
Vec3 effective_field(Method method, const DynamicsOptions& opt, const Vec3& H, const Vec3& M,
                     double Ms) {
  if (method == Method::Kim2018) return H - kGammaD * M;
  double bound = opt.gamma_c_max;
  if (opt.adaptive_gamma_bound) {
    // the bound never below γ_C at the solution, |H|/|f(H)| = (|H|/Ms)/tanh(3|H|/Ms),
    // so the fixed point H_eff = 0 ⇔ M = f(H) is kept exactly
    const double h = H.norm() / Ms;
    const double g_sol = h > 1e-4 ? h / dmath::tanh(3.0 * h) : (1.0 + 3.0 * h * h) / 3.0;
    // measured stability limit of the raised bound: k·γ ≤ 2, k = β Δt Ms (magnetics/PHYSICS.md)
    const double cap = std::min(opt.adaptive_gamma_cap, 2.0 / (opt.beta * opt.dt * Ms));
    if (g_sol <= cap) bound = std::max(bound, g_sol);
  }
  return H - gamma_c(M.norm() / Ms, bound) * M;
}

void realign_pair(const Vec3& Heff, double Ms, Vec3* M1, Vec3* M2) {
  const Vec3 M = 0.5 * (*M1 + *M2);
  const double n = M.norm();
  if (n < 1e-9 * Ms) return;  // the pair axis is M's only reference: nothing to re-align
  const Vec3 u = M / n;
  const Vec3 t = Heff - Heff.dot(u) * u;  // H_eff transverse to M
  const double tn = t.norm();
  if (tn < 1e-14 * (Heff.norm() + Ms)) return;
  Vec3 w = u.cross(t) / tn;  // ⊥ M and ⊥ t
  if (w.dot(*M1 - *M2) < 0) w = -w;  // the smaller of the two rotations
  const double c = std::min(n / Ms, 1.0);
  const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
  *M1 = Ms * (c * u + s * w);
  *M2 = Ms * (c * u - s * w);
}

namespace {

// Rotates Mk (|Mk| = Ms) in the plane of (Mk, H_eff) to the angle θ' from H_eff (eq. 8).
// `other` gives a deterministic rotation plane when Mk is antiparallel to H_eff.
void rotate_toward(const Vec3& h_hat, double c_dt, double Ms, ThetaIntegrator integ,
                   const Vec3& other, Vec3* Mk) {
  const Vec3 m_hat = *Mk / Ms;
  const double cos_t = std::clamp(m_hat.dot(h_hat), -1.0, 1.0);
  Vec3 e = m_hat - cos_t * h_hat;  // in-plane direction ⊥ H_eff
  double sin_t = e.norm();
  if (sin_t < 1e-300) {
    if (cos_t > 0) return;  // already on H_eff
    e = other - other.dot(h_hat) * h_hat;  // antiparallel: leave on the pair's side
    if (e.norm() < 1e-12 * Ms) e = any_perpendicular(h_hat);
    e.normalize();
  } else {
    e /= sin_t;
    if (integ == ThetaIntegrator::Exact && cos_t >= 0.0) {
      // θ ≤ π/2, the sin branch of eq. 9, exactly as advance_theta but without its four
      // trigonometric calls (they were a third of T_i in balls_up): with τ = tan(θ/2) =
      // sin θ / (1 + cos θ), τ' = τ e^{−cΔt}, cos θ' = (1 − τ'²)/(1 + τ'²),
      // sin θ' = 2τ'/(1 + τ'²)
      if (!(c_dt > 0)) return;
      const double tau = sin_t / (1.0 + cos_t) * dmath::exp(-c_dt);
      const double tau2 = tau * tau, inv = 1.0 / (1.0 + tau2);
      *Mk = Ms * (((1.0 - tau2) * inv) * h_hat + (2.0 * tau * inv) * e);
      return;
    }
  }
  const double theta = dmath::atan2(sin_t, cos_t);
  const double th = advance_theta(theta, c_dt, integ);
  *Mk = Ms * (dmath::cos(th) * h_hat + dmath::sin(th) * e);
}

// LLG (eq. 6) explicit step with γ scaled so that γα Ms/(1+α²) = β (magnetics/PHYSICS.md):
//   dM/dt = −(β/Ms) [ (1/α) M × H_eff + M × (M × H_eff) ],  then |M| ← Ms.
// Damping-only LLG drops the precession term.
void llg_step(bool precession, const DynamicsOptions& opt, double Ms, const Vec3& Heff,
              Vec3* Mk) {
  const Vec3 mxh = Mk->cross(Heff);
  Vec3 dM = Mk->cross(mxh);
  if (precession) dM += mxh / opt.alpha;
  *Mk -= (opt.dt * opt.beta / Ms) * dM;
  const double n = Mk->norm();
  if (n > 0) *Mk *= Ms / n;
}

// Keeps the half-angle between M1 and M2 at least φ_min (no collapse: once together they would stay so).
void keep_pair_apart(double Ms, double phi_min, Vec3* M1, Vec3* M2) {
  const Vec3 d = *M1 - *M2;
  const double dn = d.norm();
  if (dn >= 2.0 * Ms * dmath::sin(phi_min)) return;
  Vec3 u = *M1 + *M2;
  const double un = u.norm();
  u = un > 0 ? Vec3(u / un) : Vec3::UnitZ();
  Vec3 w = d - d.dot(u) * u;
  w = w.norm() > 1e-3 * dn && dn > 0 ? Vec3(w.normalized()) : any_perpendicular(u);
  *M1 = Ms * (dmath::cos(phi_min) * u + dmath::sin(phi_min) * w);
  *M2 = Ms * (dmath::cos(phi_min) * u - dmath::sin(phi_min) * w);
}

}  // namespace

void update_pair(Method method, const DynamicsOptions& opt, double Ms, const Vec3& Heff,
                 Vec3* M1, Vec3* M2) {
  switch (method) {
    case Method::OursRealigned:
      realign_pair(Heff, Ms, M1, M2);
      [[fallthrough]];
    case Method::Ours: {
      const double hn = Heff.norm();
      if (hn == 0.0) break;
      const Vec3 h_hat = Heff / hn;
      const double c_dt = opt.beta * hn * opt.dt;
      const Vec3 m1 = *M1;
      rotate_toward(h_hat, c_dt, Ms, opt.theta_integrator, *M2, M1);
      rotate_toward(h_hat, c_dt, Ms, opt.theta_integrator, m1, M2);
      break;
    }
    case Method::Kim2018:
      llg_step(true, opt, Ms, Heff, M1);
      llg_step(true, opt, Ms, Heff, M2);
      break;
    case Method::DampingLLG:
      llg_step(false, opt, Ms, Heff, M1);
      llg_step(false, opt, Ms, Heff, M2);
      break;
    case Method::Exact:
    case Method::Anderson:  // no dynamics: these methods set M = f(H) (see anderson.hpp)
      break;
  }
  keep_pair_apart(Ms, opt.min_pair_angle, M1, M2);
}

SweepStats magnetization_iteration(const MomentDesc& set, Magnetization* mz,
                                   const DynamicsOptions& opt, MagWorkspace* ws) {
  if (opt.method == Method::Anderson) {
    // a Picard step sets M = f(H): its change is the residual of the previous iterate
    const double c = picard_iteration(set, mz, opt, ws);
    return {c, c};
  }
  compute_fields(set, *mz, opt.field, &ws->H, nullptr, &ws->field);
  const long n = static_cast<long>(set.size());
  const Curve curve = curve_of(opt);
  double max_change = 0.0, max_res = 0.0;
#pragma omp parallel for schedule(static) reduction(max : max_change, max_res)
  for (long j = 0; j < n; ++j) {
    if (!set.solved(j)) continue;
    const double Ms = set.Ms[j];
    const Vec3& H = ws->H[j];
    Vec3& M1 = mz->M1[j];
    Vec3& M2 = mz->M2[j];
    if (!mz->seeded[j]) {
      // a new, unmagnetized moment: M1 = −M2, the pair axis ⊥ the field it feels
      const double hn = H.norm();
      const Vec3 w = hn > 0 ? any_perpendicular(H / hn) : Vec3(Vec3::UnitX());
      M1 = Ms * w;
      M2 = -Ms * w;
      mz->seeded[j] = 1;
    }
    const Vec3 M_old = mz->M[j];
    max_res = std::max(max_res, (M_old - curve_M(curve, H, Ms)).norm() / Ms);
    const Vec3 Heff = effective_field(opt.method, opt, H, M_old, Ms);
    update_pair(opt.method, opt, Ms, Heff, &M1, &M2);
    const Vec3 M_new = 0.5 * (M1 + M2);
    mz->M[j] = M_new;
    max_change = std::max(max_change, (M_new - M_old).norm() / Ms);
  }
  return {max_change, max_res};
}

RelaxStats relax_magnetization(
    const MomentDesc& set, Magnetization* mz, const DynamicsOptions& opt, MagWorkspace* ws,
    const std::function<void(int, const Magnetization&)>& on_iteration) {
  if (opt.method == Method::Exact) {
    const ExactStats ex = solve_exact(set, mz, curve_of(opt), opt.field);
    RelaxStats st;
    st.iterations = ex.newton_steps;
    st.converged = ex.converged;
    st.last_change = st.last_residual = ex.residual;
    if (on_iteration) on_iteration(st.iterations, *mz);
    return st;
  }
  if (opt.method == Method::Anderson) return relax_anderson(set, mz, opt, ws, on_iteration);
  RelaxStats st;
  for (int k = 1; k <= opt.max_iter; ++k) {
    const SweepStats sw = magnetization_iteration(set, mz, opt, ws);
    st.last_change = sw.change;
    st.last_residual = sw.residual;
    st.iterations = k;
    if (on_iteration) on_iteration(k, *mz);
    const double crit =
        opt.criterion == DynamicsOptions::Criterion::Residual ? sw.residual : sw.change;
    if (crit < opt.tol) {
      st.converged = true;
      break;
    }
  }
  return st;
}

RelaxStats relax_magnetization(MomentSet* set, const DynamicsOptions& opt, MagWorkspace* ws,
                               const std::function<void(int, const MomentSet&)>& on_iteration) {
  std::function<void(int, const Magnetization&)> on_sweep;
  if (on_iteration) on_sweep = [&](int k, const Magnetization&) { on_iteration(k, *set); };
  return relax_magnetization(*set, set, opt, ws, on_sweep);
}

}  // namespace magsim::mag
