// tools/paper/fig10.cpp — Fig. 10: force magnitude near a uniformly magnetized sphere.
#include "magnetics/dipole_field.hpp"
#include "magnetics/force_laws.hpp"
#include "tools/paper/experiments.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>

namespace magsim::experiments {

// Fig. 10: a uniformly magnetized sphere (radius 1 cm, NdFeB 1e6 A/m, moment along z) at the
// origin; an iron ball (radius 2 mm) at each point of the x–z cross-section outside it.
int run_fig10(const Fig10Opts& o) {
  ensure_dir(o.out);
  const double R = 0.01, a = 0.002, Ms = 1.6e6;
  const double Vs = 4.0 / 3.0 * mag::kPi * R * R * R, Va = 4.0 / 3.0 * mag::kPi * a * a * a;
  const Vec3 m(0, 0, 1e6 * Vs);  // outside, a uniformly magnetized sphere's field is a dipole's
  std::ofstream csv(o.out + "/fig10.csv");
  csv << "x,z,F_ours,F_kim\n";
  const double L = 0.03;
  double max_ratio = 0, min_ratio = 1e300;
  for (int i = 0; i < o.n; ++i) {
    for (int k = 0; k < o.n; ++k) {
      const Vec3 p(-L + 2 * L * i / (o.n - 1), 0, -L + 2 * L * k / (o.n - 1));
      if (p.norm() < R + a) {
        csv << p.x() << ',' << p.z() << ",nan,nan\n";
        continue;
      }
      const Vec3 H = mag::dipole_field(p, m);
      const mag::Mat3 J = mag::dipole_jacobian(p, m);
      // ours: M = f(H) (eq. 10), Zeeman force (eq. 4); Kim 2018: M by eq. 7, classic (eq. 13)
      const Vec3 Mo = mag::curve_M(mag::Curve::Tanh, H, Ms);
      const Vec3 Mk = mag::curve_M(mag::Curve::Kim, H, Ms);
      const double Fo = mag::zeeman_force(mag::Curve::Tanh, Va, Ms, Mo, H, J).norm();
      const double Fk = mag::classic_force(Va * Mk, J).norm();
      csv << p.x() << ',' << p.z() << ',' << Fo << ',' << Fk << '\n';
      max_ratio = std::max(max_ratio, Fo / Fk);
      min_ratio = std::min(min_ratio, Fo / Fk);
    }
  }
  json j = {{"sphere_radius", R}, {"ball_radius", a}, {"ratio_ours_over_kim_min", min_ratio},
            {"ratio_ours_over_kim_max", max_ratio}};
  std::ofstream(o.out + "/fig10.json") << j.dump(2) << "\n";
  std::printf("fig10: |F_ours|/|F_kim| ranges %.3f … %.3f over the cross-section\n", min_ratio,
              max_ratio);
  return 0;
}

}  // namespace magsim::experiments
