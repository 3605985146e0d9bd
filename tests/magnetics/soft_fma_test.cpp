// tests/magnetics/soft_fma_test.cpp — the fused a·b + c of simd.hpp's soft_fma (the field
// kernels' path on a CPU without FMA) against std::fma, which glibc computes
// exactly (by the FMA instruction or in software): the same bits in every lane (memcmp, so
// the sign of a zero counts; NaN results: both NaN). Lanes mix the cases below in random
// order, so in-range, zero and fallback lanes meet in one call.
#include "magnetics/field_kernel.hpp"
#include "magnetics/simd.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

using namespace magsim::mag::detail::simd;

namespace {

template <class T>
struct Triple {
  T a, b, c;
};

template <class T>
struct Lanes;
template <>
struct Lanes<double> {
  using V = VecD8;
  static constexpr int kN = 8;
  static double ref(double a, double b, double c) { return std::fma(a, b, c); }
};

template <class T>
bool same_bits(T x, T y) {
  if (std::isnan(x) || std::isnan(y)) return std::isnan(x) && std::isnan(y);
  return std::memcmp(&x, &y, sizeof x) == 0;
}

// Runs every triple through soft_fma::fma, kN lanes per call, in a shuffled order; returns
// the number of lanes whose bits differ from the reference (the first few printed).
template <class T>
std::size_t mismatches(std::vector<Triple<T>> t, const char* what, std::mt19937_64& rng) {
  using L = Lanes<T>;
  std::shuffle(t.begin(), t.end(), rng);
  while (t.size() % L::kN) t.push_back({T(1), T(1), T(1)});
  std::size_t bad = 0;
  for (std::size_t i = 0; i < t.size(); i += L::kN) {
    typename L::V a, b, c;
    for (int k = 0; k < L::kN; ++k) {
      a[k] = t[i + k].a;
      b[k] = t[i + k].b;
      c[k] = t[i + k].c;
    }
    const typename L::V r = soft_fma::fma(a, b, c);
    for (int k = 0; k < L::kN; ++k) {
      const T want = L::ref(a[k], b[k], c[k]), got = r[k];
      if (same_bits(got, want)) continue;
      if (++bad <= 5)
        std::printf("soft_fma %s: fma(%a, %a, %a) = %a, want %a\n", what, double(a[k]),
                    double(b[k]), double(c[k]), double(got), double(want));
    }
  }
  std::printf("soft_fma %s: %zu lanes, %zu differ\n", what, t.size(), bad);
  return bad;
}

// Random value: random sign, significand and binary exponent in [e0, e1] (below the
// normal range ldexp gives subnormals or zero)
template <class T>
T random_value(std::mt19937_64& rng, int e0, int e1) {
  constexpr int p = std::numeric_limits<T>::digits;
  const std::uint64_t m = (rng() >> (64 - (p - 1))) | (std::uint64_t{1} << (p - 1));
  const int e = std::uniform_int_distribution<int>(e0, e1)(rng);
  const T x = std::ldexp(static_cast<T>(m), e - (p - 1));
  return (rng() & 1) ? -x : x;
}

// Cases of each kind for precision T (exponent range [emin, emax] of normal numbers, safe
// emulation range ±safe for double), n random triples.
template <class T>
void check_all(std::size_t n_random, int safe) {
  constexpr int p = std::numeric_limits<T>::digits;
  constexpr int emax = std::numeric_limits<T>::max_exponent - 1;
  constexpr int emin_sub = std::numeric_limits<T>::min_exponent - p;  // smallest subnormal
  const T inf = std::numeric_limits<T>::infinity(), nan = std::numeric_limits<T>::quiet_NaN();
  std::mt19937_64 rng(20260127);
  auto sgn = [&](T x) { return (rng() & 1) ? -x : x; };
  auto unit = [&](int e0, int e1) { return random_value<T>(rng, e0, e1); };

  // 1. random exponents across the safe range and beyond it (fallback lanes), all signs
  std::vector<Triple<T>> t;
  for (std::size_t i = 0; i < n_random; ++i) {
    const int r = safe + safe / 8;
    t.push_back({unit(-r, r), unit(-r, r), unit(-2 * r, 2 * r)});
  }
  CHECK(mismatches(std::move(t), "random", rng) == 0);

  // 2. the whole range: subnormal and huge inputs, overflowing and underflowing products
  t.clear();
  for (std::size_t i = 0; i < n_random / 4; ++i)
    t.push_back({unit(emin_sub, emax), unit(emin_sub, emax), unit(emin_sub, emax)});
  for (std::size_t i = 0; i < n_random / 8; ++i) {  // products near the subnormal range
    const int e = std::uniform_int_distribution<int>(emin_sub - 2 * p, emin_sub + 3 * p)(rng);
    const T a = unit(-safe, safe);
    const T b = std::ldexp(unit(0, 0), e - std::ilogb(a));
    t.push_back({a, b, std::ldexp(unit(0, 0), std::uniform_int_distribution<int>(emin_sub, emin_sub + 3 * p)(rng))});
  }
  CHECK(mismatches(std::move(t), "full range", rng) == 0);

  // 3. cancellation c ≈ −a·b to every depth: c = −RN(a·b) plus k units at a random bit,
  //    and a·b exact with c = −a·b (+0 expected)
  t.clear();
  for (std::size_t i = 0; i < n_random / 4; ++i) {
    const T a = unit(-safe / 2, safe / 2), b = unit(-safe / 2, safe / 2);
    const T ab = a * b;
    const int shift = std::uniform_int_distribution<int>(0, 3 * p)(rng);
    const int k = std::uniform_int_distribution<int>(-3, 3)(rng);
    const T c = -ab + static_cast<T>(k) * std::ldexp(std::fabs(ab), -p - shift);
    t.push_back({a, b, c});
    const T ai = std::ldexp(T(std::uniform_int_distribution<int>(1, 1 << 10)(rng)), std::uniform_int_distribution<int>(-safe / 2, safe / 2)(rng));
    t.push_back({sgn(ai), sgn(T(3)), -(ai * T(3))});  // may be −(−x): either sign
    t.push_back({ai, T(3), -(ai * T(3))});
  }
  CHECK(mismatches(std::move(t), "cancellation", rng) == 0);

  // 4. ties and near-ties: c with ulp u, a·b = ±u/2 · (1 ± 2^-i)(1 ± 2^-j) (exactly u/2 when
  //    both are 0): exact results halfway between two floats, or just beside halfway
  //    (where rounding the sum first to a wider format would round twice)
  t.clear();
  for (std::size_t i = 0; i < n_random / 4; ++i) {
    const T c = unit(-safe / 2, safe / 2);
    const T u = std::ldexp(T(1), std::ilogb(c) - (p - 1));
    const int di = std::uniform_int_distribution<int>(0, p - 1)(rng);
    const int dj = std::uniform_int_distribution<int>(0, p - 1)(rng);
    const T fa = di ? T(1) + sgn(std::ldexp(T(1), -di)) : T(1);
    const T fb = dj ? T(1) + sgn(std::ldexp(T(1), -dj)) : T(1);
    const int s = std::uniform_int_distribution<int>(-20, 20)(rng);
    const int m = 2 * std::uniform_int_distribution<int>(0, 3)(rng) + 1;  // odd halves
    t.push_back({sgn(std::ldexp(fa, s)), std::ldexp(fb * T(m), -s) * u / 2, c});
  }
  CHECK(mismatches(std::move(t), "ties", rng) == 0);

  // 5. results at and around powers of two: c = ±2^k, a·b = ±2^(k−q)·small integer
  t.clear();
  for (std::size_t i = 0; i < n_random / 8; ++i) {
    const int k = std::uniform_int_distribution<int>(-safe / 2, safe / 2)(rng);
    const int q = std::uniform_int_distribution<int>(p - 3, 2 * p + 3)(rng);
    const T a = sgn(T(std::uniform_int_distribution<int>(1, 9)(rng)));
    const int sb = std::uniform_int_distribution<int>(-10, 10)(rng);
    t.push_back({std::ldexp(a, sb), std::ldexp(T(1), k - q - sb), sgn(std::ldexp(T(1), k))});
  }
  CHECK(mismatches(std::move(t), "powers of two", rng) == 0);

  // 6. zeros of both signs, inf and NaN in every position, with each other and with
  //    ordinary, tiny and huge values
  t.clear();
  for (int rep = 0; rep < 200; ++rep) {
    const T vals[] = {T(0), -T(0), inf, -inf, nan, unit(-safe, safe), unit(-safe, safe),
                      unit(emin_sub, emin_sub + p), unit(emax - p, emax), T(1), -T(1)};
    for (T a : vals)
      for (T b : vals)
        for (T c : vals) t.push_back({a, b, c});
  }
  CHECK(mismatches(std::move(t), "zeros, inf, NaN", rng) == 0);
}

}  // namespace

