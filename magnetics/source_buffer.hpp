// magnetics/source_buffer.hpp — internal: the flat, padded source arrays the pair kernel reads
// (field_kernel.hpp), filled by the direct sum (dipole_field.cpp) and by Barnes–Hut.
// The lowest layer of the field sums: it includes no other magnetics header, so that the
// kernels and their dispatchers can all build on it.
#pragma once

#include <cstddef>
#include <vector>

namespace magsim::mag::detail {

/// Sources are padded to a multiple of this with zero moments far away (they add exactly 0).
inline constexpr std::size_t kSourcePad = 8;
/// Position of a padding source or cell (m): far enough to never matter, near enough that
/// every power of 1/|r| the kernels form (up to 1/|r|¹¹) stays a normal double; its zero
/// moment makes every term exactly zero.
inline constexpr double kPadPosition = 1e15;

/// Flat source arrays (structure of arrays) as the pair kernel reads them (field_kernel.hpp):
/// the direct sum's packed sources, Barnes–Hut's tree-ordered ones and a target group's
/// gathered near sources alike. clear() keeps the capacity.
struct SourceBuffer {
  std::vector<double> x, y, z;     ///< (ns) position (m)
  std::vector<double> mx, my, mz;  ///< (ns) moment (A·m²)
  std::vector<double> id;          ///< (ns) moment index (−1 for padding), for self-exclusion
  std::vector<double> grp;         ///< (ns) group id (negative groups stored as −1)
  std::vector<double> rad;         ///< (ns) interaction radius (m), 0 = a point

  std::size_t size() const { return x.size(); }
  void clear();
  void push(double px, double py, double pz, double qx, double qy, double qz, double index,
            double group, double radius = 0.0);
  /// Appends sources [b, e) of s.
  void append(const SourceBuffer& s, std::size_t b, std::size_t e);
  /// Pads to a multiple of kSourcePad with zero moments far away (they add exactly 0).
  void pad();
};

}  // namespace magsim::mag::detail
