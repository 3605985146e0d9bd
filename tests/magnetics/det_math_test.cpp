// tests/magnetics/det_math_test.cpp — the deterministic functions of det_math.hpp against
// long double (64-bit significand: its own error ~1e-19, 2⁻¹¹ of a double ulp): the maximum
// error in ulps over dense samples of each domain stays within the bound det_math.hpp
// states; and the special values.
#include "magnetics/det_math.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>

using namespace magsim::mag;

namespace {

// |f − ref| in ulps of the double nearest ref
double ulps(double f, long double ref) {
  const double r = static_cast<double>(ref);
  if (r == 0.0) return f == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  const double ulp = std::nextafter(std::fabs(r), std::numeric_limits<double>::infinity()) -
                     std::fabs(r);
  return static_cast<double>(std::fabs(static_cast<long double>(f) - ref) / ulp);
}

// The largest error over n log-spaced and n uniform samples of [lo, hi] (and their
// negatives when `odd`), printed for the findings.
double max_ulps(const char* name, double lo, double hi, bool odd,
                const std::function<double(double)>& f,
                const std::function<long double(long double)>& ref) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uni(lo, hi);
  double worst = 0, at = 0;
  auto probe = [&](double x) {
    const double e = ulps(f(x), ref(x));
    if (e > worst) {
      worst = e;
      at = x;
    }
  };
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    double x = uni(rng);
    if (lo > 0) x = lo * std::pow(hi / lo, static_cast<double>(i) / n);  // log-spaced too
    probe(x);
    probe(uni(rng));
    if (odd) probe(-x);
  }
  std::printf("det_math %-6s [%g, %g]: max %.2f ulp at %.17g\n", name, lo, hi, worst, at);
  return worst;
}

}  // namespace

TEST_CASE("det_math: every function within its stated ulp bound of long double", "[det_math]") {
  CHECK(max_ulps("exp", -700, 700, false, dmath::exp, [](long double x) { return expl(x); }) <= 2);
  CHECK(max_ulps("exp", 1e-12, 1, true, dmath::exp, [](long double x) { return expl(x); }) <= 2);
  CHECK(max_ulps("expm1", 1e-300, 30, true, dmath::expm1, [](long double x) { return expm1l(x); }) <= 2);
  CHECK(max_ulps("log", 1e-300, 1e300, false, dmath::log, [](long double x) { return logl(x); }) <= 2);
  CHECK(max_ulps("log", 0.5, 2, false, dmath::log, [](long double x) { return logl(x); }) <= 2);
  CHECK(max_ulps("log1p", 1e-300, 1e10, false, dmath::log1p, [](long double x) { return log1pl(x); }) <= 2);
  CHECK(max_ulps("log1p", -0.999999, -1e-300, false, dmath::log1p,
                 [](long double x) { return log1pl(x); }) <= 2);
  CHECK(max_ulps("cosh", 1e-10, 700, true, dmath::cosh, [](long double x) { return coshl(x); }) <= 2);
  CHECK(max_ulps("tanh", 1e-300, 30, true, dmath::tanh, [](long double x) { return tanhl(x); }) <= 3);
  CHECK(max_ulps("atanh", 1e-300, 1 - 1e-15, true, dmath::atanh, [](long double x) { return atanhl(x); }) <= 3);
  CHECK(max_ulps("atanh", 0.9, 1 - 1e-16, true, dmath::atanh, [](long double x) { return atanhl(x); }) <= 3);
  CHECK(max_ulps("sin", 1e-300, 1e5, true, dmath::sin, [](long double x) { return sinl(x); }) <= 3);
  CHECK(max_ulps("sin", 1e-8, 7, true, dmath::sin, [](long double x) { return sinl(x); }) <= 3);
  CHECK(max_ulps("cos", 1e-300, 1e5, true, dmath::cos, [](long double x) { return cosl(x); }) <= 3);
  CHECK(max_ulps("cos", 1e-8, 7, true, dmath::cos, [](long double x) { return cosl(x); }) <= 3);
  CHECK(max_ulps("tan", 1e-300, 1e5, true, dmath::tan, [](long double x) { return tanl(x); }) <= 5);
  CHECK(max_ulps("atan", 1e-300, 1e300, true, dmath::atan, [](long double x) { return atanl(x); }) <= 3);
  CHECK(max_ulps("atan", 0.01, 100, true, dmath::atan, [](long double x) { return atanl(x); }) <= 3);
  CHECK(max_ulps("cbrt", 1e-300, 1e300, true, dmath::cbrt, [](long double x) { return cbrtl(x); }) <= 3);
  CHECK(max_ulps("cbrt", 1e-6, 10, true, dmath::cbrt, [](long double x) { return cbrtl(x); }) <= 3);
  // atan2 over the circle at several radii: ≤ 3 ulp
  {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> ang(-3.14159, 3.14159), lr(-30, 30);
    double worst = 0;
    for (int i = 0; i < 400000; ++i) {
      const double r = std::pow(10.0, lr(rng)), a = ang(rng);
      const double x = r * std::cos(a), y = r * std::sin(a);
      worst = std::max(worst, ulps(dmath::atan2(y, x), atan2l(y, x)));
    }
    std::printf("det_math atan2: max %.2f ulp\n", worst);
    CHECK(worst <= 3);
  }
  // pow: ≤ 2 ulp + |b ln a| 2⁻⁵² relative
  {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> la(-20, 20), b(-8, 8);
    double worst = 0;
    for (int i = 0; i < 400000; ++i) {
      const double a = std::exp(la(rng)), e = b(rng);
      const double slack = std::fabs(e * std::log(a)) * 2.0 + 2.0;  // ulps: 2⁻⁵² relative ≤ 2 ulp
      worst = std::max(worst, ulps(dmath::pow(a, e), powl(a, e)) / slack);
    }
    std::printf("det_math pow: max %.2f of its bound\n", worst);
    CHECK(worst <= 1.0);
  }
}

TEST_CASE("det_math: special values as the C library has them", "[det_math]") {
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(dmath::exp(0.0) == 1.0);
  CHECK(dmath::exp(1000.0) == inf);
  CHECK(dmath::exp(-1000.0) == 0.0);
  CHECK(std::isnan(dmath::exp(std::nan(""))));
  CHECK(dmath::log(1.0) == 0.0);
  CHECK(dmath::log(0.0) == -inf);
  CHECK(std::isnan(dmath::log(-1.0)));
  CHECK(dmath::log1p(-1.0) == -inf);
  CHECK(dmath::log1p(0.0) == 0.0);
  CHECK(dmath::tanh(100.0) == 1.0);
  CHECK(dmath::tanh(-100.0) == -1.0);
  CHECK(dmath::tanh(0.0) == 0.0);
  CHECK(dmath::atanh(1.0) == inf);
  CHECK(std::isnan(dmath::atanh(1.5)));
  CHECK(dmath::sin(0.0) == 0.0);
  CHECK(dmath::cos(0.0) == 1.0);
  CHECK(dmath::atan2(0.0, -1.0) == Approx(3.141592653589793).epsilon(1e-16));
  CHECK(dmath::atan2(1.0, 0.0) == Approx(1.5707963267948966).epsilon(1e-16));
  CHECK(dmath::cbrt(-27.0) == -3.0);
  CHECK(dmath::cbrt(8.0) == 2.0);
  CHECK(dmath::pow(2.0, 10.0) == Approx(1024.0).epsilon(1e-15));
  CHECK(dmath::pow(0.0, 2.0) == 0.0);
  CHECK(dmath::cosh(0.0) == 1.0);
}
