// magnetics/barnes_hut.cpp — Barnes–Hut far-field approximation of the dipole sums.
//
// The moments are sorted along a Morton curve and split into an octree whose leaves hold at
// most `bh_leaf_size` moments. Every cell carries the multipole of its nonzero source moments
// about a centre c that does not depend on the moments — their centre weighted by their
// largest possible moments, V_i Ms_i (induced) or |m_i| (permanent) (d_i = p_i − c):
//   M = Σ m_i (dipole), S = sym Σ d_i ⊗ m_i (quadrupole order),
//   O = sym Σ d_i ⊗ d_i ⊗ m_i (octupole order, with bh_order = 2).
// Targets come in groups of at most `bh_group_size` (a small subtree, or sibling subtrees
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
// Near field in single precision (FieldOptions::bh_near_float, θ > 0): a group's near
// sources are gathered as float arrays with positions relative to the group's centre g.tc
// (the double difference rounded: ~1e-9 m for sources a few cm away; absolute coordinates
// never go to float), moments in float, ids and groups as int32 for the masks, padded to
// 16 — and summed by sum_pairs_f32 (near_kernel_f32.cpp: 16 lanes, partial sums in float,
// totals in double). The sources' moments are converted to float once per call and their
// ids and groups to int32 once per tree, so the gather converts positions only.
//
// Far cells in single precision (FieldOptions::bh_far_float, with the float near field):
// a group's cells are gathered into CellBufferF — centres relative to g.tc, every field in
// the group's length unit L (a power of two from the cells' distances, far_scale; chosen
// with the lists, so the same for fresh and reused geometry) — and summed by far_sum_f32
// (the same series in float, 16 lanes; partial sums in float per chunk, totals in double,
// then × 1/(4π L³) or 1/(4π L⁴)). Otherwise (bh_far_float or bh_near_float false) the
// far cells stay in double.
//
// Reuse: the magnetization solvers evaluate the fields 5–35 times per step at the same
// positions with other moments. The tree, its centres and radii, the target groups and the
// interaction lists (node ids) depend on the positions, groups, which moments are nonzero,
// V Ms / |m_perm| and the leaf and group sizes (and the lists on θ and on whether J is
// wanted) only; while those are bitwise unchanged, a call redoes just the multipoles (one
// bottom-up pass) and the sums. A fresh call builds everything and then runs the same code,
// so reused and fresh results are bitwise the same.
#include "magnetics/barnes_hut.hpp"

#include "magnetics/field_kernel.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace magsim::mag {

