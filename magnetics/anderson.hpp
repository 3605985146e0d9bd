// magnetics/anderson.hpp — the fourth method (beyond the paper): solve the self-consistent
// magnetization M = f(H(M)) (eq. 10 curve, magnetics/PHYSICS.md) directly, by Picard iteration
// M ← f(H(M)) accelerated with Anderson mixing. Each iteration costs one field evaluation,
// like one Jacobi sweep of the dynamics, so iteration counts compare one to one.
// A solver below its dispatcher (relax_magnetization, magnetization.hpp): it includes the
// shared types of magnetization_types.hpp, never magnetization.hpp.
#pragma once

#include "magnetics/magnetization_types.hpp"

#include <functional>

namespace magsim::mag {

/// Anderson-accelerated Picard solve of M = f(H(M)) for every induced moment, warm-started
/// from the magnetizations in `set`. Per iteration k (x = M/Ms stacked, g = f(H(x))/Ms,
/// residual r = g − x):
///   γ = argmin ‖r_k − ΔR γ‖₂ over the last opt.anderson_depth differences,
///   x_{k+1} = x_k + β r_k − (ΔX + β ΔR) γ,   β = opt.anderson_damping,
/// then each |M_j| is clipped to Ms_j and the sub-pairs are set about M
/// (Magnetization::set_magnetization), so the dynamics can warm-start from the result.
/// Safeguards: columns that make the least-squares problem ill-conditioned are dropped; when
/// the residual grows by more than opt.anderson_restart_growth the history is cleared and β
/// halved (down to 1/8) for the next steps. Stops by the dynamics' rule (opt.criterion):
/// Residual — max_j |M_j − f(H_j)|/Ms_j of the evaluated iterate < opt.tol; Change — the
/// step's max_j |ΔM_j|/Ms_j < opt.tol, and that residual too — or at opt.max_iter.
/// Fields of the last evaluated iterate are left in ws->H.
RelaxStats relax_anderson(const MomentDesc& set, Magnetization* mz, const DynamicsOptions& opt,
                          MagWorkspace* ws,
                          const std::function<void(int, const Magnetization&)>& on_iteration = {});

/// One plain Picard sweep M_j ← f(H_j(M)) for every induced moment (eq. 10), sub-pairs set
/// about the new M. Returns max_j |ΔM_j|/Ms_j; fields of the old iterate are left in ws->H.
double picard_iteration(const MomentDesc& set, Magnetization* mz, const DynamicsOptions& opt,
                        MagWorkspace* ws);

}  // namespace magsim::mag
