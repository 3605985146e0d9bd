// magnetics/det_math.hpp — the transcendental functions that reach a simulation's state,
// written with +, −, ×, ÷ and √ alone (each IEEE-exact) and exact scalings by powers of two,
// so that every x86-64 CPU, build and libm variant returns the same bits. glibc's libm picks
// FMA or SSE2 variants of tanh, exp, log1p, sin … at run time, and they differ in the last
// bit now and then; one such bit changes a chaotic scene's end state.
//
// Accuracy, measured against long double by tests/magnetics/det_math_test.cpp over each
// function's stated domain (ulp of the double result; tools/findings/portability.md):
//   exp, expm1, log, log1p, cosh ≤ 2 ulp;  tanh, atanh, sin, cos, atan, atan2, cbrt ≤ 3 ulp;
//   tan ≤ 5 ulp;  pow(a, b) = exp(b log a): ≤ 2 ulp + |b ln a| · 2⁻⁵² relative.
// sin, cos and tan reduce by π/2 in three parts: accurate for |x| ≤ 1e5 rad, deterministic
// beyond. Non-finite arguments follow the C library's conventions (NaN in, NaN out).
#pragma once

namespace magsim::mag::dmath {

double exp(double x);
/// e^x − 1, accurate near 0
double expm1(double x);
/// natural logarithm; log(0) = −∞, log(x < 0) = NaN
double log(double x);
/// ln(1 + x), accurate near 0; −∞ at −1, NaN below
double log1p(double x);
double tanh(double x);
double cosh(double x);
/// ½ ln((1 + x)/(1 − x)); ±∞ at ±1, NaN beyond
double atanh(double x);
double sin(double x);
double cos(double x);
double tan(double x);
double atan(double x);
/// the angle of (x, y) in [−π, π], as std::atan2 (atan2(±0, x < 0) = ±π)
double atan2(double y, double x);
double cbrt(double x);
/// a^b for a > 0 (NaN for a < 0, 0 for a = 0 and b > 0)
double pow(double a, double b);
/// √(x² + y²) without overflow care (arguments of geometric size)
inline double hypot(double x, double y);

}  // namespace magsim::mag::dmath

#include <cmath>

namespace magsim::mag::dmath {
inline double hypot(double x, double y) { return std::sqrt(x * x + y * y); }
}  // namespace magsim::mag::dmath
