// magnetics/barnes_hut_tree.cpp — the Barnes–Hut octree (barnes_hut.cpp describes the
// algorithm): the Morton sort and split, each cell's expansion centre and radius, the target
// groups, and per call the packed sources and every cell's multipole.
#include "magnetics/barnes_hut_internal.hpp"

#include <cmath>

namespace magsim::mag::bh {

namespace {

// spreads the low 21 bits of v to every third bit
std::uint64_t spread3(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

int digit(std::uint64_t code, int level) {  // octant at depth `level` (0 = root split)
  return static_cast<int>((code >> (3 * (kMortonBits - 1 - level))) & 7);
}

void split_node(BarnesHutWorkspace* ws, int id, int level, int leaf_size) {
  const int b = ws->nodes[id].t0, e = ws->nodes[id].t1;
  if (e - b <= leaf_size) return;
  // skip the levels at which every moment falls in one octant
  while (level < kMortonBits &&
         digit(ws->keys[b].first, level) == digit(ws->keys[e - 1].first, level))
    ++level;
  if (level >= kMortonBits) return;  // coincident to 21 bits: one leaf
  int bounds[9];
  int k = 0;
  bounds[k++] = b;
  for (int i = b + 1; i < e; ++i)
    if (digit(ws->keys[i].first, level) != digit(ws->keys[i - 1].first, level)) bounds[k++] = i;
  bounds[k] = e;
  const int first = static_cast<int>(ws->nodes.size());
  ws->nodes.resize(first + k);
  ws->nodes[id].child = first;
  ws->nodes[id].nchild = k;
  for (int c = 0; c < k; ++c) {
    ws->nodes[first + c].t0 = bounds[c];
    ws->nodes[first + c].t1 = bounds[c + 1];
  }
  for (int c = 0; c < k; ++c) split_node(ws, first + c, level + 1, leaf_size);
}

void add_group(int g, int* gmin, int* gmax, std::uint64_t* mask) {
  if (g < 0) return;
  *gmin = std::min(*gmin, g);
  *gmax = std::max(*gmax, g);
  *mask |= std::uint64_t(1) << (g & 63);
}

// Adds a moment m at offset d from the centre to Q and X.
void add_moment(const double* d, const double* m, Node* nd) {
  for (int a = 0; a < 3; ++a) {
    for (int c = 0; c < 3; ++c) nd->Q[a][c] += m[a] * d[c];
    for (int c = 0; c < 3; ++c)
      for (int e = c; e < 3; ++e) nd->X[a][kPair[c][e]] += m[a] * d[c] * d[e];
  }
}

// Geometry of a node (once per tree): its expansion centre c, the centre of its nonzero
// sources weighted by their largest possible moments w_i (V_i Ms_i induced, |m_i|
// permanent) — of a leaf directly, of an inner node from its children's centres and total
// weights; the plain centroid where every w_i = 0. Unlike the |m|-weighted centre it does not
// move when the magnetizations change, so the tree and the lists stay valid, and unlike the
// plain centroid it stays near a strong magnet inside the cell. b = max |p_i − c|; and the
// groups of its sources that are bodies of several moments.
void node_geometry(BarnesHutWorkspace* ws, int id) {
  const detail::SourceBuffer& s = ws->src;
  Node& nd = ws->nodes[id];
  if (nd.s1 == nd.s0) return;
  double wc[3] = {0, 0, 0}, gc[3] = {0, 0, 0}, w = 0;
  if (nd.child < 0) {
    for (int k = nd.s0; k < nd.s1; ++k) {
      const double wk = ws->src_w[k];
      w += wk;
      wc[0] += wk * s.x[k]; wc[1] += wk * s.y[k]; wc[2] += wk * s.z[k];
      gc[0] += s.x[k]; gc[1] += s.y[k]; gc[2] += s.z[k];
      const int i = static_cast<int>(s.id[k]);
      if (ws->shared[i]) add_group(static_cast<int>(s.grp[k]), &nd.gmin, &nd.gmax, &nd.gmask);
    }
  } else {
    for (int c = nd.child; c < nd.child + nd.nchild; ++c) {
      const Node& ch = ws->nodes[c];
      const double cnt = ch.s1 - ch.s0;
      w += ch.w;
      for (int a = 0; a < 3; ++a) {
        wc[a] += ch.w * ch.c[a];
        gc[a] += cnt * ch.gc[a];
      }
      nd.gmin = std::min(nd.gmin, ch.gmin);
      nd.gmax = std::max(nd.gmax, ch.gmax);
      nd.gmask |= ch.gmask;
    }
  }
  nd.w = w;
  for (int a = 0; a < 3; ++a) {
    nd.gc[a] = gc[a] / (nd.s1 - nd.s0);
    nd.c[a] = w > 0 ? wc[a] / w : nd.gc[a];
  }
  double b2 = 0;
  for (int k = nd.s0; k < nd.s1; ++k) {
    const double d[3] = {s.x[k] - nd.c[0], s.y[k] - nd.c[1], s.z[k] - nd.c[2]};
    b2 = std::max(b2, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  }
  nd.b = std::sqrt(b2);
}

// Multipole of a leaf from its sources (d_i = p_i − c); of an inner node by shifting its
// children's: with d = d' + δ (δ = c_child − c): Q_ac += Q'_ac + M'_a δ_c,
// X_ace += X'_ace + δ_c Q'_ae + δ_e Q'_ac + δ_c δ_e M'_a.
void node_multipole(const detail::SourceBuffer& s, BarnesHutWorkspace* ws, int id) {
  Node& nd = ws->nodes[id];
  for (int a = 0; a < 3; ++a) {
    nd.M[a] = 0;
    for (int c = 0; c < 3; ++c) nd.Q[a][c] = 0;
    for (int c = 0; c < 6; ++c) nd.X[a][c] = 0;
  }
  if (nd.s1 == nd.s0) return;
  if (nd.child < 0) {
    for (int k = nd.s0; k < nd.s1; ++k) {
      const double d[3] = {s.x[k] - nd.c[0], s.y[k] - nd.c[1], s.z[k] - nd.c[2]};
      const double m[3] = {s.mx[k], s.my[k], s.mz[k]};
      for (int a = 0; a < 3; ++a) nd.M[a] += m[a];
      add_moment(d, m, &nd);
    }
    return;
  }
  for (int c = nd.child; c < nd.child + nd.nchild; ++c) {
    const Node& ch = ws->nodes[c];
    if (ch.s1 == ch.s0) continue;
    const double dl[3] = {ch.c[0] - nd.c[0], ch.c[1] - nd.c[1], ch.c[2] - nd.c[2]};
    for (int a = 0; a < 3; ++a) {
      nd.M[a] += ch.M[a];
      for (int cc = 0; cc < 3; ++cc) nd.Q[a][cc] += ch.Q[a][cc] + ch.M[a] * dl[cc];
      for (int cc = 0; cc < 3; ++cc)
        for (int e = cc; e < 3; ++e)
          nd.X[a][kPair[cc][e]] += ch.X[a][kPair[cc][e]] + dl[cc] * ch.Q[a][e] +
                                   dl[e] * ch.Q[a][cc] + dl[cc] * dl[e] * ch.M[a];
    }
  }
}

// The kernel's view of a cell: c, M, S = sym Q, tr S, O = sym X (fully symmetric), t.
void cell_fields(const Node& nd, double* f) {
  f[kCx] = nd.c[0]; f[kCy] = nd.c[1]; f[kCz] = nd.c[2];
  f[kMx] = nd.M[0]; f[kMy] = nd.M[1]; f[kMz] = nd.M[2];
  f[kSxx] = nd.Q[0][0]; f[kSyy] = nd.Q[1][1]; f[kSzz] = nd.Q[2][2];
  f[kSxy] = 0.5 * (nd.Q[0][1] + nd.Q[1][0]);
  f[kSxz] = 0.5 * (nd.Q[0][2] + nd.Q[2][0]);
  f[kSyz] = 0.5 * (nd.Q[1][2] + nd.Q[2][1]);
  f[kTrS] = f[kSxx] + f[kSyy] + f[kSzz];
  // O_abc = (X_a,bc + X_b,ac + X_c,ab)/3
  auto O = [&nd](int a, int b, int c) {
    return (nd.X[a][kPair[b][c]] + nd.X[b][kPair[a][c]] + nd.X[c][kPair[a][b]]) / 3.0;
  };
  f[kOxxx] = O(0, 0, 0); f[kOyyy] = O(1, 1, 1); f[kOzzz] = O(2, 2, 2);
  f[kOxxy] = O(0, 0, 1); f[kOxxz] = O(0, 0, 2); f[kOxyy] = O(0, 1, 1);
  f[kOyyz] = O(1, 1, 2); f[kOxzz] = O(0, 2, 2); f[kOyzz] = O(1, 2, 2);
  f[kOxyz] = O(0, 1, 2);
  f[kTx] = f[kOxxx] + f[kOxyy] + f[kOxzz];
  f[kTy] = f[kOxxy] + f[kOyyy] + f[kOyzz];
  f[kTz] = f[kOxxz] + f[kOyyz] + f[kOzzz];
}

void close_group(const MomentDesc& set, BarnesHutWorkspace* ws, int t0, int t1) {
  if (t1 <= t0) return;
  Group g;
  g.t0 = t0;
  g.t1 = t1;
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max()), hi = -lo;
  for (int t = t0; t < t1; ++t) {
    const int i = ws->order[t];
    lo = lo.cwiseMin(set.position[i]);
    hi = hi.cwiseMax(set.position[i]);
    if (ws->shared[i]) add_group(set.group[i], &g.tgmin, &g.tgmax, &g.tgmask);
  }
  const Vec3 c = 0.5 * (lo + hi);
  double b2 = 0;
  for (int t = t0; t < t1; ++t) b2 = std::max(b2, (set.position[ws->order[t]] - c).squaredNorm());
  for (int a = 0; a < 3; ++a) g.tc[a] = c[a];
  g.tb = std::sqrt(b2);
  ws->groups.push_back(g);
}

// A subtree of at most G moments is one group; below a larger node, consecutive children
// of at most G moments each are packed together up to G.
void make_groups(const MomentDesc& set, BarnesHutWorkspace* ws, int id, int G) {
  const Node nd = ws->nodes[id];
  if (nd.t1 - nd.t0 <= G || nd.child < 0) {
    close_group(set, ws, nd.t0, nd.t1);
    return;
  }
  int p0 = nd.t0, p1 = nd.t0;  // pending packed range
  for (int c = nd.child; c < nd.child + nd.nchild; ++c) {
    const int c0 = ws->nodes[c].t0, c1 = ws->nodes[c].t1;
    if (c1 - c0 > G) {
      close_group(set, ws, p0, p1);
      make_groups(set, ws, c, G);
      p0 = p1 = c1;
      continue;
    }
    if (p1 - p0 + c1 - c0 > G) {
      close_group(set, ws, p0, p1);
      p0 = c0;
    }
    p1 = c1;
  }
  close_group(set, ws, p0, p1);
}

// Which moments belong to a body (group ≥ 0) of several moments. Only those can bring a
// target's own body into a far cell: a cell accepted for a group of targets lies outside
// the targets' bounding sphere, so it never holds a target itself (a one-moment body).
void find_shared(const MomentDesc& set, BarnesHutWorkspace* ws) {
  const std::size_t n = set.size();
  ws->shared.assign(n, 0);
  std::int32_t gmax = -1;
  for (std::int32_t g : set.group) gmax = std::max(gmax, g);
  if (gmax < 0) return;
  if (static_cast<std::size_t>(gmax) <= 16 * n + 1024) {
    std::vector<int> count(static_cast<std::size_t>(gmax) + 1, 0);
    for (std::int32_t g : set.group)
      if (g >= 0) ++count[g];
    for (std::size_t i = 0; i < n; ++i) ws->shared[i] = set.group[i] >= 0 && count[set.group[i]] > 1;
    return;
  }
  std::vector<std::int32_t> sorted(set.group);
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 0; i < n; ++i) {
    if (set.group[i] < 0) continue;
    const auto r = std::equal_range(sorted.begin(), sorted.end(), set.group[i]);
    ws->shared[i] = r.second - r.first > 1;
  }
}

}  // namespace

// The geometry: Morton order, octree, node centres and radii, target groups. Depends on the
// positions, groups, which moments are nonzero, and the leaf and group sizes only.
void build_tree(const MomentDesc& set, const BarnesHutOptions& opt, BarnesHutWorkspace* ws) {
  const int n = static_cast<int>(set.size());
  find_shared(set, ws);
  // Morton codes on the bounding cube, sorted (ties by index: deterministic)
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max()), hi = -lo;
  for (const Vec3& p : set.position) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double side = std::max((hi - lo).maxCoeff(), 1e-300);
  const double cells = double(1 << kMortonBits);
  const double scale = cells / side;
  auto quant = [cells](double x) {
    return static_cast<std::uint64_t>(std::clamp(x, 0.0, cells - 1.0));
  };
  ws->keys.resize(n);
  for (int i = 0; i < n; ++i) {
    const Vec3 u = (set.position[i] - lo) * scale;
    ws->keys[i] = {spread3(quant(u.x())) << 2 | spread3(quant(u.y())) << 1 | spread3(quant(u.z())), i};
  }
  std::sort(ws->keys.begin(), ws->keys.end());
  ws->order.resize(n);
  for (int i = 0; i < n; ++i) ws->order[i] = ws->keys[i].second;

