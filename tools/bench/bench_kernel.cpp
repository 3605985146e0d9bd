// tools/bench/bench_kernel.cpp — speed (and, for Barnes–Hut, accuracy) of the dipole-field
// kernel of magnetics/dipole_field.cpp: pair evaluations per second of the direct sum (field
// only, and field + Jacobian), single- and multi-threaded, and the Barnes–Hut approximation
// (magnetics/barnes_hut.cpp) at several opening angles θ: time, speed-up over the direct sum,
// effective pairs/s = N²/time, and its relative field (and Jacobian) error against the
// direct sum (max over targets of |ΔH_j|/|H_j|, and RMS = √(Σ|ΔH_j|²/Σ|H_j|²)). Medians over
// repeats (wall clock). Above --full-max moments the direct sum is timed on --sample evenly
// spaced targets and extrapolated to all N (printed as "sampled"), and Barnes–Hut is checked
// on those targets. Never a pass/fail test: timings depend on the machine and its load.
//
// Barnes–Hut is timed twice: "fresh" (the octree and interaction lists built for the call,
// as after the bodies moved) and "reused" (the same positions with other moments, as the
// magnetization solvers call it 5–35 times per step: only the multipoles are redone).
// --bh-near picks its near field: "double", "float" (FieldOptions::bh_near_float, the
// default) or "both" (the default here: each θ run with both, and the float one also
// reports its speed-up over the double one and its difference from it, "near_f32_vs_f64_*":
// max and RMS relative over every target, as the errors above). --bh-far likewise picks
// the far cells' precision with the float near field (FieldOptions::bh_far_float): "double",
// "float" or "both" (the default: the float-far run also reports its speed-up over, and its
// difference from, the double-far one with the same float near field, "far_f32_vs_f64_*").
// The double near field always runs with double far cells (bh_near_float = false is the
// all-double sum).
//
// Moments: iron balls (radius 4 mm, Ms = 1.6 MA/m) in three layouts — "pile", a packed heap
// (an FCC packing of touching balls filled layer by layer on a square footprint, about three
// times as wide as high, like the scenes' piles), "cloud", a uniform random cloud at 5 %
// volume fraction, and "sheet", a square grid of balls in one horizontal plane, spacing 2.05
// radii (sakura_tree's falling sheet, or a carpet on the ground). With --groups ball every
// ball is its own rigid body (group id = its index, as the engine numbers bodies), else no
// moment has a group. Magnetized as a scene would be (--moments scene, the default: a strong
// magnet above the middle, each ball at f(H_magnet + H0)) or independently at random
// (--moments random, the hard case for multipoles).
#include "magnetics/barnes_hut.hpp"
#include "magnetics/curves.hpp"
#include "magnetics/dipole_field.hpp"
#include "magnetics/field_kernel.hpp"
#include "magnetics/fields.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <random>
#include <unordered_map>

namespace mag = magsim::mag;
using mag::Mat3;
using mag::Vec3;
using nlohmann::json;

namespace {

constexpr double kRadius = 4e-3;  // m
constexpr double kMs = 1.6e6;     // A/m (iron)
double ball_volume() { return 4.0 / 3.0 * mag::kPi * kRadius * kRadius * kRadius; }

// "scene": a strong permanent magnet (a 2 cm cube of NdFeB, m = 1.2e6 A/m × 8e-6 m³) sits
// 2 cm above the middle of the top; each ball takes M = f(H_magnet + H0) (eq. 10, the first
// sweep of a solve) with a weak uniform H0 = 0.01 Ms ẑ, times a ±10 % per-ball jitter — smooth
// like a relaxed scene. "random": |M| ∈ [0.05, 0.6] Ms uniform, directions within ~35° of z,
// independently per ball, no magnet — the hard case for any multipole expansion.
void magnetize(mag::MomentSet* s, std::mt19937* rng, bool scene) {
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> x(0.05, 0.6), jit(0.9, 1.1);
  if (!scene) {
    for (std::size_t j = 0; j < s->size(); ++j) {
      const Vec3 u = (Vec3::UnitZ() + 0.6 * Vec3(g(*rng), g(*rng), g(*rng))).normalized();
      s->set_magnetization(j, x(*rng) * kMs * u);
    }
    return;
  }
  Vec3 lo = s->position[0], hi = lo;
  for (const Vec3& p : s->position) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Vec3 pm(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), hi.z() + 0.02);
  const Vec3 mm(0, 0, -1.2e6 * 8e-6);
  const Vec3 H0(0, 0, 0.01 * kMs);
  const std::size_t n = s->size();
  for (std::size_t j = 0; j < n; ++j) {
    const Vec3 H = H0 + mag::dipole_field(s->position[j] - pm, mm);
    s->set_magnetization(j, jit(*rng) * mag::curve_M(mag::Curve::Tanh, H, kMs));
  }
  s->add_permanent(pm, 8e-6, mm);
  s->H0 = H0;
}

