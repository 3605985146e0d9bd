// Tests for magnetics/dipole_field.cpp: eq. 1, its analytic Jacobian, the summed kernel
// (AVX-512 and portable paths, cache chunks, determinism), run through compute_fields
// (magnetics/fields.hpp).
#include "magnetics/dipole_field.hpp"
#include "magnetics/field_kernel.hpp"
#include "magnetics/fields.hpp"
#include "tests/magnetics/fixtures.hpp"

#include <catch2/catch.hpp>
#include <omp.h>

#include <cstring>

using namespace magsim::mag;

namespace {
// central differences of the summed field at p (sources fixed)
Mat3 fd_jacobian(const MomentSet& s, const Vec3& p, double eps2, int skip, double h) {
  Mat3 J;
  for (int b = 0; b < 3; ++b) {
    Vec3 d = Vec3::Zero();
    d[b] = h;
    J.col(b) = (field_at(s, p + d, eps2, skip) - field_at(s, p - d, eps2, skip)) / (2 * h);
  }
  return J;
}
}  // namespace

TEST_CASE("dipole field matches eq. 1 on the axis and the equator", "[field]") {
  const Vec3 m(0, 0, 2.0);  // A·m²
  const double r = 0.05;
  // on the axis: H = 2m/(4π r³); on the equator: H = −m/(4π r³)
  const Vec3 Ha = dipole_field(Vec3(0, 0, r), m);
  const Vec3 He = dipole_field(Vec3(r, 0, 0), m);
  CHECK(Ha.z() == Approx(2 * 2.0 / (4 * kPi * r * r * r)).epsilon(1e-14));
  CHECK(He.z() == Approx(-2.0 / (4 * kPi * r * r * r)).epsilon(1e-14));
  CHECK(std::abs(Ha.x()) + std::abs(He.x()) < 1e-12);
}

TEST_CASE("field Jacobian: analytic equals finite differences, symmetric and trace-free",
          "[field][fd]") {
  const MomentSet s = magsim::test::random_cloud(24, 7);
  MomentSet set = s;
  for (std::size_t j = 0; j < set.size(); ++j)  // give the induced moments a magnetization
    if (set.kind[j] == MomentKind::Induced) set.set_magnetization(j, Vec3(1e5, 2e5, -3e5));
  FieldWorkspace ws;
  std::vector<Vec3> H;
  std::vector<Mat3> J;
  compute_fields(set, FieldOptions{}, &H, &J, &ws);
  double worst = 0;
  for (std::size_t j = 0; j < set.size(); ++j) {
    const Mat3 Jfd = fd_jacobian(set, set.position[j], 0.0, static_cast<int>(j), 1e-7);
    worst = std::max(worst, (J[j] - Jfd).norm() / J[j].norm());
    CHECK((J[j] - J[j].transpose()).norm() <= 1e-12 * J[j].norm());
    CHECK(std::abs(J[j].trace()) <= 1e-12 * J[j].norm());
    CHECK((H[j] - field_at(set, set.position[j], 0.0, static_cast<int>(j))).norm() <=
          1e-12 * H[j].norm());
  }
  INFO("worst relative FD error of J: " << worst);
  CHECK(worst <= 1e-6);
}

TEST_CASE("softened field and Jacobian are consistent", "[field][fd]") {
  const Vec3 m(0.3, -0.1, 0.7);
  const double eps2 = 1e-3 * 1e-3;
  for (const Vec3& r : {Vec3(1e-3, 2e-3, -0.5e-3), Vec3(0.02, 0.0, 0.01), Vec3(1e-5, 0, 0)}) {
    const Mat3 J = dipole_jacobian(r, m, eps2);
    Mat3 Jfd;
    const double h = 1e-6 * std::max(r.norm(), 1e-3);
    for (int b = 0; b < 3; ++b) {
      Vec3 d = Vec3::Zero();
      d[b] = h;
      Jfd.col(b) = (dipole_field(r + d, m, eps2) - dipole_field(r - d, m, eps2)) / (2 * h);
    }
    CHECK((J - Jfd).norm() <= 1e-6 * J.norm());
    CHECK(dipole_field(r, m, eps2).allFinite());
  }
  // at r = 0 the softened field is finite: −m/(4π ε³)
  CHECK(dipole_field(Vec3::Zero(), m, eps2).isApprox(-m / (4 * kPi * 1e-9), 1e-12));
}

TEST_CASE("a moment never feels itself — same-group sources are left out of J only", "[field]") {
  MomentSet s;
  s.add_permanent(Vec3(0, 0, 0), 1e-6, Vec3(0, 0, 1), 3);
  s.add_permanent(Vec3(0.01, 0, 0), 1e-6, Vec3(0, 0, 1), 3);
  s.add_permanent(Vec3(0, 0.02, 0), 1e-6, Vec3(1, 0, 0), -1);
  FieldWorkspace ws;
  std::vector<Vec3> H;
  std::vector<Mat3> J;
  compute_fields(s, FieldOptions{}, &H, &J, &ws);
  const Vec3 Hexp = dipole_field(Vec3(-0.01, 0, 0), Vec3(0, 0, 1)) +
                    dipole_field(Vec3(0, -0.02, 0), Vec3(1, 0, 0));
  CHECK(H[0].isApprox(Hexp, 1e-13));
  // J at moment 0 only from moment 2 (moment 1 shares group 3)
  CHECK(J[0].isApprox(dipole_jacobian(Vec3(0, -0.02, 0), Vec3(1, 0, 0)), 1e-13));
}

