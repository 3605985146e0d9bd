// magnetics/det_math.cpp — deterministic transcendental functions (det_math.hpp).
//
// Every function reduces its argument exactly (Cody–Waite splits of ln 2 and π/2 whose high
// parts carry few enough bits that k·hi is exact) and evaluates a Taylor series by Horner's
// rule far enough that the truncation is below 2⁻⁶⁰ relative. Only +, −, ×, ÷, √, floor and
// exact power-of-two scalings (frexp, ldexp) are used: each is exact or correctly rounded in
// IEEE 754, so the result is the same on every CPU and in every build (the build turns FMA
// contraction off, CMakeLists.txt).
#include "magnetics/det_math.hpp"

#include <cmath>
#include <limits>

namespace magsim::mag::dmath {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ln 2 = kLn2Hi + kLn2Lo, kLn2Hi with 32 significant bits (k·kLn2Hi exact for |k| < 2²¹)
constexpr double kLn2Hi = 0.6931471803691238;
constexpr double kLn2Lo = 1.9082149292705877e-10;
constexpr double kInvLn2 = 1.4426950408889634;
// π/2 = kPio2A + kPio2B + kPio2C, the first two with 33 significant bits
constexpr double kPio2A = 1.5707963267341256;
constexpr double kPio2B = 6.077100506303966e-11;
constexpr double kPio2C = 2.0222662487959506e-21;
constexpr double kTwoOverPi = 0.6366197723675814;
// π/2, π/6 and π as a double and the rest
constexpr double kPio2Hi = 1.5707963267948966, kPio2Lo = 6.123233995736766e-17;
constexpr double kPio6Hi = 0.5235987755982989, kPio6Lo = -5.360408832255455e-17;
constexpr double kPiHi = 3.141592653589793, kPiLo = 1.2246467991473532e-16;
constexpr double kSqrt3 = 1.7320508075688772;
constexpr double kTanPio12 = 0.2679491924311227;  // tan(π/12) = 2 − √3

// 1/n! for n = 0 … 20
constexpr double kInvFact[21] = {
    1.0, 1.0, 1.0 / 2, 1.0 / 6, 1.0 / 24, 1.0 / 120, 1.0 / 720, 1.0 / 5040, 1.0 / 40320,
    1.0 / 362880, 1.0 / 3628800, 1.0 / 39916800, 1.0 / 479001600, 1.0 / 6227020800.0,
    1.0 / 87178291200.0, 1.0 / 1307674368000.0, 1.0 / 20922789888000.0,
    1.0 / 355687428096000.0, 1.0 / 6402373705728000.0, 1.0 / 121645100408832000.0,
    1.0 / 2432902008176640000.0};

// e^r − 1 = Σ_{n=1}^{20} rⁿ/n!, |r| ≤ 0.7 (the tail 0.7²¹/21! < 1e-22)
double expm1_series(double r) {
  double p = kInvFact[20];
  for (int n = 19; n >= 1; --n) p = p * r + kInvFact[n];
  return p * r;
}

// ln(1 + f) for 1 + f ∈ [√½, √2], f exact: with s = f/(2 + f), ln(1 + f) = 2 atanh(s)
// = 2s + s·R(s²), R(z) = Σ_{n≥1} 2zⁿ/(2n + 1); and 2s = f − s·f, so
// ln(1 + f) = f − (f²/2 − s·(f²/2 + R)), whose leading term f carries no rounding.
// |s| ≤ 0.1716, z ≤ 0.0295: R to z¹³ (the tail 2·0.0295¹⁴/29 < 1e-22).
double log1p_kernel(double f) {
  const double s = f / (2.0 + f);
  const double z = s * s;
  double R = 2.0 / 27.0;
  for (int n = 12; n >= 1; --n) R = R * z + 2.0 / (2 * n + 1);
  R *= z;
  const double hfsq = 0.5 * f * f;
  return f - (hfsq - s * (hfsq + R));
}

// sin r and cos r for |r| ≤ π/4 (+ rounding): Taylor to r¹⁹ and r²⁰
double sin_kernel(double r) {
  const double z = r * r;
  double p = -kInvFact[19];
  for (int n = 17; n >= 3; n -= 2) p = p * z + ((n / 2) % 2 ? -kInvFact[n] : kInvFact[n]);
  return r + r * z * p;
}
double cos_kernel(double r) {
  const double z = r * r;
  double p = kInvFact[20];
  for (int n = 18; n >= 4; n -= 2) p = p * z + ((n / 2) % 2 ? -kInvFact[n] : kInvFact[n]);
  const double hz = 0.5 * z;
  return (1.0 - hz) + z * z * p;
}

// x = k·π/2 + r, |r| ≤ π/4 (+ rounding); returns r and k mod 4
double reduce_pio2(double x, int* quadrant) {
  const double k = std::floor(x * kTwoOverPi + 0.5);
  const double r = ((x - k * kPio2A) - k * kPio2B) - k * kPio2C;
  const double m = k - 4.0 * std::floor(k * 0.25);  // k mod 4, exact
  *quadrant = static_cast<int>(m);
  return r;
}

// atan a for 0 ≤ a ≤ 1: a > tan(π/12) maps to π/6 + atan((√3 a − 1)/(a + √3)); then the
// Taylor series to t²⁹ (tan(π/12)³¹/31 < 1e-19)
double atan_unit(double a) {
  double base_hi = 0.0, base_lo = 0.0;
  if (a > kTanPio12) {
    a = (kSqrt3 * a - 1.0) / (a + kSqrt3);
    base_hi = kPio6Hi;
    base_lo = kPio6Lo;
  }
  const double z = a * a;
  double p = 1.0 / 29.0;
  for (int n = 27; n >= 3; n -= 2) p = p * z + ((n / 2) % 2 ? -1.0 / n : 1.0 / n);
  return base_hi + (base_lo + (a + a * z * p));
}

}  // namespace

