// Tests for magnetics/barnes_hut.cpp in double precision: the far-field approximation
// against the direct sum — exact at θ = 0, within the stated error bound at the default θ,
// self and same-group exclusions honoured, deterministic, geometry reused and rebuilt as it
// should, and the SIMD and portable kernels in agreement. The single-precision parts are
// in barnes_hut_float_test.cpp.
#include "tests/magnetics/barnes_hut_helpers.hpp"

#include <catch2/catch.hpp>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

using namespace magsim::mag;
using namespace magsim::test::bh;

TEST_CASE("Barnes–Hut with θ = 0 is the direct sum (to 1e-12), field and Jacobian",
          "[barnes-hut]") {
  for (int layout = 0; layout < 3; ++layout) {
    const MomentSet s = layout == 0   ? magsim::test::sparse_cloud(600, 1)
                        : layout == 1 ? magsim::test::fcc_pile(600)
                                      : letters();
    FieldOptions o = bh_options(0.0);
    o.softening = layout == 2 ? 1e-3 : 0.0;
    const Errors e = bh_errors(s, o);
    INFO("layout " << layout << ": H max " << e.h_max << ", J max " << e.j_max);
    CHECK(e.h_max <= 1e-12);
    CHECK(e.j_max <= 1e-12);
  }
}

TEST_CASE("Barnes–Hut error bound at the default θ: random 3,000-moment cloud, dense pile",
          "[barnes-hut]") {
  // The bound stated in barnes_hut.hpp for the defaults (θ = 0.3, octupole order, leaves of
  // 64, groups of 32): relative field error RMS ≤ 1e-3, max ≤ 2e-2. Measured here: pile
  // RMS 2.6e-4, max 3.5e-3; cloud RMS 6.1e-5, max 2.7e-3.
  const FieldOptions o = bh_options(FieldOptions{}.bh_theta);
  const Errors c = bh_errors(magsim::test::sparse_cloud(3000, 2), o);
  INFO("cloud: H max " << c.h_max << " rms " << c.h_rms << "; J max " << c.j_max << " rms "
                       << c.j_rms);
  CHECK(c.h_rms <= 1e-3);
  CHECK(c.h_max <= 2e-2);
  const Errors p = bh_errors(magsim::test::fcc_pile(3000), o);
  INFO("pile: H max " << p.h_max << " rms " << p.h_rms << "; J max " << p.j_max << " rms "
                      << p.j_rms);
  CHECK(p.h_rms <= 1e-3);
  CHECK(p.h_max <= 2e-2);
  CHECK(c.j_rms <= 1e-3);
  CHECK(p.j_rms <= 1e-2);
}

TEST_CASE("Barnes–Hut error falls with θ, faster with the octupole-order term",
          "[barnes-hut]") {
  const MomentSet s = magsim::test::fcc_pile(2000);
  double prev[3] = {1, 1, 1};
  for (int order : {1, 2}) {
    double e[3];
    int k = 0;
    for (double theta : {0.6, 0.4, 0.2}) {
      FieldOptions o = bh_options(theta);
      o.bh_order = order;
      e[k++] = bh_errors(s, o).h_rms;
    }
    INFO("order " << order << ": RMS error at θ = 0.6, 0.4, 0.2: " << e[0] << " " << e[1]
                  << " " << e[2]);
    CHECK(e[1] < 0.6 * e[0]);
    CHECK(e[2] < 0.3 * e[1]);
    if (order == 2)
      for (int i = 0; i < 3; ++i) CHECK(e[i] < prev[i]);
    std::copy(e, e + 3, prev);
  }
}

