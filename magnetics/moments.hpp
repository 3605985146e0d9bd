// magnetics/moments.hpp — the moments of a magnetic system, structure of arrays.
//
// A moment j sits at world position p_j and stands for a volume V_j of material. It is
// either induced (magnetization M_j computed from the field, saturation Ms_j, carried as two
// sub-magnetizations M_j1, M_j2 with |M_jk| = Ms_j and M_j = (M_j1 + M_j2)/2, magnetics/PHYSICS.md)
// or permanent (a fixed world-frame moment m_j, A·m²). Moments with the same group id
// (≥ 0, usually a rigid body) exert no force on each other, but still magnetize each other.
#pragma once

#include "magnetics/types.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace magsim::mag {

/// Where the moments are and what they are made of: everything the field, force and
/// dynamics code reads besides the magnetization.
struct MomentDesc {
  std::vector<Vec3> position;       ///< (n) world position (m)
  std::vector<double> volume;       ///< (n) volume the moment stands for (m³), > 0
  std::vector<double> Ms;           ///< (n) saturation magnetization (A/m); 0 for permanent
  std::vector<MomentKind> kind;     ///< (n)
  std::vector<Vec3> m_perm;         ///< (n) world-frame permanent moment (A·m²); 0 for induced
  std::vector<std::int32_t> group;  ///< (n) rigid-body id, −1 = a group of its own
  /// (n) interaction radius a_j (m), from the moment's shape: with FieldOptions::
  /// bounded_pairs a pair is evaluated at a separation of at least a_i + a_j (field,
  /// Jacobian and so forces), so an overlap left by the contact solver cannot raise the
  /// magnetic pull. 0 = a point (never bounded); set by the engine, 0 from add_*.
  std::vector<double> radius;
  Vec3 H0 = Vec3::Zero();           ///< uniform external field (A/m)
  /// (n, or empty = none) 1 = an induced moment held at its magnetization: still a field
  /// source, but the relaxation solvers leave it as it is (a sleeping body's moments,
  /// engine/sleep.cpp). The exact solver does not read it.
  std::vector<std::uint8_t> frozen;

  std::size_t size() const { return position.size(); }
  std::size_t induced_count() const;
  /// Induced and not frozen: a moment the relaxation solvers update.
  bool solved(std::size_t j) const {
    return kind[j] == MomentKind::Induced && (frozen.empty() || !frozen[j]);
  }
};

/// The magnetization of the moments of a MomentDesc, the state the dynamics evolve (induced
/// moments; permanent moments keep M = m/V and M1 = M2 = 0). Held apart from the description
/// so that its owner — the engine keeps it in its State — is the only copy the solvers work on.
struct Magnetization {
  std::vector<Vec3> M1, M2;  ///< (n) sub-magnetizations, |M_jk| = Ms_j (A/m)
  std::vector<Vec3> M;       ///< (n) magnetization (A/m)
  std::vector<std::uint8_t> seeded;  ///< (n) 0 until the sub-pair axis has been chosen

  /// Sets induced moment j's magnetization to Mj (|Mj| ≤ Ms) keeping the sub-pair axis
  /// where possible: M_j1,2 = Ms (cos φ u ± sin φ w), cos φ = |Mj|/Ms.
  void set_magnetization(std::size_t j, const Vec3& Mj, double Ms);
};

/// The dipole moment m_j: V_j M_j for induced, m_perm_j for permanent (A·m²).
inline Vec3 moment(const MomentDesc& d, const Magnetization& mz, std::size_t j) {
  return d.kind[j] == MomentKind::Induced ? Vec3(d.volume[j] * mz.M[j]) : d.m_perm[j];
}

/// A magnetic system in one piece, description and magnetization (tools, tests, scratch).
/// The solvers take (MomentDesc, Magnetization); their MomentSet forms pass the set as both.
struct MomentSet : MomentDesc, Magnetization {
  /// Adds an unmagnetized induced moment (M = 0; its sub-pair axis is seeded on the first
  /// dynamics iteration, perpendicular to the field it feels). Returns its index.
  int add_induced(const Vec3& p, double V, double Ms_, std::int32_t grp = -1);
  /// Adds a permanent moment m (A·m²) of volume V. Returns its index.
  int add_permanent(const Vec3& p, double V, const Vec3& m, std::int32_t grp = -1);

  /// The dipole moment m_j (mag::moment).
  Vec3 moment(std::size_t j) const { return mag::moment(*this, *this, j); }
  /// Magnetization::set_magnetization with the moment's own Ms.
  using Magnetization::set_magnetization;
  void set_magnetization(std::size_t j, const Vec3& Mj) { set_magnetization(j, Mj, Ms[j]); }
  /// Forgets every induced magnetization (M = 0, unseeded).
  void reset_magnetization();
  /// Copies a description and its magnetization in (a scratch set keeps its storage).
  void assign(const MomentDesc& d, const Magnetization& mz) {
    MomentDesc::operator=(d);
    Magnetization::operator=(mz);
  }
};

/// A unit vector perpendicular to u (|u| > 0), chosen deterministically.
Vec3 any_perpendicular(const Vec3& u);

}  // namespace magsim::mag