double expm1(double x) {
  if (std::isnan(x)) return x;
  if (std::fabs(x) <= 0.7) return expm1_series(x);
  if (x < -40.0) return -1.0;
  return exp(x) - 1.0;
}

double exp(double x) {
  if (std::isnan(x)) return x;
  if (x > 709.782712893384) return kInf;
  if (x < -745.1332191019412) return 0.0;
  // x = k ln 2 + r, |r| ≤ ½ ln 2 (+ rounding); e^x = 2^k (1 + expm1(r))
  const double k = std::floor(x * kInvLn2 + 0.5);
  const double r = (x - k * kLn2Hi) - k * kLn2Lo;
  return std::ldexp(1.0 + expm1_series(r), static_cast<int>(k));
}

double log(double x) {
  if (std::isnan(x) || x == kInf) return x;
  if (x == 0.0) return -kInf;
  if (x < 0.0) return kNaN;
  int e = 0;
  double m = std::frexp(x, &e);  // x = m 2^e, m ∈ [½, 1)
  if (m < 0.70710678118654752) {
    m *= 2.0;
    --e;
  }
  // ln x = e ln 2 + ln(1 + f), f = m − 1 exact (Sterbenz)
  const double f = m - 1.0;
  const double k = e;
  return k * kLn2Hi + (log1p_kernel(f) + k * kLn2Lo);
}

double log1p(double x) {
  if (std::isnan(x) || x == kInf) return x;
  if (x == -1.0) return -kInf;
  if (x < -1.0) return kNaN;
  if (x > -0.2928932188134524 && x < 0.41421356237309505) return log1p_kernel(x);
  // u = 1 + x rounded; ln(1 + x) = ln u + (x − (u − 1))/u to first order, where
  // x − (u − 1) is u's rounding error, exactly
  const double u = 1.0 + x;
  const double c = (x - (u - 1.0)) / u;
  return log(u) + c;
}