TEST_CASE("Barnes–Hut honours self and same-group exclusions", "[barnes-hut]") {
  SECTION("letters: J leaves out the letter's own moments, H keeps them") {
    const MomentSet s = letters();
    for (double theta : {0.0, 0.3, 0.6}) {
      const Errors e = bh_errors(s, bh_options(theta));
      INFO("θ = " << theta << ": H rms " << e.h_rms << " max " << e.h_max << "; J rms "
                  << e.j_rms << " max " << e.j_max);
      CHECK(e.h_rms <= (theta == 0 ? 1e-13 : 1e-3));
      CHECK(e.j_rms <= (theta == 0 ? 1e-13 : 1e-2));
    }
  }
  SECTION("a far part of the target's own body never enters its J") {
    // body 7: a cluster at the origin and a huge far part 20 cm away (accepted as a cell);
    // free moments around both. If the far part leaked into J (even approximated), J would
    // be off by ~1e3 times the free moments' Jacobian.
    MomentSet s;
    std::mt19937 rng(9);
    std::normal_distribution<double> g;
    const double V = magsim::test::ball_volume(), Ms = magsim::test::kIronMs;
    for (int k = 0; k < 40; ++k) s.add_induced(0.01 * Vec3(g(rng), g(rng), g(rng)), V, Ms, 7);
    for (int k = 0; k < 40; ++k)
      s.add_permanent(Vec3(0.2, 0, 0) + 0.01 * Vec3(g(rng), g(rng), g(rng)), V, Vec3(0, 0, 5e4), 7);
    for (int k = 0; k < 200; ++k) {
      const int j = s.add_induced(0.1 * Vec3(g(rng), g(rng), g(rng)), V, Ms);
      s.set_magnetization(j, 0.4 * Ms * Vec3(g(rng), g(rng), g(rng)).normalized());
    }
    for (int k = 0; k < 40; ++k) s.set_magnetization(k, 0.4 * Ms * Vec3::UnitX());
    const Errors e = bh_errors(s, bh_options(0.5));
    INFO("H rms " << e.h_rms << "; J rms " << e.j_rms << " max " << e.j_max);
    CHECK(e.h_rms <= 1e-3);
    CHECK(e.j_max <= 1e-2);
  }
  SECTION("single-moment leaves and groups: a moment never feels itself") {
    // leaf and group size 1 on a lattice: a target's own one-moment cell has radius 0 and
    // sits on the group's sphere; it must stay near (exact, masked), never far (r = 0).
    // (cells of a few moments are poor multipoles: small θ keeps the error small)
    const MomentSet s = magsim::test::fcc_pile(500);
    for (int group : {1, 3}) {
      FieldOptions o = bh_options(0.15);
      o.bh_leaf_size = 1;
      o.bh_group_size = group;
      const Errors e = bh_errors(s, o);
      INFO("group size " << group << ": H max " << e.h_max << ", J max " << e.j_max);
      CHECK(std::isfinite(e.h_max));
      CHECK(std::isfinite(e.j_max));
      CHECK(e.h_rms <= 2e-3);
    }
  }
}

TEST_CASE("Barnes–Hut is deterministic: bitwise the same run to run and for 1 or 2 threads",
          "[barnes-hut]") {
  const MomentSet s = letters();
  const FieldOptions o = bh_options(0.4);
  auto run = [&](int threads) {
    const int saved = omp_get_max_threads();
    omp_set_num_threads(threads);
    FieldWorkspace ws;
    std::vector<Vec3> H;
    std::vector<Mat3> J;
    compute_fields(s, o, &H, &J, &ws);
    omp_set_num_threads(saved);
    return std::make_pair(H, J);
  };
  const auto a = run(1), b = run(2), c = run(2);
  CHECK(std::memcmp(a.first.data(), b.first.data(), a.first.size() * sizeof(Vec3)) == 0);
  CHECK(std::memcmp(a.second.data(), b.second.data(), a.second.size() * sizeof(Mat3)) == 0);
  CHECK(std::memcmp(b.first.data(), c.first.data(), b.first.size() * sizeof(Vec3)) == 0);
  // geometry cached by a 2-thread call, reused by a 1-thread call: the same bits
  MomentSet s2 = s;
  for (std::size_t j = 0; j < s2.size(); ++j)
    if (s2.M[j].squaredNorm() > 0) s2.set_magnetization(j, 0.7 * s2.M[j]);
  const int saved = omp_get_max_threads();
  FieldWorkspace ws;
  std::vector<Vec3> H1, H2;
  std::vector<Mat3> J1, J2;
  omp_set_num_threads(2);
  compute_fields(s, o, &H1, &J1, &ws);
  compute_fields(s2, o, &H2, &J2, &ws);  // reused, 2 threads
  omp_set_num_threads(1);
  compute_fields(s, o, &H1, &J1, &ws);  // reused, 1 thread
  omp_set_num_threads(saved);
  CHECK(barnes_hut_stats(ws).reused_lists);
  CHECK(std::memcmp(H1.data(), a.first.data(), H1.size() * sizeof(Vec3)) == 0);
  CHECK(std::memcmp(J1.data(), a.second.data(), J1.size() * sizeof(Mat3)) == 0);
}

