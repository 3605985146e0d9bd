// magnetics/barnes_hut.cpp — Barnes–Hut far-field approximation of the dipole sums: the
// driver. The stages live beside it: barnes_hut_tree.cpp (octree, multipoles),
// barnes_hut_lists.cpp (interaction lists, gather), barnes_hut_far.cpp (far-cell series);
// their types in barnes_hut_internal.hpp.
//
// The moments are sorted along a Morton curve and split into an octree whose leaves hold at
// most `leaf_size` moments. Every cell carries the multipole of its nonzero source moments
// about a centre c that does not depend on the moments — their centre weighted by their
// largest possible moments, V_i Ms_i (induced) or |m_i| (permanent) (d_i = p_i − c):
//   M = Σ m_i (dipole), S = sym Σ d_i ⊗ m_i (quadrupole order),
//   O = sym Σ d_i ⊗ d_i ⊗ m_i (octupole order, with order = 2).
// Targets come in groups of at most `group_size` (a small subtree, or sibling subtrees
// packed together). One walk of the tree per group lists the cells that every target of the
// group sees under an angle below θ (b < θ (R − b_t): b the cell's radius about c, R the
// distance from c to the group's centre, b_t the group's radius — the multipole acceptance
// criterion) and the leaves that are near. Near leaves are summed exactly by the direct SIMD
// kernel (field_kernel.hpp, with the self and same-group exclusions of the direct sum); far
// cells by the Taylor expansion of eq. 1 about c,
//   h_b(x) = Σ_i m_ia ∂_a∂_b G(r − d_i) = M_a ∂_a∂_b G − S_ac ∂_a∂_b∂_c G
//            + ½ O_ace ∂_a∂_b∂_c∂_e G − …,     G = 1/(4π √q),  r = x − c,  q = |r|² + ε²,
// (eq. 1 is h = ∂∂G·m; softening enters G exactly as in the direct sum), and the Jacobian
// J = ∂h/∂x of the same series; the first omitted term is smaller than the kept ones by
// about (b/R)^(order+1). A cell that may hold a source of a target's group gives the group
// its field only; its Jacobian comes from deeper cells (or exactly, leaf by leaf), so
// same-group sources stay out of J exactly. Only bodies of several moments count here: a
// one-moment body (a ball) can only meet itself, and an accepted cell never holds a target.
// Work per group does not depend on the thread that does it, so results are deterministic
// whatever the thread count.
//
// Near field in single precision (BarnesHutOptions::near_float, θ > 0): a group's near
// sources are gathered as float arrays with positions relative to the group's centre g.tc
// (the double difference rounded: ~1e-9 m for sources a few cm away; absolute coordinates
// never go to float), moments in float, ids and groups as int32 for the masks, padded to
// 16 — and summed by sum_pairs_f32 (pair_kernel.cpp: 16 lanes, partial sums in float,
// totals in double). The sources' moments are converted to float once per call and their
// ids and groups to int32 once per tree, so the gather converts positions only.
//
// Far cells in single precision (BarnesHutOptions::far_float, with the float near field):
// a group's cells are gathered into CellBufferF — centres relative to g.tc, every field in
// the group's length unit L (a power of two from the cells' distances, far_scale; chosen
// with the lists, so the same for fresh and reused geometry) — and summed by far_sum (barnes_hut_far.cpp)
// (the same series in float, 16 lanes; partial sums in float per chunk, totals in double,
// then × 1/(4π L³) or 1/(4π L⁴)). Otherwise (far_float or near_float false) the
// far cells stay in double.
//
// Reuse: the magnetization solvers evaluate the fields 5–35 times per step at the same
// positions with other moments. The tree, its centres and radii, the target groups and the
// interaction lists (node ids) depend on the positions, groups, which moments are nonzero,
// V Ms / |m_perm| and the leaf and group sizes (and the lists on θ and on whether J is
// wanted) only; while those are bitwise unchanged, a call redoes just the multipoles (one
// bottom-up pass) and the sums. A fresh call builds everything and then runs the same code,
// so reused and fresh results are bitwise the same.
#include "magnetics/barnes_hut_internal.hpp"

#include <omp.h>

#include <chrono>
#include <cmath>

