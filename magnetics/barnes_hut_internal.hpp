// magnetics/barnes_hut_internal.hpp — internal to the Barnes–Hut solver: its node, group
// and buffer types, the workspace, and the three stages the driver (barnes_hut.cpp) runs —
// the tree and its multipoles (barnes_hut_tree.cpp), the interaction lists and the gather
// into kernel buffers (barnes_hut_lists.cpp), and the far-cell series (barnes_hut_far.cpp).
// The algorithm is described at the top of barnes_hut.cpp. Include only from those files
// (and the kernel's tests and benchmark).
#pragma once

#include "magnetics/barnes_hut.hpp"
#include "magnetics/field_kernel.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

namespace magsim::mag {

namespace bh {

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
  std::size_t blocks() const { return (n + 7) / 8; }
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

// The same in float (BarnesHutOptions::far_float), blocks of 16 cells ([block][field][lane]),
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
using NearBuffer = detail::SourceBuffer;

// The same, in float for sum_pairs_f32 (BarnesHutOptions::near_float): positions relative
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
  NearBufferF nearf, nearf_j;               // the same in float (near_float)
  CellBuffer far_hj, far_h, far_j;          // cells: field and Jacobian / field only / J only
  CellBufferF far_hjf, far_hf, far_jf;      // the same in float, scaled (far_float)
  std::vector<std::pair<int, bool>> stack;  // (node, J-only)
  long near_pairs = 0, far_cells = 0;       // interaction counts (statistics)
  double lists_s = 0;                       // time spent building lists (statistics)
};

}  // namespace bh

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
  std::vector<bh::GroupLists> lists[2];
  std::vector<std::uint8_t> shared;  // moment i belongs to a body of several moments

  std::vector<std::pair<std::uint64_t, int>> keys;  // (Morton code, moment), sorted
  std::vector<int> order;                           // tree position → moment index
  std::vector<int> src_prefix;                      // nonzero sources before tree position
  std::vector<bh::Node> nodes;
  std::vector<bh::NodeHot> hot;   // (nodes) the walk's view of each node
  std::vector<double> cells;  // (nodes × kCellFields) the kernel's view of each cell
  std::vector<bh::Group> groups;
  detail::SourceBuffer src;  // nonzero sources in tree order (not padded)
  std::vector<double> src_w;  // their largest possible |m_i|
  std::vector<std::int32_t> src_id32, src_grp32;  // their ids and groups (−1: none) as int32
  std::vector<float> src_radf;                    // their interaction radii in float
  std::vector<float> src_mf[3];                   // their moments in float (this call)
  std::vector<bh::ThreadScratch> threads;
  BarnesHutStats stats;
};

namespace bh {

// ---- barnes_hut_tree.cpp ----------------------------------------------------------------

/// Sorts the moments along the Morton curve, splits the octree, sets each node's centre and
/// radius and forms the target groups (the geometry: kept while its keys are unchanged).
void build_tree(const MomentDesc& set, const BarnesHutOptions& opt, BarnesHutWorkspace* ws);
/// This call's moments into the packed sources and every cell's multipole (bottom-up).
void update_multipoles(const MomentDesc& set, const Magnetization& mz, BarnesHutWorkspace* ws);

// ---- barnes_hut_lists.cpp ---------------------------------------------------------------

/// Walks the tree for one target group and fills its interaction lists. min_gap: an
/// accepted cell also keeps every source this far from every target (bounded pairs).
void build_lists(const BarnesHutWorkspace& ws, const Group& g, double theta, double min_gap,
                 bool want_J, std::vector<std::pair<int, bool>>* stack, GroupLists* gl);
/// Copies a group's listed cells and near sources into the thread's kernel buffers, padded
/// (near_float / far_float: into the float buffers, relative to the group's centre).
void gather(const BarnesHutWorkspace& ws, const Group& g, const GroupLists& gl, bool near_float,
            bool far_float, ThreadScratch* th);

// ---- barnes_hut_far.cpp -----------------------------------------------------------------

/// Which terms a far-cell list adds: field and Jacobian, field only, Jacobian only.
enum class FarTerms { HJ, H, J };
/// Adds the far cells' series (order 1 or 2) at the target p to H and J (double cells).
void far_sum(const CellBuffer& cb, int order, FarTerms terms, const double* p, double eps2,
             double* H, double* J);
/// The same for a group's float cells at the scaled target p' (sH = 1/(4π L³),
/// sJ = 1/(4π L⁴) undo the group's length unit L; see CellBufferF).
void far_sum(const CellBufferF& cb, int order, FarTerms terms, const float* p, float eps2,
             double sH, double sJ, double* H, double* J);

}  // namespace bh

}  // namespace magsim::mag