namespace {
// the summed field and Jacobian at moment j the slow way: dipole_field/dipole_jacobian over
// every other nonzero moment, J over other groups only
void reference_at(const MomentSet& s, std::size_t j, double eps2, Vec3* H, Mat3* J) {
  *H = s.H0;
  J->setZero();
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec3 m = s.moment(i);
    if (i == j || m.isZero(0)) continue;
    const Vec3 r = s.position[j] - s.position[i];
    *H += dipole_field(r, m, eps2);
    if (s.group[j] < 0 || s.group[i] != s.group[j]) *J += dipole_jacobian(r, m, eps2);
  }
}

// 600 moments in rigid groups of 3 (and some free ones), a fifth unmagnetized
MomentSet grouped_cloud(int n) {
  MomentSet s = magsim::test::sparse_cloud(n, 11);
  for (std::size_t j = 0; j < s.size(); ++j) {
    if (j % 5 == 4) s.set_magnetization(j, Vec3::Zero());
    s.group[j] = j % 7 == 6 ? -1 : static_cast<std::int32_t>(j / 3);
  }
  s.H0 = Vec3(1e3, -2e3, 5e2);
  return s;
}
}  // namespace

TEST_CASE("SIMD and portable direct kernels match the pairwise formulas (groups, softening, "
          "zero moments)", "[field][simd]") {
  MAGSIM_NOTE_IF_NO_SIMD();
  const MomentSet s = grouped_cloud(600);
  for (double eps : {0.0, 1e-3}) {
    FieldOptions o;
    o.softening = eps;
    std::vector<Vec3> H_simd;
    std::vector<Mat3> J_simd;
    for (detail::KernelPath path :
         {detail::KernelPath::Avx512, detail::KernelPath::Fma, detail::KernelPath::Generic}) {
      const bool simd = path == detail::KernelPath::Avx512;
      detail::limit_kernel_path(path);
      FieldWorkspace ws;
      std::vector<Vec3> H;
      std::vector<Mat3> J;
      compute_fields(s, o, &H, &J, &ws);
      if (simd) {
        H_simd = H;
        J_simd = J;
      } else {  // the same bits on every path (magnetics/simd.hpp)
        for (std::size_t j = 0; j < s.size(); ++j) {
          CHECK((H[j].array() == H_simd[j].array()).all());
          CHECK((J[j].array() == J_simd[j].array()).all());
        }
      }
      double worst_h = 0, worst_j = 0;
      for (std::size_t j = 0; j < s.size(); ++j) {
        Vec3 Hr;
        Mat3 Jr;
        reference_at(s, j, eps * eps, &Hr, &Jr);
        worst_h = std::max(worst_h, (H[j] - Hr).norm() / Hr.norm());
        worst_j = std::max(worst_j, (J[j] - Jr).norm() / Jr.norm());
      }
      INFO(detail::kernel_path_name(detail::kernel_path()) << ", ε " << eps << ": worst relative H " << worst_h << ", J "
                   << worst_j);
      CHECK(worst_h <= 1e-12);
      CHECK(worst_j <= 1e-12);
    }
    detail::enable_simd_kernel(true);
  }
}

TEST_CASE("the direct sum over more sources than one cache chunk, and at chosen targets",
          "[field]") {
  const MomentSet s = grouped_cloud(9000);  // > 4096 sources: several chunks
  FieldWorkspace ws;
  std::vector<Vec3> H, Ht;
  std::vector<Mat3> J, Jt;
  FieldOptions direct;
  direct.solver = FieldSolver::Direct;  // the default, Auto, would take Barnes–Hut at 9000
  compute_fields(s, direct, &H, &J, &ws);
  const std::vector<int> targets{0, 17, 4095, 4096, 8999, 5};
  compute_fields_at(s, direct, targets, &Ht, &Jt, &ws);
  for (std::size_t k = 0; k < targets.size(); ++k) {
    const int j = targets[k];
    Vec3 Hr;
    Mat3 Jr;
    reference_at(s, j, 0.0, &Hr, &Jr);
    CHECK((H[j] - Hr).norm() <= 1e-12 * Hr.norm());
    CHECK((J[j] - Jr).norm() <= 1e-12 * Jr.norm());
    CHECK(Ht[k] == H[j]);  // the same sums in the same order
    CHECK(Jt[k] == J[j]);
  }
}

TEST_CASE("the direct sum is bitwise the same for 1 and 2 threads", "[field]") {
  const MomentSet s = grouped_cloud(700);
  std::vector<Vec3> H1, H2;
  std::vector<Mat3> J1, J2;
  FieldWorkspace ws;
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  compute_fields(s, FieldOptions{}, &H1, &J1, &ws);
  omp_set_num_threads(2);
  compute_fields(s, FieldOptions{}, &H2, &J2, &ws);
  omp_set_num_threads(saved);
  CHECK(std::memcmp(H1.data(), H2.data(), H1.size() * sizeof(Vec3)) == 0);
  CHECK(std::memcmp(J1.data(), J2.data(), J1.size() * sizeof(Mat3)) == 0);
}