namespace {

// The same positions and groups with other moments: every magnetization turned and scaled,
// some moments zeroed (and, with keep_zeros, the zero pattern of `s` kept).
MomentSet other_moments(const MomentSet& s, unsigned seed, bool keep_zeros) {
  MomentSet b = s;
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  for (std::size_t j = 0; j < b.size(); ++j) {
    if (b.kind[j] != MomentKind::Induced) continue;
    if (keep_zeros && b.M[j].squaredNorm() == 0) continue;
    const bool zero = !keep_zeros && j % 7 == 3;
    b.set_magnetization(j, zero ? Vec3::Zero().eval()
                                : Vec3(0.4 * b.Ms[j] * Vec3(g(rng), g(rng), g(rng)).normalized()));
  }
  return b;
}

}  // namespace

TEST_CASE("Barnes–Hut reuses its geometry when only the moments change, bitwise as fresh",
          "[barnes-hut]") {
  // A then B (other moments, same positions and groups) with one workspace, against B in a
  // fresh workspace: bitwise equal, for H alone and H with J, and the tree and lists reused.
  for (int layout = 0; layout < 2; ++layout) {
    const MomentSet a = layout == 0 ? letters() : magsim::test::fcc_pile(1500);
    for (bool keep_zeros : {true, false}) {
      const MomentSet b = other_moments(a, 5, keep_zeros);
      for (bool jac : {false, true}) {
        FieldOptions o = bh_options(0.4);
        o.softening = 5e-4;
        FieldWorkspace ws, fresh;
        std::vector<Vec3> Ha, Hb, Hf;
        std::vector<Mat3> Ja, Jb, Jf;
        compute_fields(a, o, &Ha, jac ? &Ja : nullptr, &ws);
        compute_fields(b, o, &Hb, jac ? &Jb : nullptr, &ws);
        const BarnesHutStats st = barnes_hut_stats(ws);
        compute_fields(b, o, &Hf, jac ? &Jf : nullptr, &fresh);
        INFO("layout " << layout << ", zeros kept " << keep_zeros << ", J " << jac);
        CHECK(st.reused_tree == keep_zeros);  // a new set of nonzero moments is a new tree
        CHECK(st.reused_lists == keep_zeros);
        CHECK(same_bits(Hb, Hf));
        if (jac) CHECK(same_bits(Jb, Jf));
        CHECK_FALSE(same_bits(Ha, Hb));  // the moments did change the field
        // and back to A: still what a fresh workspace gives
        compute_fields(a, o, &Hb, jac ? &Jb : nullptr, &ws);
        CHECK(same_bits(Hb, Ha));
        if (jac) CHECK(same_bits(Jb, Ja));
      }
    }
  }
}