namespace {

using detail::kInv4Pi;
constexpr int kMortonBits = 21;  // per axis

// index of the symmetric pair (c, e) in xx, yy, zz, xy, xz, yz order
constexpr int kPair[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};

struct Node {
  int child = -1;  // first child (children are contiguous); −1 = leaf
  int nchild = 0;
  int t0 = 0, t1 = 0;  // range of moments in tree order
  int s0 = 0, s1 = 0;  // range of nonzero sources in the packed, tree-ordered arrays
  double c[3] = {0, 0, 0};   // expansion centre (see node_geometry)
  double gc[3] = {0, 0, 0};  // centroid of the sources
  double w = 0;              // Σ w_i, the sources' largest possible |m_i| (A·m²)
  double b = 0;              // max |p_i − c| over the sources (m)
  double M[3] = {0, 0, 0};  // Σ m_i
  double Q[3][3] = {};      // Q[a][c] = Σ m_ia d_ic (full, for shifting)
  double X[3][6] = {};      // X[a][ce] = Σ m_ia d_ic d_ie (symmetric in c, e; for shifting)
  // groups (≥ 0) of the sources that belong to a body of several moments
  int gmin = std::numeric_limits<int>::max(), gmax = -1;
  std::uint64_t gmask = 0;
};

// What the list walk reads of a node (one cache line; Node holds the build-time rest).
struct alignas(64) NodeHot {
  double c[3];  // expansion centre
  double b;     // radius of the sources about c
  int child, nchild, s0, s1;
  int gmin, gmax;
  std::uint64_t gmask;
};

// A group of targets that share one interaction list: consecutive in tree order, within
// one cell (a whole small subtree, or sibling subtrees packed together).
struct Group {
  int t0 = 0, t1 = 0;        // range of moments in tree order
  double tc[3] = {0, 0, 0};  // bounding sphere of the targets
  double tb = 0;
  // their groups (≥ 0) that are bodies of several moments
  int tgmin = std::numeric_limits<int>::max(), tgmax = -1;
  std::uint64_t tgmask = 0;
};

// The fields of a far cell as the kernel reads them.
enum CellField {
  kCx, kCy, kCz, kMx, kMy, kMz,
  kSxx, kSyy, kSzz, kSxy, kSxz, kSyz, kTrS,                         // S and tr S
  kOxxx, kOyyy, kOzzz, kOxxy, kOxxz, kOxyy, kOyyz, kOxzz, kOyzz, kOxyz,  // O (symmetric)
  kTx, kTy, kTz,                                                  // t_a = O_abb
  kCellFields
};

// Blocks of 8 cells, field by field ([block][field][lane]), so that the kernel reads every
// field of a block at a fixed offset from one pointer.
struct CellBuffer {
  static constexpr std::size_t kBlock = 8 * kCellFields;
  std::vector<double> d;  // storage (grown, never shrunk)
  std::size_t n = 0;      // cells held
  std::size_t size() const { return n; }
  const double* block(std::size_t b) const { return d.data() + b * kBlock; }
  void clear() { n = 0; }
  void push(const double* vals) {
    if ((n / 8 + 1) * kBlock > d.size()) d.resize(std::max<std::size_t>(8 * kBlock, 2 * d.size()));
    double* blk = d.data() + (n / 8) * kBlock + n % 8;
    for (int k = 0; k < kCellFields; ++k) blk[8 * k] = vals[k];
    ++n;
  }
  // zero cells far away add exactly 0 (every term is linear in M, S or O)
  void pad() {
    double z[kCellFields] = {};
    z[kCx] = z[kCy] = z[kCz] = detail::kPadPosition;
    while (n % 8 != 0) push(z);
  }
};

// The same in float (FieldOptions::bh_far_float), blocks of 16 cells ([block][field][lane]),
// as one group's kernel reads them: every field scaled to the group's length unit L (a power
// of two, GroupLists::far_inv_scale = 1/L; see far_scale): the centre relative to the group's
// centre g.tc, c' = (c − g.tc)/L (the double difference, scaled exactly, then rounded —
// absolute world coordinates never go to float), M' = M, S' = S/L, tr S' = tr S/L,
// O' = O/L², t' = t/L². Then the series in r' = r/L gives L³ · 4π h and L⁴ · 4π J exactly as
// the series in r does (each term is homogeneous), and with |r'| ≥ ½ (see far_scale) no
// power of 1/|r'| up to the 11th can overflow. Lanes past `n` hold zeros; the kernels mask
// them (1/|r'| := 0), so no padding position is needed.
struct CellBufferF {
  static constexpr std::size_t kBlock = 16 * kCellFields;
  std::vector<float> d;  // storage (grown, never shrunk)
  std::size_t n = 0;     // cells held
  std::size_t size() const { return n; }
  std::size_t blocks() const { return (n + 15) / 16; }
  const float* block(std::size_t b) const { return d.data() + b * kBlock; }
  void clear() { n = 0; }
  // cell fields f (double, absolute centre) → scaled float relative to the centre tc
  void push(const double* f, const double* tc, double inv) {
    if ((n / 16 + 1) * kBlock > d.size()) d.resize(std::max<std::size_t>(4 * kBlock, 2 * d.size()));
    float* blk = d.data() + (n / 16) * kBlock + n % 16;
    const double inv2 = inv * inv;
    static_assert(kCx == 0 && kMx == 3 && kSxx == 6 && kOxxx == 13 && kTz + 1 == kCellFields);
    for (int k = kCx; k <= kCz; ++k) blk[16 * k] = static_cast<float>((f[k] - tc[k]) * inv);
    for (int k = kMx; k <= kMz; ++k) blk[16 * k] = static_cast<float>(f[k]);
    for (int k = kSxx; k <= kTrS; ++k) blk[16 * k] = static_cast<float>(f[k] * inv);
    for (int k = kOxxx; k < kCellFields; ++k) blk[16 * k] = static_cast<float>(f[k] * inv2);  // O, t
    ++n;
  }
  // zeros in the rest of the last block (masked by the kernels)
  void pad() {
    if (n % 16 == 0) return;
    float* blk = d.data() + (n / 16) * kBlock;
    for (int k = 0; k < kCellFields; ++k)
      for (std::size_t l = n % 16; l < 16; ++l) blk[16 * k + l] = 0.0f;
  }
};

// Near sources gathered for one group: whole leaves copied from the tree-ordered arrays.
struct NearBuffer {
  std::vector<double> a[9];  // x, y, z, mx, my, mz, id, grp, rad (grown, never shrunk)
  std::size_t n = 0;
  void clear() { n = 0; }
  void reserve(std::size_t m) {
    if (m > a[0].size())
      for (auto& v : a) v.resize(std::max(m, 2 * a[0].size()));
  }
  void append(const detail::SourceBuffer& s, int s0, int s1) {
    reserve(n + (s1 - s0) + detail::kSourcePad);
    const std::vector<double>* src[9] = {&s.x,  &s.y,  &s.z,   &s.mx, &s.my,
                                         &s.mz, &s.id, &s.grp, &s.rad};
    for (int k = 0; k < 9; ++k) std::copy(src[k]->begin() + s0, src[k]->begin() + s1, a[k].begin() + n);
    n += s1 - s0;
  }
  void pad() {
    reserve(n + detail::kSourcePad);
    while (n % detail::kSourcePad != 0) {
      for (int k = 0; k < 3; ++k) a[k][n] = detail::kPadPosition;
      for (int k = 3; k < 6; ++k) a[k][n] = 0.0;
      a[6][n] = a[7][n] = -1.0;
      a[8][n] = 0.0;
      ++n;
    }
  }
  // bounded: pass the radii (bounded pairs), else unbounded point dipoles
  detail::SourceView view(bool bounded) const {
    return detail::SourceView{a[0].data(), a[1].data(), a[2].data(), a[3].data(),
                              a[4].data(), a[5].data(), a[6].data(), a[7].data(), n,
                              bounded ? a[8].data() : nullptr};
  }
};

// The same, in float for sum_pairs_f32 (FieldOptions::bh_near_float): positions relative
// to the group's centre (converted from the double difference; never absolute coordinates
// in float), moments, and the ids and groups as int32 for the masks.
struct NearBufferF {
  std::vector<float> a[6];        // x, y, z (relative to the centre), mx, my, mz
  std::vector<std::int32_t> id, grp;
  std::vector<float> rad;         // interaction radii (m)
  std::size_t n = 0;
  void clear() { n = 0; }
  void reserve(std::size_t m) {
    if (m <= id.size()) return;
    const std::size_t sz = std::max(m, 2 * id.size());
    for (auto& v : a) v.resize(sz);
    id.resize(sz);
    grp.resize(sz);
    rad.resize(sz);
  }
  // sources s0..s1 of s; their moments, ids and groups already in float / int32 (mf, id32,
  // grp32: the workspace's copies, converted once per call / per tree)
  void append(const detail::SourceBuffer& s, const std::vector<float>* mf,
              const std::vector<std::int32_t>& id32, const std::vector<std::int32_t>& grp32,
              const std::vector<float>& radf, int s0, int s1, const double* c) {
    const std::size_t m = static_cast<std::size_t>(s1 - s0);
    reserve(n + m + detail::kSourcePadF);
    const double* src[3] = {s.x.data() + s0, s.y.data() + s0, s.z.data() + s0};
    for (int a3 = 0; a3 < 3; ++a3) {  // separate loops: vectorized (vcvtpd2ps)
      const double* __restrict in = src[a3];
      float* __restrict out = a[a3].data() + n;
      const double ca = c[a3];
      for (std::size_t k = 0; k < m; ++k) out[k] = static_cast<float>(in[k] - ca);
    }
    for (int a3 = 0; a3 < 3; ++a3)
      std::memcpy(a[3 + a3].data() + n, mf[a3].data() + s0, m * sizeof(float));
    std::memcpy(id.data() + n, id32.data() + s0, m * sizeof(std::int32_t));
    std::memcpy(grp.data() + n, grp32.data() + s0, m * sizeof(std::int32_t));  // −1: none
    std::memcpy(rad.data() + n, radf.data() + s0, m * sizeof(float));
    n += m;
  }
  void pad() {
    reserve(n + detail::kSourcePadF);
    while (n % detail::kSourcePadF != 0) {
      for (int k = 0; k < 3; ++k) a[k][n] = detail::kPadPositionF;
      for (int k = 3; k < 6; ++k) a[k][n] = 0.0f;
      id[n] = grp[n] = -1;
      rad[n] = 0.0f;
      ++n;
    }
  }
  detail::SourceViewF view(bool bounded) const {
    return detail::SourceViewF{a[0].data(), a[1].data(), a[2].data(), a[3].data(),
                               a[4].data(), a[5].data(), id.data(),   grp.data(),
                               n,           bounded ? rad.data() : nullptr};
  }
};

// A group's interaction lists as node ids: far cells (field and Jacobian / field only /
// Jacobian only) and near leaves (exact: field and Jacobian / Jacobian only).
struct GroupLists {
  std::vector<int> far_hj, far_h, far_j, near, near_j;
  double far_inv_scale = 1.0;  // 1/L of the float far cells (a power of two; far_scale)
};

struct ThreadScratch {
  NearBuffer near, near_j;                  // exact sources: H and J / J only
  NearBufferF nearf, nearf_j;               // the same in float (bh_near_float)
  CellBuffer far_hj, far_h, far_j;          // cells: field and Jacobian / field only / J only
  CellBufferF far_hjf, far_hf, far_jf;      // the same in float, scaled (bh_far_float)
  std::vector<std::pair<int, bool>> stack;  // (node, J-only)
  long near_pairs = 0, far_cells = 0;       // interaction counts (statistics)
  double lists_s = 0;                       // time spent building lists (statistics)
};

}  // namespace