double tanh(double x) {
  if (std::isnan(x)) return x;
  const double a = std::fabs(x);
  if (a > 22.0) return std::copysign(1.0, x);  // 1 − tanh < 1e-19
  // tanh a = t/(t + 2), t = e^{2a} − 1
  const double t = expm1(2.0 * a);
  return std::copysign(t / (t + 2.0), x);
}

double cosh(double x) {
  if (std::isnan(x)) return x;
  const double e = exp(std::fabs(x));
  return 0.5 * e + 0.5 / e;
}

double atanh(double x) {
  if (std::isnan(x)) return x;
  const double a = std::fabs(x);
  if (a > 1.0) return kNaN;
  if (a == 1.0) return std::copysign(kInf, x);
  // atanh a = ½ ln(1 + 2a/(1 − a)), 1 − a exact for a ≥ ½
  return std::copysign(0.5 * log1p(2.0 * a / (1.0 - a)), x);
}

double sin(double x) {
  if (!std::isfinite(x)) return kNaN;
  int q = 0;
  const double r = reduce_pio2(x, &q);
  switch (q) {
    case 0: return sin_kernel(r);
    case 1: return cos_kernel(r);
    case 2: return -sin_kernel(r);
    default: return -cos_kernel(r);
  }
}

double cos(double x) {
  if (!std::isfinite(x)) return kNaN;
  int q = 0;
  const double r = reduce_pio2(x, &q);
  switch (q) {
    case 0: return cos_kernel(r);
    case 1: return -sin_kernel(r);
    case 2: return -cos_kernel(r);
    default: return sin_kernel(r);
  }
}

double tan(double x) {
  if (!std::isfinite(x)) return kNaN;
  int q = 0;
  const double r = reduce_pio2(x, &q);
  const double s = sin_kernel(r), c = cos_kernel(r);
  return (q % 2 == 0) ? s / c : -c / s;
}

double atan(double x) {
  if (std::isnan(x)) return x;
  const double a = std::fabs(x);
  if (a == kInf) return std::copysign(kPio2Hi, x);
  // a > 1: atan a = π/2 − atan(1/a)
  const double r = a <= 1.0 ? atan_unit(a) : kPio2Hi + (kPio2Lo - atan_unit(1.0 / a));
  return std::copysign(r, x);
}

double atan2(double y, double x) {
  if (std::isnan(x) || std::isnan(y)) return x + y;
  if (y == 0.0) {
    if (std::signbit(x)) return std::copysign(kPiHi, y);
    return y;  // ±0
  }
  if (x == 0.0) return std::copysign(kPio2Hi, y);
  const double ax = std::fabs(x), ay = std::fabs(y);
  double t;  // the angle of (|x|, |y|) in [0, π/2]
  if (ax == kInf && ay == kInf) t = 0.5 * kPio2Hi;
  else if (ay <= ax) t = atan(ay / ax);
  else t = kPio2Hi + (kPio2Lo - atan(ax / ay));
  if (std::signbit(x)) t = kPiHi + (kPiLo - t);
  return std::copysign(t, y);
}

double cbrt(double x) {
  if (x == 0.0 || !std::isfinite(x)) return x;
  int e = 0;
  double m = std::frexp(std::fabs(x), &e);  // |x| = m 2^e, m ∈ [½, 1)
  // make e a multiple of 3: m ∈ [½, 4)
  const int r = ((e % 3) + 3) % 3;
  m = std::ldexp(m, r);
  e -= r;
  // Newton on y³ = m from a linear start (|error| < 30 %): six steps reach full precision
  double y = 0.7 + 0.3 * m;
  for (int i = 0; i < 6; ++i) y = y - (y * y * y - m) / (3.0 * y * y);
  return std::copysign(std::ldexp(y, e / 3), x);
}

double pow(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return a + b;
  if (b == 0.0) return 1.0;
  if (a < 0.0) return kNaN;
  if (a == 0.0) return b > 0.0 ? 0.0 : kInf;
  return exp(b * log(a));
}

}  // namespace magsim::mag::dmath