  // nonzero sources in tree order (moments filled in by update_multipoles)
  ws->src.clear();
  ws->src_w.clear();
  ws->src_prefix.resize(n + 1);
  for (int t = 0; t < n; ++t) {
    ws->src_prefix[t] = static_cast<int>(ws->src.size());
    const int i = ws->order[t];
    if (!ws->nz[i]) continue;
    const Vec3& p = set.position[i];
    ws->src.push(p.x(), p.y(), p.z(), 0.0, 0.0, 0.0, i, set.group[i], set.radius[i]);
    ws->src_w.push_back(ws->w[i]);
  }
  ws->src_prefix[n] = static_cast<int>(ws->src.size());
  const std::size_t ns = ws->src.size();
  ws->src_id32.resize(ns);
  ws->src_grp32.resize(ns);
  ws->src_radf.resize(ns);
  for (std::size_t k = 0; k < ns; ++k) {
    ws->src_id32[k] = static_cast<std::int32_t>(ws->src.id[k]);
    ws->src_grp32[k] = static_cast<std::int32_t>(ws->src.grp[k]);
    ws->src_radf[k] = static_cast<float>(ws->src.rad[k]);
  }

  ws->nodes.assign(1, Node{});
  ws->nodes[0].t1 = n;
  split_node(ws, 0, 0, std::max(1, opt.leaf_size));
  // geometry bottom-up (children have larger indices than their parent)
  const int nn = static_cast<int>(ws->nodes.size());
  for (int id = nn - 1; id >= 0; --id) {
    Node& nd = ws->nodes[id];
    nd.s0 = ws->src_prefix[nd.t0];
    nd.s1 = ws->src_prefix[nd.t1];
    node_geometry(ws, id);
  }
  ws->hot.resize(nn);
  for (int id = 0; id < nn; ++id) {
    const Node& nd = ws->nodes[id];
    ws->hot[id] = NodeHot{{nd.c[0], nd.c[1], nd.c[2]}, nd.b, nd.child, nd.nchild, nd.s0, nd.s1,
                          nd.gmin, nd.gmax, nd.gmask};
  }
  ws->groups.clear();
  make_groups(set, ws, 0, std::max(1, opt.group_size));
}