struct BarnesHutWorkspace {
  // The geometry (tree, groups, lists) is kept while the positions, groups, the set of
  // nonzero moments, the largest possible moments (V Ms, |m| of permanent ones; they set
  // the expansion centres) and the leaf and group sizes stay bitwise the same (key_*); the lists
  // also depend on θ and on whether J is wanted (one set of lists for each).
  bool tree_valid = false;
  std::vector<Vec3> key_pos;
  std::vector<std::int32_t> key_grp;
  std::vector<std::uint8_t> key_nz, nz;  // moment i nonzero (cached / this call)
  std::vector<double> key_w, w;          // its largest possible |m_i| (cached / this call)
  std::vector<double> key_rad;           // interaction radii (cached)
  int key_leaf = 0, key_group = 0;
  bool lists_valid[2] = {false, false};  // [want_J]
  double lists_theta[2] = {0, 0};
  double lists_gap[2] = {0, 0};          // the far cells' minimum gap (bounded pairs)
  std::vector<GroupLists> lists[2];
  std::vector<std::uint8_t> shared;  // moment i belongs to a body of several moments

  std::vector<std::pair<std::uint64_t, int>> keys;  // (Morton code, moment), sorted
  std::vector<int> order;                           // tree position → moment index
  std::vector<int> src_prefix;                      // nonzero sources before tree position
  std::vector<Node> nodes;
  std::vector<NodeHot> hot;   // (nodes) the walk's view of each node
  std::vector<double> cells;  // (nodes × kCellFields) the kernel's view of each cell
  std::vector<Group> groups;
  detail::SourceBuffer src;  // nonzero sources in tree order (not padded)
  std::vector<double> src_w;  // their largest possible |m_i|
  std::vector<std::int32_t> src_id32, src_grp32;  // their ids and groups (−1: none) as int32
  std::vector<float> src_radf;                    // their interaction radii in float
  std::vector<float> src_mf[3];                   // their moments in float (this call)
  std::vector<ThreadScratch> threads;
  BarnesHutStats stats;
};

BarnesHutWorkspace* new_barnes_hut_workspace() { return new BarnesHutWorkspace; }

void barnes_hut_forget_geometry(FieldWorkspace* ws) {
  if (!ws->bh) return;
  ws->bh->tree_valid = false;
  ws->bh->lists_valid[0] = ws->bh->lists_valid[1] = false;
}
void BarnesHutWorkspaceDeleter::operator()(BarnesHutWorkspace* p) const { delete p; }

BarnesHutStats barnes_hut_stats(const FieldWorkspace& ws) {
  return ws.bh ? ws.bh->stats : BarnesHutStats{};
}

