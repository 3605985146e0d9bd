// tests/magnetics/simd_avx2_test.cpp — the AVX2+FMA lane set (magnetics/simd_avx2.hpp)
// against the lane contract of simd.hpp, written here per lane in scalar C++: every
// operation the kernel bodies call, on random values mixed with ±0, ±inf, NaN, subnormals and
// the extremes, under random masks. The same bits in every lane (memcmp, so the sign of a
// zero counts; NaN results: both NaN). Runs where the CPU has AVX2 and FMA.
#include "magnetics/field_kernel.hpp"
#include "magnetics/simd_avx2.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <type_traits>

#ifdef MAGSIM_FMA_KERNEL

namespace {

using namespace magsim::mag::detail::simd;

// Results per operation (kOps rows of W lanes), then the masks' results (kMaskOps rows)
constexpr int kOps = 14, kMaskOps = 5;

// One round of every operation on inputs a, b, c (W lanes) with the mask m = ids ≠ self;
// row k of out holds operation k's lanes: add sub mul max keep sqrt div mul_in mul_add
// neg_mul_add dot3 inv_sqrt fold(c, a) cst(a₀); masks as 1 or 0: less(a, b), m,
// less(a, b) & m, first_lanes(n), any(m) (lane 0); the last row but one holds hsum(a) (lane 0)
// and, for floats, fold(acc, a) with acc = the first 8 lanes of c, widened.
#pragma GCC push_options
#pragma GCC target("avx2,fma")
template <class V, class T, class Id>
void avx2_round(const T* a, const T* b, const T* c, const Id* ids, Id self, std::size_t n,
                T* out, double* extra) {
  constexpr int W = sizeof(V) / sizeof(T);
  const V va = ld(a, V()), vb = ld(b, V()), vc = ld(c, V()), one = cst<V>(1.0);
  const auto m = differ_lanes(ids, self, V());
  const V rows[kOps] = {add(va, vb),          sub(va, vb),
                        mul(va, vb),          max(va, vb),
                        keep(m, va),          sqrt(m, va),
                        div(m, va, vb),       mul_in(m, va, vb),
                        mul_add(va, vb, vc),  neg_mul_add(va, vb, vc),
                        dot3(va, vb, vc, vb, vc, va), inv_sqrt(m, va),
                        cst<V>(0.0),          cst<V>(static_cast<double>(a[0]))};
  for (int k = 0; k < kOps; ++k) std::memcpy(out + k * W, &rows[k], sizeof(V));
  const V masks[kMaskOps] = {keep(less(va, vb), one), keep(m, one), keep(less(va, vb) & m, one),
                             keep(first_lanes(V(), n), one), any(m) ? one : cst<V>(0.0)};
  for (int k = 0; k < kMaskOps; ++k) std::memcpy(out + (kOps + k) * W, &masks[k], sizeof(V));
  A8 acc = ld(extra, A8());
  if constexpr (std::is_same_v<T, double>) {
    const V f = fold(vc, va);
    std::memcpy(out + 12 * W, &f, sizeof(V));
    extra[8] = hsum(va);
  } else {
    acc = fold(acc, va);
    extra[8] = hsum(acc);
  }
  std::memcpy(extra, &acc, sizeof acc);
}
#pragma GCC pop_options

template <class T>
bool same_bits(T x, T y) {
  if (std::isnan(x) || std::isnan(y)) return std::isnan(x) && std::isnan(y);
  return std::memcmp(&x, &y, sizeof x) == 0;
}

// The contract of one lane (simd.hpp)
template <class T>
void contract(T a, T b, T c, bool m, T* r) {
  r[0] = a + b;
  r[1] = a - b;
  r[2] = a * b;
  r[3] = a > b ? a : b;
  r[4] = m ? a : T(0);
  r[5] = m ? std::sqrt(a) : T(0);
  r[6] = m ? a / b : T(0);
  r[7] = m ? a * b : a;
  if constexpr (std::is_same_v<T, double>) {
    r[8] = std::fma(a, b, c);
    r[9] = std::fma(-a, b, c);
    r[10] = std::fma(c, a, std::fma(b, c, a * b));
  } else {  // float: rounded twice
    const T ab = a * b, bc = b * c, ca = c * a;
    r[8] = ab + c;
    r[9] = c - ab;
    r[10] = ca + (bc + ab);
  }
  r[11] = m ? T(1) / std::sqrt(a) : T(0);
  r[12] = c + a;  // fold of double lanes
}

template <class T>
T pick(std::mt19937_64& rng) {
  using L = std::numeric_limits<T>;
  const T special[] = {T(0),        -T(0),         T(1),          T(-1),        T(2),
                       T(0.5),      L::denorm_min(), -L::denorm_min(), L::min(), L::max(),
                       -L::max(),   L::infinity(), -L::infinity(), L::quiet_NaN(), -L::quiet_NaN(),
                       T(3),        T(1e-30),      T(1e30)};
  std::uniform_int_distribution<int> kind(0, 3);
  if (kind(rng) == 0) {
    std::uniform_int_distribution<std::size_t> k(0, sizeof special / sizeof special[0] - 1);
    return special[k(rng)];
  }
  std::uniform_real_distribution<double> mant(-2.0, 2.0);
  std::uniform_int_distribution<int> ex(-40, 40);
  return static_cast<T>(std::ldexp(mant(rng), ex(rng)));
}

template <class V, class T, class Id>
void check_lane_set(int rounds) {
  constexpr int W = sizeof(V) / sizeof(T);
  std::mt19937_64 rng(20261127);
  std::uniform_int_distribution<int> coin(0, 2);
  std::uniform_int_distribution<std::size_t> count(0, W + 2);
  int bad = 0;
  for (int round = 0; round < rounds && bad < 20; ++round) {
    T a[W], b[W], c[W], out[(kOps + kMaskOps) * W];
    Id ids[W];
    double extra[9];
    const Id self = static_cast<Id>(7);
    for (int k = 0; k < W; ++k) {
      a[k] = pick<T>(rng);
      b[k] = coin(rng) == 0 ? a[k] : pick<T>(rng);  // equal pairs: max of ±0, ties
      c[k] = pick<T>(rng);
      ids[k] = coin(rng) == 0 ? self : static_cast<Id>(k);
      if constexpr (std::is_same_v<Id, double>)
        if (coin(rng) == 0 && k % 3 == 0) ids[k] = std::numeric_limits<double>::quiet_NaN();
    }
    for (int k = 0; k < 8; ++k) extra[k] = static_cast<double>(c[k]);
    const std::size_t n = count(rng);
    avx2_round<V>(a, b, c, ids, self, n, out, extra);
    bool any = false;
    for (int k = 0; k < W; ++k) {
      const bool m = !(ids[k] == self);
      any = any || m;
      T r[13];
      contract(a[k], b[k], c[k], m, r);
      for (int op = 0; op < 13; ++op) {
        if (op == 12 && !std::is_same_v<T, double>) continue;
        if (!same_bits(out[op * W + k], r[op])) {
          ++bad;
          UNSCOPED_INFO("op " << op << " lane " << k << ": a " << a[k] << " b " << b[k] << " c "
                              << c[k] << " m " << m << ": " << out[op * W + k] << " vs " << r[op]);
        }
      }
      const T mk[kMaskOps - 1] = {T(a[k] < b[k]), T(m), T(a[k] < b[k] && m),
                                  T(static_cast<std::size_t>(k) < n)};
      for (int j = 0; j < kMaskOps - 1; ++j)
        if (!same_bits(out[(kOps + j) * W + k], mk[j])) ++bad;
      if (!same_bits(out[13 * W + k], a[0])) ++bad;  // cst(a₀)
    }
    for (int k = 0; k < W; ++k)
      if (out[(kOps + kMaskOps - 1) * W + k] != T(any)) ++bad;
    // fold and hsum in double
    double acc[8], want_sum;
    const auto tree = [](const double* l) {
      return ((l[0] + l[4]) + (l[1] + l[5])) + ((l[2] + l[6]) + (l[3] + l[7]));
    };
    if constexpr (std::is_same_v<T, double>) {
      want_sum = tree(a);
      for (int k = 0; k < 8; ++k) acc[k] = extra[k];  // unchanged
    } else {
      for (int k = 0; k < 8; ++k)
        acc[k] = static_cast<double>(c[k]) +
                 (static_cast<double>(a[k]) + static_cast<double>(a[k + 8]));
      want_sum = tree(acc);
    }
    for (int k = 0; k < 8; ++k)
      if (!same_bits(extra[k], acc[k])) ++bad;
    if (!same_bits(extra[8], want_sum)) ++bad;
  }
  CHECK(bad == 0);
}

}  // namespace

TEST_CASE("simd_avx2: every AVX2 lane operation gives the contract's bits in double and float "
          "lanes, masked lanes included (signed zeros, inf, NaN, subnormals)",
          "[simd][kernel]") {
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) {
    WARN("no AVX2+FMA on this CPU: the AVX2 lane set is not run");
    return;
  }
  check_lane_set<A8, double, double>(20000);
  check_lane_set<A16, float, std::int32_t>(20000);
}

#endif  // MAGSIM_FMA_KERNEL