// FCC lattice of touching balls, filled layer by layer over a square footprint.
mag::MomentSet pile(int n, unsigned seed, bool scene) {
  const double d = 2.0 * kRadius * 1.001;  // nearest-neighbour distance
  const double a = d * std::sqrt(2.0);     // cubic cell
  // footprint side W with height ≈ W/3 at packing fraction 0.74
  const double W = std::cbrt(3.0 * n * ball_volume() / 0.74);
  const int nxy = static_cast<int>(std::ceil(W / a));
  std::vector<Vec3> pts;
  for (int k = 0; static_cast<int>(pts.size()) < n; ++k) {
    // one cubic layer at a time (two atomic layers), sorted by height
    std::vector<Vec3> layer;
    for (int i = 0; i < nxy; ++i)
      for (int j = 0; j < nxy; ++j) {
        const Vec3 o(i * a, j * a, k * a);
        for (const Vec3& b : {Vec3(0, 0, 0), Vec3(0.5, 0.5, 0), Vec3(0.5, 0, 0.5), Vec3(0, 0.5, 0.5)})
          layer.push_back(o + a * b);
      }
    std::stable_sort(layer.begin(), layer.end(),
                     [](const Vec3& p, const Vec3& q) { return p.z() < q.z(); });
    for (const Vec3& p : layer)
      if (static_cast<int>(pts.size()) < n) pts.push_back(p);
  }
  mag::MomentSet s;
  for (const Vec3& p : pts) s.add_induced(p, ball_volume(), kMs);
  std::mt19937 rng(seed);
  magnetize(&s, &rng, scene);
  return s;
}

// A square grid of balls in the plane z = 0, spacing 2.05 radii, filled row by row.
mag::MomentSet sheet(int n, unsigned seed, bool scene) {
  const double d = 2.05 * kRadius;
  const int nx = static_cast<int>(std::ceil(std::sqrt(double(n))));
  mag::MomentSet s;
  for (int k = 0; k < n; ++k) s.add_induced(Vec3((k % nx) * d, (k / nx) * d, 0.0), ball_volume(), kMs);
  std::mt19937 rng(seed);
  magnetize(&s, &rng, scene);
  return s;
}

// The same positions and groups with every moment changed (|M| scaled by 0.9…1.1 per
// moment, zero moments stay zero): what a magnetization solver's next sweep hands over.
mag::MomentSet other_moments(const mag::MomentSet& a, unsigned seed) {
  mag::MomentSet b = a;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> f(0.9, 1.1);
  for (std::size_t j = 0; j < b.size(); ++j)
    if (b.kind[j] == mag::MomentKind::Induced) {
      const Vec3 M = f(rng) * b.M[j];
      b.set_magnetization(j, M.norm() > b.Ms[j] ? Vec3(b.M[j]) : M);
    }
  return b;
}