namespace {

// ---- tree -------------------------------------------------------------------------------

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

void close_group(const MomentSet& set, BarnesHutWorkspace* ws, int t0, int t1) {
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
void make_groups(const MomentSet& set, BarnesHutWorkspace* ws, int id, int G) {
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
void find_shared(const MomentSet& set, BarnesHutWorkspace* ws) {
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

// The geometry: Morton order, octree, node centres and radii, target groups. Depends on the
// positions, groups, which moments are nonzero, and the leaf and group sizes only.
void build_tree(const MomentSet& set, const FieldOptions& opt, BarnesHutWorkspace* ws) {
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
  split_node(ws, 0, 0, std::max(1, opt.bh_leaf_size));
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
  make_groups(set, ws, 0, std::max(1, opt.bh_group_size));
}

// The moments of this call: sources' moments, multipoles bottom-up, the kernel's cells.
void update_multipoles(const MomentSet& set, BarnesHutWorkspace* ws) {
  detail::SourceBuffer& s = ws->src;
  const int ns = static_cast<int>(s.size());
  for (int k = 0; k < ns; ++k) {
    const Vec3 m = set.moment(static_cast<std::size_t>(s.id[k]));
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

// ---- interaction lists -------------------------------------------------------------------

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

// ---- far-cell kernel ---------------------------------------------------------------------
//
// The series of the file comment, written out (u_n = q^{-n/2}, ρ = r·M − tr S, w = S r,
// s = rᵀ S r; with order 2 also o1 = O·r (matrix), o2 = O:rr, o3 = O⋮rrr, τ = t·r,
// t_a = O_abb):
//   A   = 3ρ u5 + (15 s − 22.5 τ) u7 + 52.5 o3 u9
//   4π h = A r − u3 M + u5 (4.5 t − 6 w) − 22.5 u7 o2
//   c_r = −7.5 ρ u7 + (78.75 τ − 52.5 s) u9 − 236.25 o3 u11
//   K   = 3 u5 M + 30 u7 w − 22.5 u7 t + 157.5 u9 o2 + c_r r
//   4π J = A I + r Kᵀ + K rᵀ − 6 u5 S − 45 u7 o1
// With order 1 every O term is dropped (τ = o3 = 0, t = o1 = o2 = 0).

template <bool kH, bool kJ, int kOrder>
void far_portable(const CellBuffer& cb, const double* p, double eps2, double* Hout,
                  double* Jout) {
  double hx = 0, hy = 0, hz = 0;
  double ja = 0, jxx = 0, jyy = 0, jzz = 0, jxy = 0, jxz = 0, jyz = 0;
  const std::size_t nb = cb.size() / 8;
  for (std::size_t blk = 0; blk < nb; ++blk) {
  const double* B = cb.block(blk);
  const double *cx = B + 8 * kCx, *cy = B + 8 * kCy, *cz = B + 8 * kCz, *Mx = B + 8 * kMx,
               *My = B + 8 * kMy, *Mz = B + 8 * kMz, *Sxx = B + 8 * kSxx, *Syy = B + 8 * kSyy,
               *Szz = B + 8 * kSzz, *Sxy = B + 8 * kSxy, *Sxz = B + 8 * kSxz,
               *Syz = B + 8 * kSyz, *trS = B + 8 * kTrS, *Oxxx = B + 8 * kOxxx,
               *Oyyy = B + 8 * kOyyy, *Ozzz = B + 8 * kOzzz, *Oxxy = B + 8 * kOxxy,
               *Oxxz = B + 8 * kOxxz, *Oxyy = B + 8 * kOxyy, *Oyyz = B + 8 * kOyyz,
               *Oxzz = B + 8 * kOxzz, *Oyzz = B + 8 * kOyzz, *Oxyz = B + 8 * kOxyz,
               *Tx = B + 8 * kTx, *Ty = B + 8 * kTy, *Tz = B + 8 * kTz;
#pragma omp simd reduction(+ : hx, hy, hz, ja, jxx, jyy, jzz, jxy, jxz, jyz)
  for (std::size_t i = 0; i < 8; ++i) {
    const double rx = p[0] - cx[i], ry = p[1] - cy[i], rz = p[2] - cz[i];
    const double q = rx * rx + ry * ry + rz * rz + eps2;
    const double u = 1.0 / std::sqrt(q);
    const double u2 = u * u, u3 = u2 * u, u5 = u3 * u2, u7 = u5 * u2, u9 = u7 * u2,
                 u11 = u9 * u2;
    const double wx = Sxx[i] * rx + Sxy[i] * ry + Sxz[i] * rz;
    const double wy = Sxy[i] * rx + Syy[i] * ry + Syz[i] * rz;
    const double wz = Sxz[i] * rx + Syz[i] * ry + Szz[i] * rz;
    const double s = rx * wx + ry * wy + rz * wz;
    const double rho = rx * Mx[i] + ry * My[i] + rz * Mz[i] - trS[i];
    double oxx = 0, oyy = 0, ozz = 0, oxy = 0, oxz = 0, oyz = 0;  // o1
    double o2x = 0, o2y = 0, o2z = 0, o3 = 0, tau = 0, tx = 0, ty = 0, tz = 0;
    if constexpr (kOrder >= 2) {
      oxx = Oxxx[i] * rx + Oxxy[i] * ry + Oxxz[i] * rz;
      oyy = Oxyy[i] * rx + Oyyy[i] * ry + Oyyz[i] * rz;
      ozz = Oxzz[i] * rx + Oyzz[i] * ry + Ozzz[i] * rz;
      oxy = Oxxy[i] * rx + Oxyy[i] * ry + Oxyz[i] * rz;
      oxz = Oxxz[i] * rx + Oxyz[i] * ry + Oxzz[i] * rz;
      oyz = Oxyz[i] * rx + Oyyz[i] * ry + Oyzz[i] * rz;
      o2x = oxx * rx + oxy * ry + oxz * rz;
      o2y = oxy * rx + oyy * ry + oyz * rz;
      o2z = oxz * rx + oyz * ry + ozz * rz;
      o3 = o2x * rx + o2y * ry + o2z * rz;
      tx = Tx[i]; ty = Ty[i]; tz = Tz[i];
      tau = tx * rx + ty * ry + tz * rz;
    }
    const double A = 3.0 * rho * u5 + (15.0 * s - 22.5 * tau) * u7 + 52.5 * o3 * u9;
    if constexpr (kH) {
      hx += A * rx - u3 * Mx[i] + u5 * (4.5 * tx - 6.0 * wx) - 22.5 * u7 * o2x;
      hy += A * ry - u3 * My[i] + u5 * (4.5 * ty - 6.0 * wy) - 22.5 * u7 * o2y;
      hz += A * rz - u3 * Mz[i] + u5 * (4.5 * tz - 6.0 * wz) - 22.5 * u7 * o2z;
    }
    if constexpr (kJ) {
      const double cr = -7.5 * rho * u7 + (78.75 * tau - 52.5 * s) * u9 - 236.25 * o3 * u11;
      const double Kx = 3.0 * u5 * Mx[i] + u7 * (30.0 * wx - 22.5 * tx) + 157.5 * u9 * o2x + cr * rx;
      const double Ky = 3.0 * u5 * My[i] + u7 * (30.0 * wy - 22.5 * ty) + 157.5 * u9 * o2y + cr * ry;
      const double Kz = 3.0 * u5 * Mz[i] + u7 * (30.0 * wz - 22.5 * tz) + 157.5 * u9 * o2z + cr * rz;
      ja += A;
      jxx += 2.0 * rx * Kx - 6.0 * u5 * Sxx[i] - 45.0 * u7 * oxx;
      jyy += 2.0 * ry * Ky - 6.0 * u5 * Syy[i] - 45.0 * u7 * oyy;
      jzz += 2.0 * rz * Kz - 6.0 * u5 * Szz[i] - 45.0 * u7 * ozz;
      jxy += rx * Ky + ry * Kx - 6.0 * u5 * Sxy[i] - 45.0 * u7 * oxy;
      jxz += rx * Kz + rz * Kx - 6.0 * u5 * Sxz[i] - 45.0 * u7 * oxz;
      jyz += ry * Kz + rz * Ky - 6.0 * u5 * Syz[i] - 45.0 * u7 * oyz;
    }
  }
  }
  if constexpr (kH) {
    Hout[0] += hx * kInv4Pi; Hout[1] += hy * kInv4Pi; Hout[2] += hz * kInv4Pi;
  }
  if constexpr (kJ) {
    Jout[0] += (ja + jxx) * kInv4Pi; Jout[1] += (ja + jyy) * kInv4Pi;
    Jout[2] += (ja + jzz) * kInv4Pi;
    Jout[3] += jxy * kInv4Pi; Jout[4] += jxz * kInv4Pi; Jout[5] += jyz * kInv4Pi;
  }
}

#ifdef MAGSIM_AVX512_KERNEL

using V8 = __m512d;
MAGSIM_TARGET_AVX512 inline V8 set1(double x) { return _mm512_set1_pd(x); }
MAGSIM_TARGET_AVX512 inline V8 ld(const double* p) { return _mm512_loadu_pd(p); }
MAGSIM_TARGET_AVX512 inline V8 add(V8 a, V8 b) { return _mm512_add_pd(a, b); }
MAGSIM_TARGET_AVX512 inline V8 sub(V8 a, V8 b) { return _mm512_sub_pd(a, b); }
MAGSIM_TARGET_AVX512 inline V8 mul(V8 a, V8 b) { return _mm512_mul_pd(a, b); }
MAGSIM_TARGET_AVX512 inline V8 fma(V8 a, V8 b, V8 c) { return _mm512_fmadd_pd(a, b, c); }
MAGSIM_TARGET_AVX512 inline V8 fnma(V8 a, V8 b, V8 c) { return _mm512_fnmadd_pd(a, b, c); }
// a·x + b·y + c·z
MAGSIM_TARGET_AVX512 inline V8 dot3(V8 a, V8 b, V8 c, V8 x, V8 y, V8 z) {
  return fma(c, z, fma(b, y, mul(a, x)));
}

// 1/√q, as in dipole_field.cpp (vrsqrt14pd and one fourth-order step, error < 1e-16)
MAGSIM_TARGET_AVX512 inline V8 rsqrt_pd(V8 q) {
  const V8 y = _mm512_maskz_rsqrt14_pd(0xff, q);
  const V8 e = fnma(q, mul(y, y), set1(1.0));
  const V8 p = fma(fma(set1(5.0 / 16.0), e, set1(3.0 / 8.0)), e, set1(0.5));
  return fma(mul(y, e), p, y);
}

MAGSIM_TARGET_AVX512 inline double hsum(V8 v) {
  alignas(64) double t[8];
  _mm512_store_pd(t, v);
  return ((t[0] + t[4]) + (t[1] + t[5])) + ((t[2] + t[6]) + (t[3] + t[7]));
}

// The far-cell series of one block of W cells (see far_portable for it written out), the
// same code in double (V = V8, W = 8) and in single precision (V = V16, W = 16, the cells
// scaled to the group's unit L): adds 4π h (kH) and 4π J's parts (kJ) of the cells at
// offsets r = p − c from the target, u2 … u7 the powers of u = 1/√q. Defined below, after
// the single-precision helpers.
template <class V, int W, int kOrder, bool kH, bool kJ, class T>
MAGSIM_TARGET_AVX512 inline void far_block(const T* B, V rx, V ry, V rz, V u2, V u3, V u5, V u7,
                                           V& hx, V& hy, V& hz, V& ja, V& jxx, V& jyy, V& jzz,
                                           V& jxy, V& jxz, V& jyz);

template <bool kH, bool kJ, int kOrder>
MAGSIM_TARGET_AVX512 void far_avx512(const CellBuffer& cb, const double* p, double eps2,
                                     double* Hout, double* Jout) {
  const V8 px = set1(p[0]), py = set1(p[1]), pz = set1(p[2]), e2 = set1(eps2);
  const V8 zero = _mm512_setzero_pd();
  V8 hx = zero, hy = zero, hz = zero;
  V8 ja = zero, jxx = zero, jyy = zero, jzz = zero, jxy = zero, jxz = zero, jyz = zero;
  const std::size_t nb = cb.size() / 8;
  for (std::size_t blk = 0; blk < nb; ++blk) {
    const double* B = cb.block(blk);
    const V8 rx = sub(px, ld(B + 8 * kCx)), ry = sub(py, ld(B + 8 * kCy)), rz = sub(pz, ld(B + 8 * kCz));
    const V8 q = fma(rz, rz, fma(ry, ry, fma(rx, rx, e2)));
    const V8 u = rsqrt_pd(q);
    const V8 u2 = mul(u, u), u3 = mul(u2, u), u5 = mul(u3, u2), u7 = mul(u5, u2);
    far_block<V8, 8, kOrder, kH, kJ>(B, rx, ry, rz, u2, u3, u5, u7, hx, hy, hz, ja, jxx, jyy, jzz, jxy, jxz, jyz);
  }
  if constexpr (kH) {
    Hout[0] += hsum(hx) * kInv4Pi; Hout[1] += hsum(hy) * kInv4Pi; Hout[2] += hsum(hz) * kInv4Pi;
  }
  if constexpr (kJ) {
    const double a = hsum(ja);
    Jout[0] += (a + 2.0 * hsum(jxx)) * kInv4Pi; Jout[1] += (a + 2.0 * hsum(jyy)) * kInv4Pi;
    Jout[2] += (a + 2.0 * hsum(jzz)) * kInv4Pi;
    Jout[3] += hsum(jxy) * kInv4Pi; Jout[4] += hsum(jxz) * kInv4Pi; Jout[5] += hsum(jyz) * kInv4Pi;
  }
}

#endif  // MAGSIM_AVX512_KERNEL

template <bool kH, bool kJ>
void far_sum(const CellBuffer& cb, int order, const double* p, double eps2, double* H,
             double* J) {
  if (cb.size() == 0) return;
#ifdef MAGSIM_AVX512_KERNEL
  if (detail::simd_kernel_active()) {
    if (order >= 2) far_avx512<kH, kJ, 2>(cb, p, eps2, H, J);
    else far_avx512<kH, kJ, 1>(cb, p, eps2, H, J);
    return;
  }
#endif
  if (order >= 2) far_portable<kH, kJ, 2>(cb, p, eps2, H, J);
  else far_portable<kH, kJ, 1>(cb, p, eps2, H, J);
}

// ---- far-cell kernel in single precision (FieldOptions::bh_far_float) ---------------------
//
// The same series as far_portable / far_avx512, in float, on a group's scaled cells
// (CellBufferF: r' = r/L, S' = S/L, O' = O/L², so the sums below are L³ · 4π h and L⁴ · 4π J;
// sH = 1/(4π L³) and sJ = 1/(4π L⁴) undo both in double). 1/√q: vrsqrt14ps refined by one
// Newton–Raphson step (≈ 1.5·2⁻²⁸, below float rounding) on AVX-512, 1/std::sqrt in the
// portable loop; lanes past the last cell masked to 1/√q = 0 (their cells are zeros, so every
// term is exactly 0). Partial sums in float over at most kFarChunkF cells (kFarChunkF / 16
// per lane), then in double, in a fixed order: deterministic, and the float rounding of the
// sum does not grow with the list. The two kernels agree to float rounding (not bitwise).

// Cells per chunk of float partial sums (64 per AVX-512 lane; lists are rarely longer).
constexpr std::size_t kFarChunkF = 1024;

template <bool kH, bool kJ, int kOrder>
void far_f32_portable(const CellBufferF& cb, const float* p, float eps2, double sH, double sJ,
                      double* Hout, double* Jout) {
  double acc[10] = {};  // hx hy hz ja jxx jyy jzz jxy jxz jyz
  const std::size_t nb = cb.blocks();
  // float partial sums of kFarChunkF / 16 cells (as many as an AVX-512 lane sums)
  constexpr std::size_t kChunkBlocks = kFarChunkF / 16 / 16;
  for (std::size_t b0 = 0; b0 < nb; b0 += kChunkBlocks) {
    const std::size_t b1 = std::min(nb, b0 + kChunkBlocks);
    float hx = 0, hy = 0, hz = 0;
    float ja = 0, jxx = 0, jyy = 0, jzz = 0, jxy = 0, jxz = 0, jyz = 0;
    for (std::size_t blk = b0; blk < b1; ++blk) {
    const float* B = cb.block(blk);
    const std::size_t valid = std::min<std::size_t>(16, cb.size() - 16 * blk);
    const float *cx = B + 16 * kCx, *cy = B + 16 * kCy, *cz = B + 16 * kCz, *Mx = B + 16 * kMx,
                *My = B + 16 * kMy, *Mz = B + 16 * kMz, *Sxx = B + 16 * kSxx, *Syy = B + 16 * kSyy,
                *Szz = B + 16 * kSzz, *Sxy = B + 16 * kSxy, *Sxz = B + 16 * kSxz,
                *Syz = B + 16 * kSyz, *trS = B + 16 * kTrS, *Oxxx = B + 16 * kOxxx,
                *Oyyy = B + 16 * kOyyy, *Ozzz = B + 16 * kOzzz, *Oxxy = B + 16 * kOxxy,
                *Oxxz = B + 16 * kOxxz, *Oxyy = B + 16 * kOxyy, *Oyyz = B + 16 * kOyyz,
                *Oxzz = B + 16 * kOxzz, *Oyzz = B + 16 * kOyzz, *Oxyz = B + 16 * kOxyz,
                *Tx = B + 16 * kTx, *Ty = B + 16 * kTy, *Tz = B + 16 * kTz;
#pragma omp simd reduction(+ : hx, hy, hz, ja, jxx, jyy, jzz, jxy, jxz, jyz)
    for (std::size_t i = 0; i < 16; ++i) {
      const float rx = p[0] - cx[i], ry = p[1] - cy[i], rz = p[2] - cz[i];
      const float q = rx * rx + ry * ry + rz * rz + eps2;
      const float u = i < valid ? 1.0f / std::sqrt(i < valid ? q : 1.0f) : 0.0f;  // padding: 0
      const float u2 = u * u, u3 = u2 * u, u5 = u3 * u2, u7 = u5 * u2, u9 = u7 * u2,
                  u11 = u9 * u2;
      const float wx = Sxx[i] * rx + Sxy[i] * ry + Sxz[i] * rz;
      const float wy = Sxy[i] * rx + Syy[i] * ry + Syz[i] * rz;
      const float wz = Sxz[i] * rx + Syz[i] * ry + Szz[i] * rz;
      const float s = rx * wx + ry * wy + rz * wz;
      const float rho = rx * Mx[i] + ry * My[i] + rz * Mz[i] - trS[i];
      float oxx = 0, oyy = 0, ozz = 0, oxy = 0, oxz = 0, oyz = 0;  // o1
      float o2x = 0, o2y = 0, o2z = 0, o3 = 0, tau = 0, tx = 0, ty = 0, tz = 0;
      if constexpr (kOrder >= 2) {
        oxx = Oxxx[i] * rx + Oxxy[i] * ry + Oxxz[i] * rz;
        oyy = Oxyy[i] * rx + Oyyy[i] * ry + Oyyz[i] * rz;
        ozz = Oxzz[i] * rx + Oyzz[i] * ry + Ozzz[i] * rz;
        oxy = Oxxy[i] * rx + Oxyy[i] * ry + Oxyz[i] * rz;
        oxz = Oxxz[i] * rx + Oxyz[i] * ry + Oxzz[i] * rz;
        oyz = Oxyz[i] * rx + Oyyz[i] * ry + Oyzz[i] * rz;
        o2x = oxx * rx + oxy * ry + oxz * rz;
        o2y = oxy * rx + oyy * ry + oyz * rz;
        o2z = oxz * rx + oyz * ry + ozz * rz;
        o3 = o2x * rx + o2y * ry + o2z * rz;
        tx = Tx[i]; ty = Ty[i]; tz = Tz[i];
        tau = tx * rx + ty * ry + tz * rz;
      }
      // A = 3ρ u5 + (15 s − 22.5 τ) u7 + 52.5 o3 u9
      const float A = 3.0f * rho * u5 + (15.0f * s - 22.5f * tau) * u7 + 52.5f * o3 * u9;
      if constexpr (kH) {
        // 4π h = A r − u3 M + u5 (4.5 t − 6 w) − 22.5 u7 o2
        hx += A * rx - u3 * Mx[i] + u5 * (4.5f * tx - 6.0f * wx) - 22.5f * u7 * o2x;
        hy += A * ry - u3 * My[i] + u5 * (4.5f * ty - 6.0f * wy) - 22.5f * u7 * o2y;
        hz += A * rz - u3 * Mz[i] + u5 * (4.5f * tz - 6.0f * wz) - 22.5f * u7 * o2z;
      }
      if constexpr (kJ) {
        // c_r = −7.5 ρ u7 + (78.75 τ − 52.5 s) u9 − 236.25 o3 u11
        // K = 3 u5 M + 30 u7 w − 22.5 u7 t + 157.5 u9 o2 + c_r r
        // 4π J = A I + r Kᵀ + K rᵀ − 6 u5 S − 45 u7 o1
        const float cr = -7.5f * rho * u7 + (78.75f * tau - 52.5f * s) * u9 - 236.25f * o3 * u11;
        const float Kx = 3.0f * u5 * Mx[i] + u7 * (30.0f * wx - 22.5f * tx) + 157.5f * u9 * o2x + cr * rx;
        const float Ky = 3.0f * u5 * My[i] + u7 * (30.0f * wy - 22.5f * ty) + 157.5f * u9 * o2y + cr * ry;
        const float Kz = 3.0f * u5 * Mz[i] + u7 * (30.0f * wz - 22.5f * tz) + 157.5f * u9 * o2z + cr * rz;
        ja += A;
        jxx += 2.0f * rx * Kx - 6.0f * u5 * Sxx[i] - 45.0f * u7 * oxx;
        jyy += 2.0f * ry * Ky - 6.0f * u5 * Syy[i] - 45.0f * u7 * oyy;
        jzz += 2.0f * rz * Kz - 6.0f * u5 * Szz[i] - 45.0f * u7 * ozz;
        jxy += rx * Ky + ry * Kx - 6.0f * u5 * Sxy[i] - 45.0f * u7 * oxy;
        jxz += rx * Kz + rz * Kx - 6.0f * u5 * Sxz[i] - 45.0f * u7 * oxz;
        jyz += ry * Kz + rz * Ky - 6.0f * u5 * Syz[i] - 45.0f * u7 * oyz;
      }
    }
    }
    const float part[10] = {hx, hy, hz, ja, jxx, jyy, jzz, jxy, jxz, jyz};
    for (int k = 0; k < 10; ++k) acc[k] += part[k];
  }
  if constexpr (kH) {
    Hout[0] += acc[0] * sH; Hout[1] += acc[1] * sH; Hout[2] += acc[2] * sH;
  }
  if constexpr (kJ) {
    Jout[0] += (acc[3] + acc[4]) * sJ; Jout[1] += (acc[3] + acc[5]) * sJ;
    Jout[2] += (acc[3] + acc[6]) * sJ;
    Jout[3] += acc[7] * sJ; Jout[4] += acc[8] * sJ; Jout[5] += acc[9] * sJ;
  }
}

#ifdef MAGSIM_AVX512_KERNEL

using V16 = __m512;
MAGSIM_TARGET_AVX512 inline V16 fset1(float x) { return _mm512_set1_ps(x); }
MAGSIM_TARGET_AVX512 inline V16 fld(const float* p) { return _mm512_loadu_ps(p); }
MAGSIM_TARGET_AVX512 inline V16 add(V16 a, V16 b) { return _mm512_add_ps(a, b); }
MAGSIM_TARGET_AVX512 inline V16 sub(V16 a, V16 b) { return _mm512_sub_ps(a, b); }
MAGSIM_TARGET_AVX512 inline V16 mul(V16 a, V16 b) { return _mm512_mul_ps(a, b); }
MAGSIM_TARGET_AVX512 inline V16 fma(V16 a, V16 b, V16 c) { return _mm512_fmadd_ps(a, b, c); }
MAGSIM_TARGET_AVX512 inline V16 fnma(V16 a, V16 b, V16 c) { return _mm512_fnmadd_ps(a, b, c); }
// a·x + b·y + c·z
MAGSIM_TARGET_AVX512 inline V16 dot3(V16 a, V16 b, V16 c, V16 x, V16 y, V16 z) {
  return fma(c, z, fma(b, y, mul(a, x)));
}

// 1/√q in the lanes of `keep` (0 elsewhere): vrsqrt14ps (|rel. error| ≤ 2⁻¹⁴) and one
// Newton–Raphson step y + (y/2)(1 − q y²) (≈ 1.5·2⁻²⁸), as in near_kernel_f32.cpp
MAGSIM_TARGET_AVX512 inline V16 rsqrt_ps(__mmask16 keep, V16 q) {
  const V16 y = _mm512_maskz_rsqrt14_ps(keep, q);
  const V16 e = fnma(q, mul(y, y), fset1(1.0f));
  return fma(mul(y, fset1(0.5f)), e, y);
}

// The 16 float lanes of v widened and added to the 8 double lanes of acc (lane k gets float
// lanes k and k + 8): exact widening, a fixed order (as in near_kernel_f32.cpp).
MAGSIM_TARGET_AVX512 inline V8 widen_add(V8 acc, V16 v) {
  const __m512d vd = _mm512_castps_pd(v);
  const __m256 l = _mm256_castpd_ps(_mm512_maskz_extractf64x4_pd(0xf, vd, 0));
  const __m256 h = _mm256_castpd_ps(_mm512_maskz_extractf64x4_pd(0xf, vd, 1));
  return add(acc, add(_mm512_maskz_cvtps_pd(0xff, l), _mm512_maskz_cvtps_pd(0xff, h)));
}

// A constant in every lane of V (overloads on a V argument, whose value is ignored).
MAGSIM_TARGET_AVX512 inline V8 splat(V8, double x) { return _mm512_set1_pd(x); }
MAGSIM_TARGET_AVX512 inline V16 splat(V16, double x) { return _mm512_set1_ps(static_cast<float>(x)); }
template <class V>
MAGSIM_TARGET_AVX512 inline V cst(double x) { return splat(V(), x); }
MAGSIM_TARGET_AVX512 inline V16 ld(const float* p) { return _mm512_loadu_ps(p); }

template <class V, int W, int kOrder, bool kH, bool kJ, class T>
MAGSIM_TARGET_AVX512 inline void far_block(const T* B, V rx, V ry, V rz, V u2, V u3, V u5, V u7,
                                           V& hx, V& hy, V& hz, V& ja, V& jxx, V& jyy, V& jzz,
                                           V& jxy, V& jxz, V& jyz) {
  const V zero = cst<V>(0.0);
  const V Sxx = ld(B + W * kSxx), Syy = ld(B + W * kSyy), Szz = ld(B + W * kSzz),
            Sxy = ld(B + W * kSxy), Sxz = ld(B + W * kSxz), Syz = ld(B + W * kSyz);
  const V Mx = ld(B + W * kMx), My = ld(B + W * kMy), Mz = ld(B + W * kMz);
  const V wx = dot3(Sxx, Sxy, Sxz, rx, ry, rz);
  const V wy = dot3(Sxy, Syy, Syz, rx, ry, rz);
  const V wz = dot3(Sxz, Syz, Szz, rx, ry, rz);
  const V s = dot3(rx, ry, rz, wx, wy, wz);
  const V rho = sub(dot3(rx, ry, rz, Mx, My, Mz), ld(B + W * kTrS));
  V oxx = zero, oyy = zero, ozz = zero, oxy = zero, oxz = zero, oyz = zero;
  V o2x = zero, o2y = zero, o2z = zero, o3 = zero, tau = zero, tx = zero, ty = zero,
      tz = zero, u9 = zero;
  // A = 3ρ u5 + (15 s − 22.5 τ) u7 + 52.5 o3 u9
  V A = fma(mul(cst<V>(3.0), rho), u5, mul(mul(cst<V>(15.0), s), u7));
  if constexpr (kOrder >= 2) {
    const V Oxxy = ld(B + W * kOxxy), Oxxz = ld(B + W * kOxxz), Oxyy = ld(B + W * kOxyy),
              Oyyz = ld(B + W * kOyyz), Oxzz = ld(B + W * kOxzz), Oyzz = ld(B + W * kOyzz),
              Oxyz = ld(B + W * kOxyz);
    oxx = dot3(ld(B + W * kOxxx), Oxxy, Oxxz, rx, ry, rz);
    oyy = dot3(Oxyy, ld(B + W * kOyyy), Oyyz, rx, ry, rz);
    ozz = dot3(Oxzz, Oyzz, ld(B + W * kOzzz), rx, ry, rz);
    oxy = dot3(Oxxy, Oxyy, Oxyz, rx, ry, rz);
    oxz = dot3(Oxxz, Oxyz, Oxzz, rx, ry, rz);
    oyz = dot3(Oxyz, Oyyz, Oyzz, rx, ry, rz);
    o2x = dot3(oxx, oxy, oxz, rx, ry, rz);
    o2y = dot3(oxy, oyy, oyz, rx, ry, rz);
    o2z = dot3(oxz, oyz, ozz, rx, ry, rz);
    o3 = dot3(o2x, o2y, o2z, rx, ry, rz);
    tx = ld(B + W * kTx); ty = ld(B + W * kTy); tz = ld(B + W * kTz);
    tau = dot3(tx, ty, tz, rx, ry, rz);
    u9 = mul(u7, u2);
    A = fma(mul(cst<V>(52.5), o3), u9, fnma(mul(cst<V>(22.5), tau), u7, A));
  }
  if constexpr (kH) {
    // 4π h = A r − u3 M − u5 v − 22.5 u7 o2,  v = 6 w − 4.5 t
    const V c6 = cst<V>(6.0);
    V vx = mul(c6, wx), vy = mul(c6, wy), vz = mul(c6, wz);
    if constexpr (kOrder >= 2) {
      const V c45 = cst<V>(4.5), u7_225 = mul(cst<V>(22.5), u7);
      vx = fnma(c45, tx, vx);
      vy = fnma(c45, ty, vy);
      vz = fnma(c45, tz, vz);
      hx = fnma(u7_225, o2x, hx);
      hy = fnma(u7_225, o2y, hy);
      hz = fnma(u7_225, o2z, hz);
    }
    hx = fnma(u3, Mx, fnma(u5, vx, fma(A, rx, hx)));
    hy = fnma(u3, My, fnma(u5, vy, fma(A, ry, hy)));
    hz = fnma(u3, Mz, fnma(u5, vz, fma(A, rz, hz)));
  }
  if constexpr (kJ) {
    // c_r = −7.5 ρ u7 + (78.75 τ − 52.5 s) u9 − 236.25 o3 u11
    // K = 3 u5 M + 30 u7 w − 22.5 u7 t + 157.5 u9 o2 + c_r r
    if constexpr (kOrder < 2) u9 = mul(u7, u2);
    V cr = fnma(mul(cst<V>(7.5), rho), u7, mul(mul(cst<V>(-52.5), s), u9));
    const V u5_3m = mul(cst<V>(3.0), u5), u7_30 = mul(cst<V>(30.0), u7);
    V Kx = fma(u7_30, wx, mul(u5_3m, Mx));
    V Ky = fma(u7_30, wy, mul(u5_3m, My));
    V Kz = fma(u7_30, wz, mul(u5_3m, Mz));
    if constexpr (kOrder >= 2) {
      const V u11 = mul(u9, u2);
      cr = fnma(mul(cst<V>(236.25), o3), u11, fma(mul(cst<V>(78.75), tau), u9, cr));
      const V u7_225 = mul(cst<V>(22.5), u7), u9_1575 = mul(cst<V>(157.5), u9);
      Kx = fma(u9_1575, o2x, fnma(u7_225, tx, Kx));
      Ky = fma(u9_1575, o2y, fnma(u7_225, ty, Ky));
      Kz = fma(u9_1575, o2z, fnma(u7_225, tz, Kz));
    }
    Kx = fma(cr, rx, Kx);
    Ky = fma(cr, ry, Ky);
    Kz = fma(cr, rz, Kz);
    // 4π J = A I + r Kᵀ + K rᵀ − 6 u5 S − 45 u7 o1; the diagonal sums hold half of their
    // r K, S and o1 terms (doubled at the end)
    const V u5_3 = mul(cst<V>(3.0), u5), u5_6 = mul(cst<V>(6.0), u5);
    ja = add(ja, A);
    V dxx = fnma(u5_3, Sxx, mul(rx, Kx)), dyy = fnma(u5_3, Syy, mul(ry, Ky)),
        dzz = fnma(u5_3, Szz, mul(rz, Kz));
    V dxy = fnma(u5_6, Sxy, fma(ry, Kx, mul(rx, Ky)));
    V dxz = fnma(u5_6, Sxz, fma(rz, Kx, mul(rx, Kz)));
    V dyz = fnma(u5_6, Syz, fma(rz, Ky, mul(ry, Kz)));
    if constexpr (kOrder >= 2) {
      const V u7_225 = mul(cst<V>(22.5), u7), u7_45 = mul(cst<V>(45.0), u7);
      dxx = fnma(u7_225, oxx, dxx);
      dyy = fnma(u7_225, oyy, dyy);
      dzz = fnma(u7_225, ozz, dzz);
      dxy = fnma(u7_45, oxy, dxy);
      dxz = fnma(u7_45, oxz, dxz);
      dyz = fnma(u7_45, oyz, dyz);
    }
    jxx = add(jxx, dxx); jyy = add(jyy, dyy); jzz = add(jzz, dzz);
    jxy = add(jxy, dxy); jxz = add(jxz, dxz); jyz = add(jyz, dyz);
  }
}

template <bool kH, bool kJ, int kOrder>
MAGSIM_TARGET_AVX512 void far_f32_avx512(const CellBufferF& cb, const float* p, float eps2,
                                         double sH, double sJ, double* Hout, double* Jout) {
  const V16 px = fset1(p[0]), py = fset1(p[1]), pz = fset1(p[2]), e2 = fset1(eps2);
  const V16 zero = _mm512_setzero_ps();
  // double accumulators across chunks: hx hy hz ja jxx jyy jzz jxy jxz jyz
  V8 acc[10];
  for (V8& a : acc) a = _mm512_setzero_pd();
  const std::size_t nb = cb.blocks();
  constexpr std::size_t kChunkBlocks = kFarChunkF / 16;
  for (std::size_t b0 = 0; b0 < nb; b0 += kChunkBlocks) {
    const std::size_t b1 = std::min(nb, b0 + kChunkBlocks);
    V16 hx = zero, hy = zero, hz = zero;
    V16 ja = zero, jxx = zero, jyy = zero, jzz = zero, jxy = zero, jxz = zero, jyz = zero;
    for (std::size_t blk = b0; blk < b1; ++blk) {
    const float* B = cb.block(blk);
    const std::size_t valid = std::min<std::size_t>(16, cb.size() - 16 * blk);
    const __mmask16 keep = static_cast<__mmask16>((1u << valid) - 1u);
    const V16 rx = sub(px, fld(B + 16 * kCx)), ry = sub(py, fld(B + 16 * kCy)), rz = sub(pz, fld(B + 16 * kCz));
    const V16 q = fma(rz, rz, fma(ry, ry, fma(rx, rx, e2)));
    const V16 u = rsqrt_ps(keep, q);
    const V16 u2 = mul(u, u), u3 = mul(u2, u), u5 = mul(u3, u2), u7 = mul(u5, u2);
    far_block<V16, 16, kOrder, kH, kJ>(B, rx, ry, rz, u2, u3, u5, u7, hx, hy, hz, ja, jxx, jyy, jzz, jxy, jxz, jyz);
    }
    if constexpr (kH) {
      acc[0] = widen_add(acc[0], hx); acc[1] = widen_add(acc[1], hy); acc[2] = widen_add(acc[2], hz);
    }
    if constexpr (kJ) {
      acc[3] = widen_add(acc[3], ja); acc[4] = widen_add(acc[4], jxx);
      acc[5] = widen_add(acc[5], jyy); acc[6] = widen_add(acc[6], jzz);
      acc[7] = widen_add(acc[7], jxy); acc[8] = widen_add(acc[8], jxz);
      acc[9] = widen_add(acc[9], jyz);
    }
  }
  if constexpr (kH) {
    Hout[0] += hsum(acc[0]) * sH; Hout[1] += hsum(acc[1]) * sH; Hout[2] += hsum(acc[2]) * sH;
  }
  if constexpr (kJ) {
    const double a = hsum(acc[3]);
    Jout[0] += (a + 2.0 * hsum(acc[4])) * sJ; Jout[1] += (a + 2.0 * hsum(acc[5])) * sJ;
    Jout[2] += (a + 2.0 * hsum(acc[6])) * sJ;
    Jout[3] += hsum(acc[7]) * sJ; Jout[4] += hsum(acc[8]) * sJ; Jout[5] += hsum(acc[9]) * sJ;
  }
}

#endif  // MAGSIM_AVX512_KERNEL

// Adds a group's float far cells at the scaled target p' (sH = 1/(4π L³), sJ = 1/(4π L⁴)).
template <bool kH, bool kJ>
void far_sum_f32(const CellBufferF& cb, int order, const float* p, float eps2, double sH,
                 double sJ, double* H, double* J) {
  if (cb.size() == 0) return;
#ifdef MAGSIM_AVX512_KERNEL
  if (detail::simd_kernel_active()) {
    if (order >= 2) far_f32_avx512<kH, kJ, 2>(cb, p, eps2, sH, sJ, H, J);
    else far_f32_avx512<kH, kJ, 1>(cb, p, eps2, sH, sJ, H, J);
    return;
  }
#endif
  if (order >= 2) far_f32_portable<kH, kJ, 2>(cb, p, eps2, sH, sJ, H, J);
  else far_f32_portable<kH, kJ, 1>(cb, p, eps2, sH, sJ, H, J);
}

}  // namespace

void barnes_hut_fields(const MomentSet& set, const FieldOptions& opt, std::vector<Vec3>* H,
                       std::vector<Mat3>* J, BarnesHutWorkspace* ws) {
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
    const Vec3 m = set.moment(i);
    ws->nz[i] = !(m.x() == 0.0 && m.y() == 0.0 && m.z() == 0.0);
    ws->w[i] = set.kind[i] == MomentKind::Induced ? set.volume[i] * set.Ms[i] : m.norm();
  }
  const int leaf = std::max(1, opt.bh_leaf_size), gsize = std::max(1, opt.bh_group_size);
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
  update_multipoles(set, ws);
  const auto t_built = std::chrono::steady_clock::now();
  const double eps2 = opt.softening * opt.softening;
  const float eps2f = static_cast<float>(eps2);
  // θ = 0 promises the direct sum: the near field (then everything) stays in double
  const bool near_float = opt.bh_near_float && opt.bh_theta > 0;
  // the far cells in float too (only with the near field in float: bh_near_float = false
  // keeps the whole sum in double)
  const bool far_float = near_float && opt.bh_far_float;
  const bool want_J = J != nullptr;
  const int mode = want_J ? 1 : 0;
  // bounded pairs: near leaves carry the radii; far cells keep 2 a_max of clearance
  const bool bounded = pairs_bounded(set, opt);
  double min_gap = 0.0;
  if (bounded)
    for (double a : set.radius) min_gap = std::max(min_gap, 2.0 * a);
  const bool new_lists = !ws->lists_valid[mode] || ws->lists_theta[mode] != opt.bh_theta ||
                         ws->lists_gap[mode] != min_gap;
  const int order = opt.bh_order;
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
      if (new_lists) build_lists(*ws, g, opt.bh_theta, min_gap, want_J, &th.stack, &lists[l]);
      th.lists_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t_l0).count();
      gather(*ws, g, lists[l], near_float, far_float, &th);
      const detail::SourceView vn = th.near.view(bounded), vj = th.near_j.view(bounded);
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
            far_sum_f32<true, true>(th.far_hjf, order, pf, eps2s, sH, sJ, h, jac);
            far_sum_f32<false, true>(th.far_jf, order, pf, eps2s, sH, sJ, h, jac);
          }
          far_sum_f32<true, false>(th.far_hf, order, pf, eps2s, sH, sJ, h, jac);
        } else {
          if (want_J) {
            far_sum<true, true>(th.far_hj, order, pp, eps2, h, jac);
            far_sum<false, true>(th.far_j, order, pp, eps2, h, jac);
          }
          far_sum<true, false>(th.far_h, order, pp, eps2, h, jac);
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
  ws->lists_theta[mode] = opt.bh_theta;
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
