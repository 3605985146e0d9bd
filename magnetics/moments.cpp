// magnetics/moments.cpp — bookkeeping of the moment arrays and the sub-pair gauge.
#include "magnetics/moments.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace magsim::mag {

Vec3 any_perpendicular(const Vec3& u) {
  // cross with the coordinate axis least aligned with u
  Vec3 a = Vec3::UnitX();
  if (std::abs(u.y()) < std::abs(u.x()) && std::abs(u.y()) <= std::abs(u.z())) a = Vec3::UnitY();
  else if (std::abs(u.z()) < std::abs(u.x())) a = Vec3::UnitZ();
  return u.cross(a).normalized();
}

int MomentSet::add_induced(const Vec3& p, double V, double Ms_, std::int32_t grp) {
  position.push_back(p);
  volume.push_back(V);
  Ms.push_back(Ms_);
  kind.push_back(MomentKind::Induced);
  m_perm.push_back(Vec3::Zero());
  group.push_back(grp);
  radius.push_back(0.0);
  M1.push_back(Vec3::Zero());
  M2.push_back(Vec3::Zero());
  M.push_back(Vec3::Zero());
  seeded.push_back(0);
  return static_cast<int>(position.size()) - 1;
}

int MomentSet::add_permanent(const Vec3& p, double V, const Vec3& m, std::int32_t grp) {
  position.push_back(p);
  volume.push_back(V);
  Ms.push_back(0.0);
  kind.push_back(MomentKind::Permanent);
  m_perm.push_back(m);
  group.push_back(grp);
  radius.push_back(0.0);
  M1.push_back(Vec3::Zero());
  M2.push_back(Vec3::Zero());
  M.push_back(m / V);
  seeded.push_back(1);
  return static_cast<int>(position.size()) - 1;
}

void Magnetization::set_magnetization(std::size_t j, const Vec3& Mj, double ms) {
  const double n = Mj.norm();
  const double c = std::min(n / ms, 1.0);
  const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
  Vec3 u = n > 0 ? Vec3(Mj / n) : (seeded[j] ? Vec3((M1[j] - M2[j]).normalized()) : Vec3::UnitX());
  Vec3 w = M1[j] - M2[j];
  w -= w.dot(u) * u;
  w = w.norm() > 1e-12 * ms ? Vec3(w.normalized()) : any_perpendicular(u);
  if (n == 0) {  // unmagnetized: the pair is antiparallel along w ⊥ u
    M1[j] = ms * w;
    M2[j] = -ms * w;
  } else {
    M1[j] = ms * (c * u + s * w);
    M2[j] = ms * (c * u - s * w);
  }
  M[j] = 0.5 * (M1[j] + M2[j]);
  seeded[j] = 1;
}

void MomentSet::reset_magnetization() {
  for (std::size_t j = 0; j < size(); ++j) {
    if (kind[j] != MomentKind::Induced) continue;
    M1[j] = M2[j] = M[j] = Vec3::Zero();
    seeded[j] = 0;
  }
}

std::size_t MomentDesc::induced_count() const {
  return static_cast<std::size_t>(
      std::count(kind.begin(), kind.end(), MomentKind::Induced));
}

}  // namespace magsim::mag