// The moments of this call: sources' moments, multipoles bottom-up, the kernel's cells.
void update_multipoles(const MomentDesc& set, const Magnetization& mz, BarnesHutWorkspace* ws) {
  detail::SourceBuffer& s = ws->src;
  const int ns = static_cast<int>(s.size());
  for (int k = 0; k < ns; ++k) {
    const Vec3 m = moment(set, mz, static_cast<std::size_t>(s.id[k]));
    s.mx[k] = m.x(); s.my[k] = m.y(); s.mz[k] = m.z();
  }
  // float copies for the float near field's gather (cheap; done whatever the options)
  const std::vector<double>* md[3] = {&s.mx, &s.my, &s.mz};
  for (int a = 0; a < 3; ++a) {
    ws->src_mf[a].resize(ns);
    for (int k = 0; k < ns; ++k) ws->src_mf[a][k] = static_cast<float>((*md[a])[k]);
  }
  const int nn = static_cast<int>(ws->nodes.size());
  for (int id = nn - 1; id >= 0; --id) node_multipole(s, ws, id);
  ws->cells.resize(static_cast<std::size_t>(nn) * kCellFields);
  for (int id = 0; id < nn; ++id) cell_fields(ws->nodes[id], &ws->cells[std::size_t(id) * kCellFields]);
}

}  // namespace magsim::mag::bh
