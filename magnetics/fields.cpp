// magnetics/fields.cpp — the field options and the dispatch of compute_fields: the direct
// sum (dipole_field.cpp) or Barnes–Hut (barnes_hut.cpp), each given its own options.
#include "magnetics/fields.hpp"

#include "magnetics/dipole_field.hpp"

#include <cmath>
#include <sstream>
#include <utility>

namespace magsim::mag {

std::string validate(const FieldOptions& o) {
  std::ostringstream e;
  if (!(o.softening >= 0 && std::isfinite(o.softening)))
    e << "softening must be >= 0, got " << o.softening;
  else if (!(o.bh_theta >= 0 && o.bh_theta <= 1))
    e << "bh_theta must be in [0, 1], got " << o.bh_theta;
  else if (o.auto_threshold < 0) e << "auto_threshold must be >= 0, got " << o.auto_threshold;
  else if (o.bh_leaf_size < 1) e << "bh_leaf_size must be >= 1, got " << o.bh_leaf_size;
  else if (o.bh_group_size < 1) e << "bh_group_size must be >= 1, got " << o.bh_group_size;
  else if (o.bh_order < 1 || o.bh_order > 2) e << "bh_order must be 1 or 2, got " << o.bh_order;
  else return validate(o.near_field);
  return e.str();
}

bool pairs_bounded(const MomentDesc& set, const FieldOptions& opt) {
  if (!opt.bounded_pairs) return false;
  for (double a : set.radius)
    if (a > 0) return true;
  return false;
}

FieldSolver resolve_solver(const FieldOptions& opt, std::size_t n) {
  if (opt.solver != FieldSolver::Auto) return opt.solver;
  return n >= static_cast<std::size_t>(opt.auto_threshold) ? FieldSolver::BarnesHut
                                                            : FieldSolver::Direct;
}

// scratch: a copy starts with the packed arrays but builds its own tree
FieldWorkspace::FieldWorkspace(const FieldWorkspace& o) : src(o.src), near(o.near) {}
FieldWorkspace& FieldWorkspace::operator=(const FieldWorkspace& o) {
  if (this != &o) {
    FieldWorkspace t(o);
    *this = std::move(t);
  }
  return *this;
}

BarnesHutStats barnes_hut_stats(const FieldWorkspace& ws) {
  return ws.bh ? barnes_hut_stats(*ws.bh) : BarnesHutStats{};
}

void barnes_hut_forget_geometry(FieldWorkspace* ws) {
  if (ws->bh) barnes_hut_forget_geometry(ws->bh.get());
}

namespace {

DirectSumOptions direct_options(const MomentDesc& set, const FieldOptions& opt) {
  DirectSumOptions d;
  d.softening = opt.softening;
  d.bounded = pairs_bounded(set, opt);
  return d;
}

BarnesHutOptions barnes_hut_options(const MomentDesc& set, const FieldOptions& opt) {
  BarnesHutOptions b;
  b.softening = opt.softening;
  b.bounded = pairs_bounded(set, opt);
  b.theta = opt.bh_theta;
  b.leaf_size = opt.bh_leaf_size;
  b.group_size = opt.bh_group_size;
  b.order = opt.bh_order;
  b.near_float = opt.bh_near_float;
  b.far_float = opt.bh_far_float;
  return b;
}

}  // namespace

void compute_fields(const MomentDesc& set, const Magnetization& mz, const FieldOptions& opt,
                    std::vector<Vec3>* H, std::vector<Mat3>* J, FieldWorkspace* ws) {
  if (resolve_solver(opt, set.size()) == FieldSolver::BarnesHut) {
    if (!ws->bh) ws->bh.reset(new_barnes_hut_workspace());
    barnes_hut_fields(set, mz, barnes_hut_options(set, opt), H, J, ws->bh.get());
  } else {
    direct_sum_fields(set, mz, direct_options(set, opt), nullptr, H, J, &ws->src);
  }
  // the pair model's field on touching spheres (near_field.hpp; J stays the dipoles': the
  // model's forces are added by compute_forces)
  add_near_field(set, mz, opt.near_field, &ws->near, H);
}

void compute_fields_at(const MomentDesc& set, const Magnetization& mz, const FieldOptions& opt,
                       const std::vector<int>& targets, std::vector<Vec3>* H,
                       std::vector<Mat3>* J, FieldWorkspace* ws) {
  direct_sum_fields(set, mz, direct_options(set, opt), &targets, H, J, &ws->src);
}

}  // namespace magsim::mag