TEST_CASE("Barnes–Hut rebuilds its geometry when positions, groups or options change",
          "[barnes-hut]") {
  const MomentSet a = letters();
  const FieldOptions o = bh_options(0.4);
  FieldWorkspace ws;
  std::vector<Vec3> H, Hf;
  std::vector<Mat3> J, Jf;
  compute_fields(a, o, &H, &J, &ws);
  compute_fields(a, o, &H, &J, &ws);
  CHECK(barnes_hut_stats(ws).reused_tree);
  CHECK(barnes_hut_stats(ws).reused_lists);
  auto check_fresh = [&](const MomentSet& s, const FieldOptions& opt, bool tree_reused) {
    compute_fields(s, opt, &H, &J, &ws);
    const BarnesHutStats st = barnes_hut_stats(ws);
    CHECK(st.reused_tree == tree_reused);
    CHECK_FALSE(st.reused_lists);
    FieldWorkspace fresh;
    compute_fields(s, opt, &Hf, &Jf, &fresh);
    CHECK(same_bits(H, Hf));
    CHECK(same_bits(J, Jf));
  };
  SECTION("one position moved by one ulp, then a real move") {
    MomentSet b = a;
    b.position[17].x() = std::nextafter(b.position[17].x(), 1.0);
    check_fresh(b, o, false);
    b.position[400] += Vec3(0.05, -0.02, 0.01);
    check_fresh(b, o, false);
  }
  SECTION("a group changed") {
    MomentSet b = a;
    b.group[3] = 159;
    check_fresh(b, o, false);
  }
  SECTION("θ changed: the tree stays, the lists are redone") {
    check_fresh(a, bh_options(0.3), true);
  }
  SECTION("leaf size changed") {
    FieldOptions p = o;
    p.bh_leaf_size = 16;
    check_fresh(a, p, false);
  }
  SECTION("a permanent moment's strength changed (it weights the expansion centres)") {
    MomentSet b = a;
    b.add_permanent(Vec3(0.2, 0.2, 0.45), 8e-6, Vec3(0, 0, -5.0));
    compute_fields(b, o, &H, &J, &ws);
    b.m_perm.back() *= 1.5;
    check_fresh(b, o, false);
  }
}

TEST_CASE("Barnes–Hut: one-moment bodies do not make J exact (same-group test)",
          "[barnes-hut]") {
  // Every ball its own rigid body (as the engine numbers them): J must cost what it costs
  // without groups (far cells keep their Jacobian), and the result is the same.
  MomentSet s = magsim::test::fcc_pile(3000);
  FieldOptions o = bh_options(FieldOptions{}.bh_theta);
  FieldWorkspace ws0, ws1;
  std::vector<Vec3> H0, H1;
  std::vector<Mat3> J0, J1;
  compute_fields(s, o, &H0, &J0, &ws0);
  const BarnesHutStats st0 = barnes_hut_stats(ws0);
  for (std::size_t j = 0; j < s.size(); ++j) s.group[j] = static_cast<std::int32_t>(j);
  compute_fields(s, o, &H1, &J1, &ws1);
  const BarnesHutStats st1 = barnes_hut_stats(ws1);
  INFO("near pairs per target without groups " << st0.near_pairs_per_target << ", with "
                                               << st1.near_pairs_per_target);
  CHECK(st1.near_pairs_per_target == st0.near_pairs_per_target);
  CHECK(st1.far_cells_per_target == st0.far_cells_per_target);
  CHECK(same_bits(H0, H1));
  CHECK(same_bits(J0, J1));
}

TEST_CASE("Barnes–Hut: the AVX-512 and the portable far-cell kernels give the same bits", "[barnes-hut]") {
  const MomentSet s = magsim::test::sparse_cloud(800, 4);
  FieldOptions o = bh_options(0.5);
  o.softening = 5e-4;
  o.bh_near_float = false;  // the near field in double
  const Errors e = simd_vs_portable(s, o);
  INFO("SIMD vs portable: H max " << e.h_max << ", J max " << e.j_max);
  CHECK(e.h_max == 0.0);
  CHECK(e.j_max == 0.0);
}

TEST_CASE("Auto picks Barnes–Hut from auto_threshold moments on", "[barnes-hut]") {
  FieldOptions o;
  o.solver = FieldSolver::Auto;
  o.auto_threshold = 1000;
  CHECK(resolve_solver(o, 999) == FieldSolver::Direct);
  CHECK(resolve_solver(o, 1000) == FieldSolver::BarnesHut);
  o.solver = FieldSolver::Direct;
  CHECK(resolve_solver(o, 100000) == FieldSolver::Direct);
  FieldSolver f;
  CHECK(parse_field_solver("barnes-hut", &f));
  CHECK(f == FieldSolver::BarnesHut);
  CHECK_FALSE(parse_field_solver("fmm", &f));
  CHECK(validate(FieldOptions{}).empty());
  o.bh_theta = 1.5;
  CHECK_FALSE(validate(o).empty());
}
