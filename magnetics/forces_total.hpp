// magnetics/forces_total.hpp — ForceModel::ZeemanTotal, internal to forces.cpp (see the
// formulas at compute_forces in forces.hpp).
#pragma once

#include "magnetics/magnetization.hpp"

namespace magsim::mag::detail {

/// The ZeemanTotal forces and torques; ws->H and ws->J already hold the fields of `set`.
void zeeman_total_forces(const MomentSet& set, Curve curve, const FieldOptions& field,
                         MagWorkspace* ws, std::vector<Vec3>* F, std::vector<Vec3>* tau,
                         std::vector<Vec3>* F_classic, double tol, int max_iter);

}  // namespace magsim::mag::detail
