// magnetics/types.hpp — shared vocabulary of the magnetics core (Eigen only).
// SI units throughout: metres, A/m for H and M, A·m² for moments, newtons, seconds.
#pragma once

#include "magnetics/names.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace magsim::mag {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kMu0 = 4e-7 * kPi;  ///< vacuum permeability (T·m/A)

enum class MomentKind : std::uint8_t { Induced, Permanent };

/// Magnetization dynamics / solver. Exact is the Newton ground truth (no dynamics);
/// Anderson solves M = f(H(M)) by Anderson-accelerated Picard iteration (beyond the paper).
enum class Method : std::uint8_t { Ours, OursRealigned, Kim2018, DampingLLG, Exact, Anderson };
inline constexpr NameTable<Method, 6> kMethodNames{{{Method::Ours, "ours"},
                                                    {Method::OursRealigned, "ours-realigned"},
                                                    {Method::Kim2018, "kim2018"},
                                                    {Method::DampingLLG, "damping-llg"},
                                                    {Method::Exact, "exact"},
                                                    {Method::Anderson, "anderson"}}};

/// Magnetization curve M = f(H).
enum class Curve : std::uint8_t {
  Tanh,  ///< ours, eq. 10: f(H) = Ms tanh(3|H|/Ms) H/|H|
  Kim,   ///< Kim 2018, eq. 7: M = H/γ_D below saturation, Ms H/|H| above (γ_D = 1/3)
  /// A sphere of bulk iron, μr,initial = 1000 (kIronChi): M solves M = Ms tanh(χ(|H| − |M|/3)/Ms)
  /// along H, the bulk tanh law inside a sphere's self-field −M/3 (PHYSICS.md, "The curves").
  /// The near-field reference's material: eq. 10 gives a lone sphere 0.80× its moment at 0.3 Ms.
  Iron
};
inline constexpr NameTable<Curve, 3> kCurveNames{
    {{Curve::Tanh, "tanh"}, {Curve::Kim, "kim"}, {Curve::Iron, "iron"}}};
/// The curves an option may choose (kim is kim2018's own and comes with that method).
inline constexpr NameTable<Curve, 2> kCurveOptionNames{{{Curve::Tanh, "tanh"}, {Curve::Iron, "iron"}}};
/// χ = μr,initial − 1 of Curve::Iron.
inline constexpr double kIronChi = 999.0;

/// Force model for induced moments.
enum class ForceModel : std::uint8_t {
  /// The method's own pairing (force_model_of): classic for anderson, exact and kim2018,
  /// eq. 4 for ours, ours-realigned and damping-llg. An option's default, which
  /// resolve_force_model replaces before any force is computed.
  Method,
  /// ours, eq. 4 (M varies with H): F = μ0 V J [A (2M + H) + M], each moment's gradient with
  /// the sources fixed; 2(χ+1) ≈ 8× classic in the linear range
  Zeeman,
  Classic,  ///< eqs. 13–14: F = μ0 J m, m held constant
  /// eq. 4 as the gradient of the system's Zeeman energy with every magnetization a variable
  /// (forces_total.hpp): conservative, momentum-conserving; compute_forces'
  /// reaction-symmetric pairing has no effect on it
  ZeemanTotal
};
inline constexpr NameTable<ForceModel, 4> kForceModelNames{{{ForceModel::Method, "method"},
                                                            {ForceModel::Zeeman, "zeeman"},
                                                            {ForceModel::Classic, "classic"},
                                                            {ForceModel::ZeemanTotal, "zeeman-total"}}};

/// The curve a method converges to (Kim 2018 uses eq. 7, every other method eq. 10).
inline Curve curve_of(Method m) { return m == Method::Kim2018 ? Curve::Kim : Curve::Tanh; }
/// Whether a method converges to the curve the options choose: anderson and exact set
/// M = f(H) for any f; Kim 2018 keeps eq. 7 and the θ dynamics eq. 10 (their γ_C is eq. 10's).
inline bool takes_chosen_curve(Method m) { return m == Method::Anderson || m == Method::Exact; }
/// The curve a method converges to when `chosen` is asked for.
inline Curve curve_of(Method m, Curve chosen) { return takes_chosen_curve(m) ? chosen : curve_of(m); }
/// Empty when method m may be asked for curve c, else why not, in one line (for the caller
/// to prefix with the option's name): eq. 10 is every method's but Kim 2018's, iron only
/// the methods that take a chosen curve.
inline std::string curve_error(Method m, Curve c) {
  if (c != Curve::Iron || takes_chosen_curve(m)) return {};
  return std::string("iron needs method anderson or exact (") + kMethodNames.name(m) + " keeps its own curve)";
}
/// The force model a method is paired with: eq. 4 for the paper's θ dynamics and the
/// damping-only LLG (ours, ours-realigned, damping-llg: the paper's pairing); the classic force
/// for Kim 2018 and for the converged solves (anderson, exact), where it is −∇U* of the
/// co-energy (coenergy.hpp) and the engine's default.
inline ForceModel force_model_of(Method m) {
  switch (m) {
    case Method::Kim2018:
    case Method::Anderson:
    case Method::Exact: return ForceModel::Classic;
    default: return ForceModel::Zeeman;
  }
}

/// The force `chosen` with ForceModel::Method replaced by the method's own pairing.
inline ForceModel resolve_force_model(ForceModel chosen, Method m) {
  return chosen == ForceModel::Method ? force_model_of(m) : chosen;
}

/// A method's name in kMethodNames.
inline const char* method_name(Method m) { return kMethodNames.name(m); }
/// Parses a method name (kMethodNames); returns false (and leaves *out alone) on an unknown name.
inline bool parse_method(const std::string& name, Method* out) { return kMethodNames.parse(name, out); }

}  // namespace magsim::mag