namespace magsim::mag {

using namespace bh;

BarnesHutWorkspace* new_barnes_hut_workspace() { return new BarnesHutWorkspace; }

void BarnesHutWorkspaceDeleter::operator()(BarnesHutWorkspace* p) const { delete p; }

void barnes_hut_forget_geometry(BarnesHutWorkspace* ws) {
  ws->tree_valid = false;
  ws->lists_valid[0] = ws->lists_valid[1] = false;
}

BarnesHutStats barnes_hut_stats(const BarnesHutWorkspace& ws) { return ws.stats; }

void barnes_hut_fields(const MomentDesc& set, const Magnetization& mz,
                       const BarnesHutOptions& opt, std::vector<Vec3>* H, std::vector<Mat3>* J,
                       BarnesHutWorkspace* ws) {
  const auto t_start = std::chrono::steady_clock::now();
  const int n = static_cast<int>(set.size());
  H->resize(n);
  if (J) J->resize(n);
  ws->stats = BarnesHutStats{};
  if (n == 0) return;
  // reuse the geometry when nothing it depends on changed (bitwise)
  ws->nz.resize(n);
  ws->w.resize(n);
  for (int i = 0; i < n; ++i) {
    const Vec3 m = moment(set, mz, i);
    ws->nz[i] = !(m.x() == 0.0 && m.y() == 0.0 && m.z() == 0.0);
    ws->w[i] = set.kind[i] == MomentKind::Induced ? set.volume[i] * set.Ms[i] : m.norm();
  }
  const int leaf = std::max(1, opt.leaf_size), gsize = std::max(1, opt.group_size);
  const bool same_tree =
      ws->tree_valid && static_cast<int>(ws->key_pos.size()) == n && ws->key_leaf == leaf &&
      ws->key_group == gsize && ws->key_nz == ws->nz &&
      std::memcmp(ws->key_w.data(), ws->w.data(), n * sizeof(double)) == 0 &&
      std::memcmp(ws->key_pos.data(), set.position.data(), n * sizeof(Vec3)) == 0 &&
      std::memcmp(ws->key_grp.data(), set.group.data(), n * sizeof(std::int32_t)) == 0 &&
      std::memcmp(ws->key_rad.data(), set.radius.data(), n * sizeof(double)) == 0;
  if (!same_tree) {
    ws->tree_valid = false;
    ws->lists_valid[0] = ws->lists_valid[1] = false;
    build_tree(set, opt, ws);
    ws->key_pos = set.position;
    ws->key_grp = set.group;
    ws->key_rad = set.radius;
    ws->key_nz = ws->nz;
    ws->key_w = ws->w;
    ws->key_leaf = leaf;
    ws->key_group = gsize;
    ws->tree_valid = true;
  }
  const auto t_tree = std::chrono::steady_clock::now();
  update_multipoles(set, mz, ws);
  const auto t_built = std::chrono::steady_clock::now();
  const double eps2 = opt.softening * opt.softening;
  const float eps2f = static_cast<float>(eps2);
  // θ = 0 promises the direct sum: the near field (then everything) stays in double
  const bool near_float = opt.near_float && opt.theta > 0;
  // the far cells in float too (only with the near field in float: near_float = false
  // keeps the whole sum in double)
  const bool far_float = near_float && opt.far_float;
  const bool want_J = J != nullptr;
  const int mode = want_J ? 1 : 0;
  // bounded pairs: near leaves carry the radii; far cells keep 2 a_max of clearance
  const bool bounded = opt.bounded;
  double min_gap = 0.0;
  if (bounded)
    for (double a : set.radius) min_gap = std::max(min_gap, 2.0 * a);
  const bool new_lists = !ws->lists_valid[mode] || ws->lists_theta[mode] != opt.theta ||
                         ws->lists_gap[mode] != min_gap;
  const int order = opt.order;
  const int nthreads = omp_get_max_threads();
  if (static_cast<int>(ws->threads.size()) < nthreads) ws->threads.resize(nthreads);
  for (ThreadScratch& th : ws->threads) {
    th.near_pairs = th.far_cells = 0;
    th.lists_s = 0;
  }
  const long ngroups = static_cast<long>(ws->groups.size());
  std::vector<GroupLists>& lists = ws->lists[mode];
  if (new_lists) lists.resize(ngroups);
#pragma omp parallel
  {
    ThreadScratch& th = ws->threads[omp_get_thread_num()];
#pragma omp for schedule(dynamic, 1)
    for (long l = 0; l < ngroups; ++l) {
      const Group& g = ws->groups[l];
      const auto t_l0 = std::chrono::steady_clock::now();
      if (new_lists) build_lists(*ws, g, opt.theta, min_gap, want_J, &th.stack, &lists[l]);
      th.lists_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t_l0).count();
      gather(*ws, g, lists[l], near_float, far_float, &th);
      const detail::SourceView vn = detail::view_of(th.near, bounded, 0, th.near.size()),
                               vj = detail::view_of(th.near_j, bounded, 0, th.near_j.size());
      const detail::SourceViewF vnf = th.nearf.view(bounded), vjf = th.nearf_j.view(bounded);
      const long nt = g.t1 - g.t0;
      th.near_pairs += nt * static_cast<long>(vn.n + vj.n + vnf.n + vjf.n);
      th.far_cells += nt * static_cast<long>(th.far_hj.size() + th.far_h.size() + th.far_j.size() +
                                             16 * (th.far_hjf.blocks() + th.far_hf.blocks() +
                                                   th.far_jf.blocks()));
      // float far cells: unit L = 1/inv (exact powers of two), 4π and L³ (L⁴) undone in double
      const double inv = lists[l].far_inv_scale;
      const double sH = kInv4Pi * inv * inv * inv, sJ = sH * inv;
      const float eps2s = static_cast<float>(eps2 * inv * inv);
      for (int t = g.t0; t < g.t1; ++t) {
        const int i = ws->order[t];
        const Vec3& p = set.position[i];
        const double grp = set.group[i] >= 0 ? static_cast<double>(set.group[i])
                                             : std::numeric_limits<double>::quiet_NaN();
        const detail::Target tg{p.x(), p.y(), p.z(), static_cast<double>(i), grp, set.radius[i]};
        const double pp[3] = {p.x(), p.y(), p.z()};
        double h[3] = {0, 0, 0}, jac[6] = {0, 0, 0, 0, 0, 0}, unused[3] = {0, 0, 0};
        const detail::PairTerms terms = want_J ? detail::PairTerms::HJ : detail::PairTerms::H;
        if (near_float) {
          // relative to the group's centre (the difference in double, then rounded)
          const detail::TargetF tf{static_cast<float>(p.x() - g.tc[0]),
                                   static_cast<float>(p.y() - g.tc[1]),
                                   static_cast<float>(p.z() - g.tc[2]), static_cast<std::int32_t>(i),
                                   set.group[i] >= 0 ? set.group[i] : detail::kNoGroupF,
                                   static_cast<float>(set.radius[i])};
          detail::sum_pairs_f32(vnf, tf, eps2f, terms, h, jac);
          if (want_J) detail::sum_pairs_f32(vjf, tf, eps2f, detail::PairTerms::HJ, unused, jac);
        } else {
          detail::sum_pairs(vn, tg, eps2, terms, h, jac);
          if (want_J) detail::sum_pairs(vj, tg, eps2, detail::PairTerms::HJ, unused, jac);
        }
        if (far_float) {
          // the target relative to the group's centre, in the group's unit L
          const float pf[3] = {static_cast<float>((p.x() - g.tc[0]) * inv),
                               static_cast<float>((p.y() - g.tc[1]) * inv),
                               static_cast<float>((p.z() - g.tc[2]) * inv)};
          if (want_J) {
            far_sum(th.far_hjf, order, bh::FarTerms::HJ, pf, eps2s, sH, sJ, h, jac);
            far_sum(th.far_jf, order, bh::FarTerms::J, pf, eps2s, sH, sJ, h, jac);
          }
          far_sum(th.far_hf, order, bh::FarTerms::H, pf, eps2s, sH, sJ, h, jac);
        } else {
          if (want_J) {
            far_sum(th.far_hj, order, bh::FarTerms::HJ, pp, eps2, h, jac);
            far_sum(th.far_j, order, bh::FarTerms::J, pp, eps2, h, jac);
          }
          far_sum(th.far_h, order, bh::FarTerms::H, pp, eps2, h, jac);
        }
        (*H)[i] = set.H0 + Vec3(h[0], h[1], h[2]);
        if (want_J) {
          (*J)[i] << jac[0], jac[3], jac[4],
                     jac[3], jac[1], jac[5],
                     jac[4], jac[5], jac[2];
        }
      }
    }
  }
  ws->lists_valid[mode] = true;
  ws->lists_theta[mode] = opt.theta;
  ws->lists_gap[mode] = min_gap;
  const auto t_end = std::chrono::steady_clock::now();
  BarnesHutStats& st = ws->stats;
  st.nodes = static_cast<int>(ws->nodes.size());
  st.groups = static_cast<int>(ngroups);
  st.reused_tree = same_tree;
  st.reused_lists = !new_lists;
  long near_pairs = 0, far_cells = 0;  // summed as integers: the same whatever the threads
  for (const ThreadScratch& th : ws->threads) {
    near_pairs += th.near_pairs;
    far_cells += th.far_cells;
    st.lists_s += th.lists_s;
  }
  st.near_pairs_per_target = double(near_pairs) / n;
  st.far_cells_per_target = double(far_cells) / n;
  st.tree_s = std::chrono::duration<double>(t_tree - t_start).count();
  st.build_s = std::chrono::duration<double>(t_built - t_start).count();
  st.eval_s = std::chrono::duration<double>(t_end - t_built).count();
}

}  // namespace magsim::mag
