// magnetics/barnes_hut_lists.cpp — per target group, the walk that lists far cells and near
// leaves (the multipole acceptance criterion of barnes_hut.cpp) and the gather of a group's
// cells and near sources into the thread's kernel buffers (double or float).
#include "magnetics/barnes_hut_internal.hpp"

#include <cmath>

namespace magsim::mag::bh {

namespace {

// May the cell hold a source of a body of several moments that one of the targets belongs to?
bool groups_overlap(const NodeHot& src, const Group& g) {
  return src.gmax >= 0 && g.tgmax >= 0 && src.gmin <= g.tgmax && g.tgmin <= src.gmax &&
         (src.gmask & g.tgmask) != 0;
}

// The length unit L of a group's float far cells (CellBufferF), returned as 1/L, a power of
// two (so the scaling is exact). Every target sees every listed cell's centre at
// |r| ≥ d_min = min R − b_t (R: centre to the group's centre; > 0 by the acceptance test)
// and at |r| ≤ d_max = max R + b_t. L = d_min rounded up to a power of two (so |r'| ≥ ½,
// and 1/|r'|¹¹ ≤ 2¹¹: no overflow), raised towards d_max / 1024 when the cells span more
// than three decades (so that |r'| ≤ ~1024 and 1/|r'|¹¹ ≥ 2⁻¹¹⁰ stays a normal float), but
// never above 256 d_min (then 1/|r'|¹¹ ≤ 2⁹⁹). Beyond those spans (d_max/d_min > 2.6e5) the
// highest powers of the farthest cells underflow towards 0 (their terms are negligible
// there); nothing overflows. Depends on the lists and the tree only: the same for fresh
// and reused geometry, whatever the thread.
double far_scale(const BarnesHutWorkspace& ws, const Group& g, const GroupLists& gl) {
  double r2min = std::numeric_limits<double>::infinity(), r2max = 0;
  for (const std::vector<int>* ids : {&gl.far_hj, &gl.far_h, &gl.far_j})
    for (int id : *ids) {
      const NodeHot& nd = ws.hot[id];
      const double dx = nd.c[0] - g.tc[0], dy = nd.c[1] - g.tc[1], dz = nd.c[2] - g.tc[2];
      const double r2 = dx * dx + dy * dy + dz * dz;
      r2min = std::min(r2min, r2);
      r2max = std::max(r2max, r2);
    }
  if (!(r2max > 0)) return 1.0;
  const double dmax = std::sqrt(r2max) + g.tb;
  double dmin = std::sqrt(r2min) - g.tb;
  if (!(dmin > 0)) dmin = dmax * 1e-6;  // (not reached: accepted cells lie outside the sphere)
  const double L = std::min(std::max(dmin, dmax / 1024.0), 256.0 * dmin);
  if (!(L > 0) || !std::isfinite(L)) return 1.0;
  int e = 0;
  std::frexp(L, &e);  // L = f 2^e, f ∈ [½, 1): 2^e ≥ L
  return std::ldexp(1.0, -e);
}

}  // namespace

// Walks the tree for one target group and fills its interaction lists (see file comment).
// min_gap: an accepted cell also keeps every source this far from every target (bounded
// pairs: 2 × the largest interaction radius, so that no far pair would need the bound).
void build_lists(const BarnesHutWorkspace& ws, const Group& g, double theta, double min_gap,
                 bool want_J, std::vector<std::pair<int, bool>>* stack, GroupLists* gl) {
  gl->far_hj.clear();
  gl->far_h.clear();
  gl->far_j.clear();
  gl->near.clear();
  gl->near_j.clear();
  stack->clear();
  stack->emplace_back(0, false);
  while (!stack->empty()) {
    const auto [id, j_only] = stack->back();
    stack->pop_back();
    const NodeHot& nd = ws.hot[id];
    if (nd.s1 == nd.s0) continue;
    const double dx = nd.c[0] - g.tc[0], dy = nd.c[1] - g.tc[1], dz = nd.c[2] - g.tc[2];
    const double R = std::sqrt(dx * dx + dy * dy + dz * dz);
    // multipole acceptance: every target of the group sees the cell under an angle < θ;
    // the margin keeps out (despite rounding) a cell holding a target itself (b = 0 at R = b_t)
    const bool accept = theta > 0 && R * (1.0 - 1e-12) > g.tb + nd.b && nd.b < theta * (R - g.tb) &&
                        R - g.tb - nd.b >= min_gap;
    const bool overlap = want_J && groups_overlap(nd, g);
    if (accept) {
      if (!want_J) {
        gl->far_h.push_back(id);
        continue;
      }
      if (!overlap) {
        (j_only ? gl->far_j : gl->far_hj).push_back(id);
        continue;
      }
      // the cell may hold sources of the group's own rigid bodies: its field from the
      // expansion, its Jacobian from deeper down
      if (!j_only) gl->far_h.push_back(id);
    }
    if (nd.child < 0) {
      ((accept || j_only) ? gl->near_j : gl->near).push_back(id);
      continue;
    }
    const bool child_j_only = j_only || accept;
    for (int c = nd.child + nd.nchild - 1; c >= nd.child; --c) stack->emplace_back(c, child_j_only);
  }
  gl->far_inv_scale = far_scale(ws, g, *gl);
}

// Copies a group's listed cells and near sources (with this call's moments) into the
// thread's kernel buffers, padded.
// With near_float the near sources go to the float buffers instead, relative to the group's
// centre g.tc.
// With far_float the far cells go to the float buffers, relative to g.tc and scaled by
// gl.far_inv_scale (CellBufferF).
void gather(const BarnesHutWorkspace& ws, const Group& g, const GroupLists& gl, bool near_float,
            bool far_float, ThreadScratch* th) {
  th->near.clear();
  th->near_j.clear();
  th->nearf.clear();
  th->nearf_j.clear();
  th->far_hj.clear();
  th->far_h.clear();
  th->far_j.clear();
  th->far_hjf.clear();
  th->far_hf.clear();
  th->far_jf.clear();
  auto cells = [&ws](const std::vector<int>& ids, CellBuffer* cb) {
    for (int id : ids) cb->push(&ws.cells[std::size_t(id) * kCellFields]);
    cb->pad();
  };
  auto cells_f = [&ws, &g, &gl](const std::vector<int>& ids, CellBufferF* cb) {
    for (int id : ids) cb->push(&ws.cells[std::size_t(id) * kCellFields], g.tc, gl.far_inv_scale);
    cb->pad();
  };
  if (far_float) {
    cells_f(gl.far_hj, &th->far_hjf);
    cells_f(gl.far_h, &th->far_hf);
    cells_f(gl.far_j, &th->far_jf);
  } else {
    cells(gl.far_hj, &th->far_hj);
    cells(gl.far_h, &th->far_h);
    cells(gl.far_j, &th->far_j);
  }
  auto leaves = [&ws](const std::vector<int>& ids, NearBuffer* nb) {
    for (int id : ids) nb->append(ws.src, ws.hot[id].s0, ws.hot[id].s1);
    nb->pad();
  };
  auto leaves_f = [&ws, &g](const std::vector<int>& ids, NearBufferF* nb) {
    for (int id : ids)
      nb->append(ws.src, ws.src_mf, ws.src_id32, ws.src_grp32, ws.src_radf, ws.hot[id].s0,
                 ws.hot[id].s1, g.tc);
    nb->pad();
  };
  if (near_float) {
    leaves_f(gl.near, &th->nearf);
    leaves_f(gl.near_j, &th->nearf_j);
  } else {
    leaves(gl.near, &th->near);
    leaves(gl.near_j, &th->near_j);
  }
}

}  // namespace magsim::mag::bh