// Uniform random balls at 5 % volume fraction, no two overlapping (grid-hashed rejection).
mag::MomentSet cloud(int n, unsigned seed, bool scene) {
  const double L = std::cbrt(n * ball_volume() / 0.05);
  const double cell = 2.0 * kRadius;
  const int nc = std::max(1, static_cast<int>(L / cell));
  std::unordered_map<long, std::vector<int>> grid;
  auto key = [&](int i, int j, int k) { return (static_cast<long>(i) * nc + j) * nc + k; };
  auto cell_of = [&](double v) { return std::clamp(static_cast<int>(v / L * nc), 0, nc - 1); };
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, L);
  std::vector<Vec3> pts;
  while (static_cast<int>(pts.size()) < n) {
    const Vec3 p(u(rng), u(rng), u(rng));
    const int ci = cell_of(p.x()), cj = cell_of(p.y()), ck = cell_of(p.z());
    bool ok = true;
    for (int di = -1; di <= 1 && ok; ++di)
      for (int dj = -1; dj <= 1 && ok; ++dj)
        for (int dk = -1; dk <= 1 && ok; ++dk) {
          auto it = grid.find(key(ci + di, cj + dj, ck + dk));
          if (it == grid.end()) continue;
          for (int q : it->second) ok = ok && (pts[q] - p).norm() >= 2.0 * kRadius;
        }
    if (!ok) continue;
    grid[key(ci, cj, ck)].push_back(static_cast<int>(pts.size()));
    pts.push_back(p);
  }
  mag::MomentSet s;
  for (const Vec3& p : pts) s.add_induced(p, ball_volume(), kMs);
  magnetize(&s, &rng, scene);
  return s;
}

bool g_use_min = false;  // --stat min: the fastest repeat instead of the median
bool g_cpu_clock = false;  // --clock cpu: process CPU time instead of wall time