TEST_CASE("soft_fma: double lanes give std::fma's bits (random, range, cancellation, ties, "
          "powers of two, zeros, inf and NaN)",
          "[simd][soft_fma]") {
  check_all<double>(std::size_t{1} << 21, 450);
}

TEST_CASE("soft_fma: the generic instance's mul_add and neg_mul_add are fused in double lanes and not in float lanes", "[simd][soft_fma]") {
  // 1 + 2^-30 squared is 1 + 2^-29 + 2^-60: only a fused operation keeps the 2^-60
  const double x = 1.0 + 0x1p-30;
  PD a, c;
  for (int k = 0; k < 8; ++k) {
    a.v[k] = x * (k + 1);
    c.v[k] = -(1.0 + 0x1p-29) * (k + 1) * (k + 1);
  }
  const PD r = fused_soft::mul_add(a, a, c), n = fused_soft::neg_mul_add(a, a, PD{-c.v});
  for (int k = 0; k < 8; ++k) {
    CHECK(r.v[k] == std::fma(a.v[k], a.v[k], c.v[k]));
    CHECK(r.v[k] == 0x1p-60 * (k + 1) * (k + 1));
    CHECK(n.v[k] == -r.v[k]);
  }
  const float y = 1.0f + 0x1p-12f;
  PF f, g;
  for (int k = 0; k < 16; ++k) {
    f.v[k] = y;
    g.v[k] = -(1.0f + 0x1p-11f);
  }
  // float lanes round twice by contract (simd.hpp, unfused_float): (1 + 2^-11 + 2^-24)
  // rounds to the even 1 + 2^-11 first, so the sum is 0, where a fused one gives 2^-24
  const PF rf = fused_soft::mul_add(f, f, g);
  for (int k = 0; k < 16; ++k) CHECK(rf.v[k] == 0.0f);
}
