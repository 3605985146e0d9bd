// magnetics/forces_total.hpp — ForceModel::ZeemanTotal, internal to forces.cpp (see the
// formulas at compute_forces in forces.hpp).
#pragma once

#include "magnetics/magnetization.hpp"

namespace magsim::mag::detail {

/// The ZeemanTotal forces and torques; ws->H and ws->J already hold the fields of `set`.
void zeeman_total_forces(const MomentDesc& set, const Magnetization& mz, Curve curve,
                         const FieldOptions& field, MagWorkspace* ws, std::vector<Vec3>* F,
                         std::vector<Vec3>* tau, std::vector<Vec3>* F_classic, double tol,
                         int max_iter);

/// The permanent moments' own field (with H0; and its Jacobian when Jp != nullptr) at the
/// permanent moments, listed in *perm; *scratch receives `set` with every induced M zeroed.
void permanent_field(const MomentDesc& set, const Magnetization& mz, const FieldOptions& field,
                     MomentSet* scratch, std::vector<int>* perm, std::vector<Vec3>* Hp,
                     std::vector<Mat3>* Jp, FieldWorkspace* ws);

}  // namespace magsim::mag::detail