double now_s() {
  if (g_cpu_clock) {
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

template <class F>
double median_seconds(int repeat, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < repeat; ++r) {
    const double t0 = now_s();
    f();
    t.push_back(now_s() - t0);
  }
  std::sort(t.begin(), t.end());
  return g_use_min ? t.front() : t[t.size() / 2];
}

struct Errors {
  double h_max = 0, h_rms = 0, j_max = 0, j_rms = 0;
};

// max_j |ΔH_j|/|H_j| and √(Σ|ΔH_j|² / Σ|H_j|²) over the sampled targets (and for J, Frobenius)
Errors errors(const std::vector<int>& sample, const std::vector<Vec3>& H, const std::vector<Mat3>* J,
              const std::vector<Vec3>& Href, const std::vector<Mat3>* Jref) {
  Errors e;
  double hn = 0, hd = 0, jn = 0, jd = 0;
  for (std::size_t k = 0; k < sample.size(); ++k) {
    const int i = sample[k];
    const double dh = (H[i] - Href[k]).norm(), rh = Href[k].norm();
    e.h_max = std::max(e.h_max, rh > 0 ? dh / rh : dh);
    hn += dh * dh;
    hd += rh * rh;
    if (J && Jref) {
      const double dj = ((*J)[i] - (*Jref)[k]).norm(), rj = (*Jref)[k].norm();
      e.j_max = std::max(e.j_max, rj > 0 ? dj / rj : dj);
      jn += dj * dj;
      jd += rj * rj;
    }
  }
  e.h_rms = hd > 0 ? std::sqrt(hn / hd) : 0;
  e.j_rms = jd > 0 ? std::sqrt(jn / jd) : 0;
  return e;
}

std::vector<int> sample_targets(int n, int k) {
  std::vector<int> s;
  if (k >= n) {
    for (int i = 0; i < n; ++i) s.push_back(i);
    return s;
  }
  for (int i = 0; i < k; ++i) s.push_back(static_cast<int>((static_cast<long>(i) * n) / k));
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench_kernel — pair evaluations per second of the dipole-field kernel, and "
               "Barnes–Hut speed and accuracy against the direct sum"};
  std::vector<int> sizes{1000, 2500, 10000, 100000};
  std::vector<int> threads{1, 2};
  std::vector<double> thetas{0.3, 0.5, 0.7};
  std::vector<std::string> layouts{"pile", "cloud"};
  std::string json_path, moments = "scene", groups = "none";
  int repeat = 3, sample = 2048, full_max = 20000, leaf = 64, group = 32, order = 2;
  bool portable = false, no_bh = false;
  std::string bh_near = "both", bh_far = "both";
  app.add_option("--sizes", sizes, "numbers of moments")->delimiter(',');
  app.add_option("--threads", threads, "thread counts")->delimiter(',');
  app.add_option("--theta", thetas, "Barnes–Hut opening angles θ")->delimiter(',');
  app.add_option("--layouts", layouts, "pile, cloud, sheet")->delimiter(',');
  app.add_option("--groups", groups, "none (no moment has a group, the default) or ball "
                 "(every ball its own rigid body, as in the engine)")
      ->check(CLI::IsMember({"none", "ball"}));
  app.add_option("--moments", moments, "scene (smooth, a magnet above) or random")
      ->check(CLI::IsMember({"scene", "random"}));
  app.add_option("--json", json_path, "write the results as JSON to this file");
  app.add_option("--repeat", repeat, "timed repeats per figure (median reported)")->check(CLI::PositiveNumber);
  app.add_option("--sample", sample,
                 "above --full-max moments the direct sum is timed (and Barnes–Hut checked) "
                 "on this many evenly spaced targets and extrapolated to all")->check(CLI::PositiveNumber);
  app.add_option("--full-max", full_max, "largest size evaluated at every target by the direct sum");
  app.add_option("--leaf", leaf, "Barnes–Hut leaf size")->check(CLI::PositiveNumber);
  app.add_option("--group", group, "Barnes–Hut target group size")->check(CLI::PositiveNumber);
  app.add_option("--order", order, "Barnes–Hut expansion order (1: quadrupole, 2: octupole)")
      ->check(CLI::Range(1, 2));
  std::string stat = "median", clock = "wall";
  app.add_option("--clock", clock, "wall (default) or cpu: process CPU time, steadier on a "
                 "busy machine but the sum over threads")->check(CLI::IsMember({"wall", "cpu"}));
  app.add_option("--stat", stat, "median (default) or min over the repeats (min is steadier "
                 "on a shared machine)")->check(CLI::IsMember({"median", "min"}));
  app.add_flag("--portable", portable, "also time the portable (non-AVX-512) direct loop");
  app.add_flag("--no-bh", no_bh, "direct sum only");
  app.add_option("--bh-near", bh_near, "Barnes–Hut near field in float, double, or both "
                 "(the default: both timed, float compared with double)")
      ->check(CLI::IsMember({"float", "double", "both"}));
  app.add_option("--bh-far", bh_far, "Barnes–Hut far cells (with the float near field) in "
                 "float, double, or both (the default: both timed, float compared with double)")
      ->check(CLI::IsMember({"float", "double", "both"}));
  CLI11_PARSE(app, argc, argv);
  g_use_min = stat == "min";
  g_cpu_clock = clock == "cpu";

  json out;
  out["simd_kernel"] = mag::detail::simd_kernel_active();
  out["kernel_path"] = mag::detail::kernel_path_name(mag::detail::kernel_path());
  out["repeat"] = repeat;
  out["stat"] = stat;
  out["clock"] = clock;
  out["moments"] = moments;
  out["groups"] = groups;
  out["bh_near"] = bh_near;
  out["bh_far"] = bh_far;
  out["results"] = json::array();
  std::printf("# AVX-512 kernel: %s (path %s); %s of %d repeats; pairs/s = targets × sources / time\n",
              mag::detail::simd_kernel_active() ? "yes" : "no",
              mag::detail::kernel_path_name(mag::detail::kernel_path()), g_use_min ? "min" : "median", repeat);
  for (const std::string& layout : layouts) {
    if (layout != "pile" && layout != "cloud" && layout != "sheet") {
      std::fprintf(stderr, "unknown layout %s (pile, cloud, sheet)\n", layout.c_str());
      return 2;
    }
    for (int n : sizes) {
      const bool scene = moments == "scene";
      mag::MomentSet set = layout == "pile"    ? pile(n, 7, scene)
                           : layout == "sheet" ? sheet(n, 7, scene)
                                               : cloud(n, 7, scene);
      if (groups == "ball")
        for (std::size_t j = 0; j < set.size(); ++j) set.group[j] = static_cast<std::int32_t>(j);
      const mag::MomentSet set_b = other_moments(set, 11);
      const bool sampled = n > full_max;
      const std::vector<int> tgt = sample_targets(n, sampled ? sample : n);
      const double frac = double(tgt.size()) / n;  // sampled share of the targets
      mag::FieldOptions direct;
      direct.solver = mag::FieldSolver::Direct;  // (the default is Auto)
      mag::FieldWorkspace ws;
      // reference: the direct sum at the sampled targets
      std::vector<Vec3> Href, H;
      std::vector<Mat3> Jref, J;
      mag::compute_fields_at(set, direct, tgt, &Href, &Jref, &ws);
      for (int nt : threads) {
        omp_set_num_threads(nt);
        json rec;
        rec["layout"] = layout;
        rec["n"] = n;
        rec["threads"] = nt;
        rec["direct_sampled_targets"] = sampled ? static_cast<int>(tgt.size()) : 0;
        auto time_direct = [&](bool jac) {
          const double t = median_seconds(repeat, [&] {
            if (sampled) mag::compute_fields_at(set, direct, tgt, &H, jac ? &J : nullptr, &ws);
            else mag::compute_fields(set, direct, &H, jac ? &J : nullptr, &ws);
          });
          return t / frac;  // extrapolated to every target
        };
        const double pairs = double(n) * double(n);
        const double td_h = time_direct(false), td_hj = time_direct(true);
        rec["direct"] = {{"time_H_s", td_h}, {"time_HJ_s", td_hj},
                         {"pairs_per_s_H", pairs / td_h}, {"pairs_per_s_HJ", pairs / td_hj}};
        std::printf("%-5s n=%6d threads=%d direct%s: H %9.3f ms %.3g pairs/s | H+J %9.3f ms %.3g pairs/s\n",
                    layout.c_str(), n, nt, sampled ? " (sampled, extrapolated)" : "",
                    td_h * 1e3, pairs / td_h, td_hj * 1e3, pairs / td_hj);
        if (portable) {
          mag::detail::enable_simd_kernel(false);
          const double tp_h = time_direct(false), tp_hj = time_direct(true);
          mag::detail::enable_simd_kernel(true);
          rec["portable"] = {{"time_H_s", tp_h}, {"time_HJ_s", tp_hj},
                             {"pairs_per_s_H", pairs / tp_h}, {"pairs_per_s_HJ", pairs / tp_hj}};
          std::printf("%-5s n=%6d threads=%d portable: H %9.3f ms %.3g pairs/s | H+J %9.3f ms %.3g pairs/s\n",
                      layout.c_str(), n, nt, tp_h * 1e3, pairs / tp_h, tp_hj * 1e3, pairs / tp_hj);
        }
        if (!no_bh && bh_near == "both") {
          // the near-field pair kernel alone, as Barnes–Hut runs it: 32 targets against the
          // first 2,048 moments, double (sum_pairs) against float (sum_pairs_f32, positions
          // relative to the sources' centroid)
          const int ns = std::min(n, 2048), nt32 = std::min(ns, 32);
          mag::detail::SourceBuffer sd;
          Vec3 c = Vec3::Zero();
          for (int k = 0; k < ns; ++k) c += set.position[k] / ns;
          std::vector<float> f[6];
          std::vector<std::int32_t> fid, fgrp;
          for (int k = 0; k < ns || sd.size() % mag::detail::kSourcePad != 0 ||
                          fid.size() % mag::detail::kSourcePadF != 0; ++k) {
            const bool real = k < ns;
            const Vec3 p = real ? set.position[k] : Vec3::Constant(mag::detail::kPadPosition);
            const Vec3 m = real ? set.moment(k) : Vec3::Zero();
            const int g = real ? set.group[k] : -1;
            if (real || sd.size() % mag::detail::kSourcePad != 0)
              sd.push(p.x(), p.y(), p.z(), m.x(), m.y(), m.z(), real ? k : -1, g);
            if (real || fid.size() % mag::detail::kSourcePadF != 0) {
              const Vec3 r = real ? Vec3(p - c) : Vec3::Constant(mag::detail::kPadPositionF);
              for (int a = 0; a < 3; ++a) f[a].push_back(static_cast<float>(r[a]));
              for (int a = 0; a < 3; ++a) f[3 + a].push_back(static_cast<float>(m[a]));
              fid.push_back(real ? k : -1);
              fgrp.push_back(g < 0 ? -1 : g);
            }
          }
          const mag::detail::SourceView vd{sd.x.data(), sd.y.data(), sd.z.data(), sd.mx.data(),
                                           sd.my.data(), sd.mz.data(), sd.id.data(), sd.grp.data(),
                                           sd.size(), nullptr};
          const mag::detail::SourceViewF vf{f[0].data(), f[1].data(), f[2].data(), f[3].data(),
                                            f[4].data(), f[5].data(), fid.data(), fgrp.data(),
                                            fid.size(), nullptr};
          double sink = 0;
          auto kernel = [&](bool fl, bool jac) {
            const auto terms = jac ? mag::detail::PairTerms::HJ : mag::detail::PairTerms::H;
            return median_seconds(repeat, [&] {
              for (int rep = 0; rep < 20; ++rep)
                for (int k = 0; k < nt32; ++k) {
                  double h[3] = {0, 0, 0}, jj[6] = {0, 0, 0, 0, 0, 0};
                  const Vec3& p = set.position[k];
                  const double g = set.group[k] >= 0 ? set.group[k] : std::nan("");
                  if (fl) {
                    const Vec3 r = p - c;
                    const mag::detail::TargetF t{float(r.x()), float(r.y()), float(r.z()), k,
                                                 set.group[k] >= 0 ? set.group[k] : mag::detail::kNoGroupF, 0.0f};
                    mag::detail::sum_pairs_f32(vf, t, 0.0f, terms, h, jj);
                  } else {
                    const mag::detail::Target t{p.x(), p.y(), p.z(), double(k), g, 0.0};
                    mag::detail::sum_pairs(vd, t, 0.0, terms, h, jj);
                  }
                  sink += h[0] + jj[0];
                }
            });
          };
          const double kp = 20.0 * nt32 * ns;  // pairs per timed call
          const double kd_h = kernel(false, false), kd_hj = kernel(false, true);
          const double kf_h = kernel(true, false), kf_hj = kernel(true, true);
          rec["near_kernel"] = {{"sources", ns}, {"pairs_per_s_H_double", kp / kd_h},
                                {"pairs_per_s_HJ_double", kp / kd_hj},
                                {"pairs_per_s_H_float", kp / kf_h},
                                {"pairs_per_s_HJ_float", kp / kf_hj},
                                {"speedup_H", kd_h / kf_h}, {"speedup_HJ", kd_hj / kf_hj}};
          std::printf("%-5s n=%6d threads=%d near kernel alone (%d sources): H %.3g → %.3g pairs/s "
                      "(×%.2f) | H+J %.3g → %.3g pairs/s (×%.2f) (double → float)%s\n",
                      layout.c_str(), n, nt, ns, kp / kd_h, kp / kf_h, kd_h / kf_h, kp / kd_hj,
                      kp / kf_hj, kd_hj / kf_hj, std::isfinite(sink) ? "" : " (non-finite!)");
        }
        rec["barnes_hut"] = json::array();
        // (bh_near_float, bh_far_float); the far cells in float only with the near field
        std::vector<std::pair<bool, bool>> modes;
        if (bh_near != "float") modes.emplace_back(false, false);
        if (bh_near != "double") {
          if (bh_far != "float") modes.emplace_back(true, false);
          if (bh_far != "double") modes.emplace_back(true, true);
        }
        for (double theta : no_bh ? std::vector<double>{} : thetas) {
         // the double-near run of this θ (for the float one's comparison)
         double tdn_h = 0, tdn_hj = 0, tdn_rh = 0, tdn_rhj = 0;
         std::vector<Vec3> Hdn;
         std::vector<Mat3> Jdn;
         // the float-near, double-far run (for the float-far one's comparison)
         double tdf_h = 0, tdf_hj = 0, tdf_rh = 0, tdf_rhj = 0;
         std::vector<Vec3> Hdf;
         std::vector<Mat3> Jdf;
         for (const auto& [near_float, far_float] : modes) {
          mag::FieldOptions bh;
          bh.solver = mag::FieldSolver::BarnesHut;
          bh.bh_theta = theta;
          bh.bh_leaf_size = leaf;
          bh.bh_group_size = group;
          bh.bh_order = order;
          bh.bh_near_float = near_float;
          bh.bh_far_float = far_float;
          // fresh: the geometry forgotten before every call (tree and lists built)
          auto fresh = [&](bool jac) {
            mag::barnes_hut_forget_geometry(&ws);
            mag::compute_fields(set, bh, &H, jac ? &J : nullptr, &ws);
          };
          const double tb_h = median_seconds(repeat, [&] { fresh(false); });
          const Errors eh = errors(tgt, H, nullptr, Href, nullptr);
          const double tb_hj = median_seconds(repeat, [&] { fresh(true); });
          const Errors ej = errors(tgt, H, &J, Href, &Jref);
          const mag::BarnesHutStats st = mag::barnes_hut_stats(ws);
          // float near field against double near field (the same far field), every target
          json near_cmp = json::object();
          std::string near_txt;
          if (!near_float) {
            Hdn = H;
            Jdn = J;
          } else if (!far_float) {
            Hdf = H;
            Jdf = J;
          }
          if (far_float && !Hdf.empty()) {
            // float far cells against double ones (the same float near field), every target
            const Errors d = errors(sample_targets(n, n), H, &J, Hdf, &Jdf);
            near_cmp = {{"far_f32_vs_f64_H_max", d.h_max}, {"far_f32_vs_f64_H_rms", d.h_rms},
                        {"far_f32_vs_f64_J_max", d.j_max}, {"far_f32_vs_f64_J_rms", d.j_rms}};
            char buf[200];
            std::snprintf(buf, sizeof buf, " | float vs double far: H rms %.2e max %.2e, J rms %.2e max %.2e",
                          d.h_rms, d.h_max, d.j_rms, d.j_max);
            near_txt = buf;
          } else if (near_float && !far_float && !Hdn.empty()) {
            const Errors d = errors(sample_targets(n, n), H, &J, Hdn, &Jdn);
            near_cmp = {{"near_f32_vs_f64_H_max", d.h_max}, {"near_f32_vs_f64_H_rms", d.h_rms},
                        {"near_f32_vs_f64_J_max", d.j_max}, {"near_f32_vs_f64_J_rms", d.j_rms}};
            char buf[200];
            std::snprintf(buf, sizeof buf, " | float vs double near: H rms %.2e max %.2e, J rms %.2e max %.2e",
                          d.h_rms, d.h_max, d.j_rms, d.j_max);
            near_txt = buf;
          }
          // reused: the same positions, the moments alternating between two sets
          auto time_reused = [&](bool jac) {
            int k = 0;
            mag::compute_fields(set, bh, &H, jac ? &J : nullptr, &ws);
            return median_seconds(repeat, [&] {
              mag::compute_fields(++k % 2 ? set_b : set, bh, &H, jac ? &J : nullptr, &ws);
            });
          };
          const double tr_h = time_reused(false), tr_hj = time_reused(true);
          const mag::BarnesHutStats st_r = mag::barnes_hut_stats(ws);
          // reuse gives bitwise what a fresh evaluation gives
          std::vector<Vec3> Hr, Hf;
          std::vector<Mat3> Jr, Jf;
          mag::compute_fields(set, bh, &Hr, &Jr, &ws);
          mag::compute_fields(set_b, bh, &Hr, &Jr, &ws);
          mag::barnes_hut_forget_geometry(&ws);
          mag::compute_fields(set_b, bh, &Hf, &Jf, &ws);
          const bool same = std::memcmp(Hr.data(), Hf.data(), Hr.size() * sizeof(Vec3)) == 0 &&
                            std::memcmp(Jr.data(), Jf.data(), Jr.size() * sizeof(Mat3)) == 0;
          json bhrec = {{"theta", theta}, {"leaf", leaf}, {"group", group}, {"order", order},
                                       {"bh_near", near_float ? "float" : "double"},
                                       {"bh_far", far_float ? "float" : "double"},
                                       {"time_H_s", tb_h}, {"time_HJ_s", tb_hj},
                                       {"speedup_H", td_h / tb_h}, {"speedup_HJ", td_hj / tb_hj},
                                       {"eff_pairs_per_s_H", pairs / tb_h},
                                       {"eff_pairs_per_s_HJ", pairs / tb_hj},
                                       {"H_err_max", eh.h_max}, {"H_err_rms", eh.h_rms},
                                       {"J_err_max", ej.j_max}, {"J_err_rms", ej.j_rms},
                                       {"near_pairs_per_target", st.near_pairs_per_target},
                                       {"far_cells_per_target", st.far_cells_per_target},
                                       {"build_s", st.build_s}, {"lists_s", st.lists_s},
                                       {"eval_s", st.eval_s},
                                       {"time_H_reused_s", tr_h}, {"time_HJ_reused_s", tr_hj},
                                       {"speedup_H_reused", td_h / tr_h},
                                       {"speedup_HJ_reused", td_hj / tr_hj},
                                       {"reused_build_s", st_r.build_s},
                                       {"reused_eval_s", st_r.eval_s},
                                       {"reuse_bitwise_identical", same}};
          if (!near_float) {
            tdn_h = tb_h; tdn_hj = tb_hj; tdn_rh = tr_h; tdn_rhj = tr_hj;
          } else if (!far_float) {
            tdf_h = tb_h; tdf_hj = tb_hj; tdf_rh = tr_h; tdf_rhj = tr_hj;
          }
          // speed-ups of the float part over the double one (fresh and reused): the far
          // cells (float near field in both), or else the near field (far cells in double)
          auto speedup = [&](const char* part, double h, double hj, double rh, double rhj) {
            const std::string k = std::string(part) + "_f32_speedup_";
            bhrec[k + "H"] = h / tb_h;
            bhrec[k + "HJ"] = hj / tb_hj;
            bhrec[k + "H_reused"] = rh / tr_h;
            bhrec[k + "HJ_reused"] = rhj / tr_hj;
            char buf[160];
            std::snprintf(buf, sizeof buf, " | float/double %s speed-up: fresh H ×%.2f H+J ×%.2f, reused H ×%.2f H+J ×%.2f",
                          part, h / tb_h, hj / tb_hj, rh / tr_h, rhj / tr_hj);
            near_txt += buf;
          };
          if (far_float && tdf_h > 0) speedup("far", tdf_h, tdf_hj, tdf_rh, tdf_rhj);
          else if (near_float && !far_float && tdn_h > 0) speedup("near", tdn_h, tdn_hj, tdn_rh, tdn_rhj);
          bhrec.update(near_cmp);
          rec["barnes_hut"].push_back(bhrec);
          std::printf("%-5s n=%6d threads=%d BH θ=%.2f %s near %s far: H %8.3f ms (×%5.1f, %.3g eff. pairs/s) "
                      "err max %.2e rms %.2e | H+J %8.3f ms (×%5.1f) J err max %.2e rms %.2e "
                      "| near %.0f far %.0f per target | build %.2f lists %.2f eval %.2f ms "
                      "| reused: H %8.3f ms (×%5.1f) H+J %8.3f ms (×%5.1f)%s%s\n",
                      layout.c_str(), n, nt, theta, near_float ? "float " : "double",
                      far_float ? "float " : "double", tb_h * 1e3, td_h / tb_h, pairs / tb_h, eh.h_max,
                      eh.h_rms, tb_hj * 1e3, td_hj / tb_hj, ej.j_max, ej.j_rms,
                      st.near_pairs_per_target, st.far_cells_per_target, st.build_s * 1e3,
                      st.lists_s * 1e3, st.eval_s * 1e3, tr_h * 1e3, td_h / tr_h, tr_hj * 1e3,
                      td_hj / tr_hj, same ? "" : " NOT BITWISE AS FRESH", near_txt.c_str());
         }
        }
        std::fflush(stdout);
        out["results"].push_back(rec);
      }
    }
  }
  if (!json_path.empty()) {
    const std::filesystem::path p(json_path);
    if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
    std::ofstream f(json_path);
    if (!f) {
      std::fprintf(stderr, "cannot write %s\n", json_path.c_str());
      return 1;
    }
    f << out.dump(2) << "\n";
    std::printf("# wrote %s\n", json_path.c_str());
  }
  return 0;
}
