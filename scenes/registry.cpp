// scenes/registry.cpp — the five scenes as data (the paper's four and crystal_balls). Sizes and strengths are ours
// (the paper gives only counts); each is stated beside its value, in SI units.
#include "scenes/registry.hpp"
#include "magnetics/det_math.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace magsim::scenes {

using engine::BodyDesc;
using engine::BodyType;
using engine::MomentDesc;
using engine::SceneDesc;
using engine::ShapeDesc;
using engine::ShapeKind;
using engine::Vec3;
using engine::Quat;

namespace {

using mag::kPi;  // magnetics/types.hpp
constexpr double kIronMs = 1.6e6;        // saturation magnetization of iron (A/m)
constexpr double kIronDensity = 7870.0;  // (kg/m³)
// magnetization of an N52 neodymium magnet, Br ≈ 1.43 T (A/m): a cube of side s carries
// 1.1e6 · s³ A·m², a sphere of radius R 1.1e6 · 4/3 π R³
constexpr double kN52M = 1.1e6;
// rolling resistance ρ = c_rr · r of balls on the ground and the tree (falling_magnet states
// the measurements that chose it), and in sakura_tree of a ball on a ball
constexpr double kRollingCoefficient = 0.2;
const render::Color kIron{0.55f, 0.56f, 0.58f};
const render::Color kMagnetRed{0.80f, 0.12f, 0.12f};

double sphere_volume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

/// A permanent moment m (A·m², body frame) standing for `volume` of magnet, at `offset`.
MomentDesc permanent_moment(double volume, const Vec3& m, const Vec3& offset = Vec3::Zero()) {
  MomentDesc d;
  d.permanent = true;
  d.offset = offset;
  d.volume = volume;
  d.moment = m;
  return d;
}

/// A magnet body: one shape (at its origin), the given permanent moments, coloured as a
/// magnet and counted as "the magnet" by the attachment metrics.
BodyDesc magnet_body(const std::string& name, BodyType type, const Vec3& p, ShapeKind kind,
                     const Vec3& size, std::vector<MomentDesc> moments) {
  BodyDesc b;
  b.name = name;
  b.type = type;
  b.magnet = true;
  b.position = p;
  b.shapes.push_back({kind, Vec3::Zero(), Quat::Identity(), size});
  b.moments = std::move(moments);
  b.color = kMagnetRed;
  return b;
}

/// An iron ball: one sphere, one induced moment at its centre (modelling level: 1 moment).
BodyDesc iron_ball(const std::string& name, const Vec3& p, double r) {
  BodyDesc b;
  b.name = name;
  b.position = p;
  b.density = kIronDensity;
  b.shapes.push_back({ShapeKind::Sphere, Vec3::Zero(), Quat::Identity(), Vec3(r, r, r)});
  MomentDesc m;
  m.volume = sphere_volume(r);
  m.Ms = kIronMs;
  b.moments.push_back(m);
  b.color = kIron;
  return b;
}

/// N balls of radius r stacked in square layers of side n, pitch 2r(1 + gap), bottom layer
/// resting on z = 0 and centred on (cx, cy).
void stack_balls(SceneDesc* s, int N, int side, double r, double gap, double cx, double cy,
                 double z0 = 0.0) {
  const double pitch = 2.0 * r * (1.0 + gap);
  for (int k = 0; k < N; ++k) {
    const int layer = k / (side * side), in = k % (side * side);
    const int i = in % side, j = in / side;
    const Vec3 p(cx + (i - 0.5 * (side - 1)) * pitch, cy + (j - 0.5 * (side - 1)) * pitch,
                 z0 + r + layer * pitch);
    s->bodies.push_back(iron_ball("ball_" + std::to_string(k), p, r));
  }
}

// ---------------------------------------------------------------------------------------
// gap between stacked balls, a fraction of the diameter: they start apart, not in contact
constexpr double kStackGap = 0.001;
constexpr int kBallsUpSide = 9;    // balls per row (9 × 9 per layer, the paper's 9×9×3)
constexpr int kBallsUpLayers = 3;  // the paper's layers: the magnet's height is set from them

// The rotation by `angle` (rad) about the unit `axis`: q = (cos ½θ, sin ½θ · axis), with the
// deterministic sine and cosine (a scene's start is part of its state hash)
Quat axis_angle(double angle, const Vec3& axis) {
  const double h = 0.5 * angle;
  const double s = mag::dmath::sin(h);
  return Quat(mag::dmath::cos(h), s * axis.x(), s * axis.y(), s * axis.z());
}

// balls_up — 243 iron balls (9×9×3, radius 5 mm) resting on frictionless ground; a 3 cm
// N52 cube magnet (29.7 A·m², 1.1e6 A/m · (3 cm)³) fixed 3 cm above the top layer pulls them
// up. Sized for the classic force (the default): the paper's 2 cm cube (8.8 A·m²) lifts one
// ball under it, 3 cm holds 140–155 (tools/findings/balls_up.md).
SceneDesc balls_up(const SceneParams& p) {
  SceneDesc s;
  s.name = "balls_up";
  // no sleep: the pile is cheap (about 4 ms a frame), and asleep it missed the 0.1 m/s mark of
  // its lifted pile in 2 of 8 runs rather than 1 (tools/findings/performance.md)
  s.description = "243 iron balls on frictionless ground pulled up by a fixed cube magnet";
  s.modelling_level =
      "1 induced moment per ball (sphere primitive); magnet: static box geom with 1 "
      "permanent moment at its centre; no friction";
  const int N = p.count > 0 ? p.count : 243;
  const double r = 0.005;
  stack_balls(&s, N, kBallsUpSide, r, kStackGap, 0, 0);
  const double L = 0.03;  // cube side (m)
  // the magnet's face 3 cm above the paper's 3 layers (--count leaves it there: fewer balls
  // only lie lower)
  const double face = kBallsUpLayers * 2 * r + 0.03;  // (m)
  s.bodies.push_back(magnet_body("magnet", BodyType::Static, Vec3(0, 0, face + L / 2), ShapeKind::Box,
                                 Vec3(L / 2, L / 2, L / 2),
                                 {permanent_moment(L * L * L, Vec3(0, 0, kN52M * L * L * L * p.strength))}));  // 29.7 A·m², up
  s.options.friction = 0.0;
  // iron's eddy-current loss (σ ≈ 1e7 S/m), a property of the balls, not a knob: over 8 runs
  // of 2 s (243…236 balls) the lifted pile's fastest ball fell from 0.07–0.85 m/s without it
  // to 0.011–0.049 m/s, at 0.89× the cost per frame (tools/findings/energy.md). The paper's
  // loss-free variant is --eddy-conductivity 0; the ground stays frictionless, as there.
  s.options.eddy_conductivity = 1e7;  // (S/m)
  s.options.quickstep_iterations = 100;
  // up to 8 rigid sub-steps per frame where bodies in contact move fast (the motion term
  // only: the load term would split every frame of the resting pile)
  s.options.max_substeps = 8;
  s.options.substep_load = false;
  s.camera.eye = Eigen::Vector3f(0.16f, -0.20f, 0.12f);
  s.camera.target = Eigen::Vector3f(0.0f, 0.0f, 0.03f);
  s.default_seconds = 3.0;
  // the pile spans ±4 cm; a ball farther than 15 cm sideways from the magnet was thrown
  s.escape_radius = 0.15;  // (m)
  return s;
}

// ---------------------------------------------------------------------------------------
// alphabets — 100 letter pieces (iron, 3 cm tall, 5 mm strokes, 1 induced moment per
// stroke box) on a 5×5×4 grid at 6 cm pitch, no gravity; an invisible, "excessively strong"
// 300 A·m² moment at the grid centre with an invisible collider of radius 2 cm (the paper's
// fiction: no real magnet of that size carries it; an N52 sphere of 300 A·m² would have a
// radius of 4.0 cm at 1.1e6 A/m). Where a stroke lies on the collider its moment is 2.25 cm
// from the centre: |H| = 2m/(4π r³) = 4.2 MA/m = 2.6 Ms on the axis, inside Fig. 9's region
// |H| ≥ 2.5 Ms where Kim 2018's dynamics fails. 6 cm rather than 7 cm: the corner letters
// start where the pull falls as r⁻⁷, so their time to arrive goes as the distance^4.5; from
// 0.22 m they were still arriving 1.5 s in (tools/findings/energy.md). Letters arrive at up to
// 15 m/s, so the frame splits into up to 16 rigid sub-steps where bodies in contact move fast
// or are pressed hard into their contacts (tools/findings/alphabets.md).
struct Stroke {
  double x0, y0, x1, y1;  // glyph units: width 2, height 3
};
const std::vector<std::vector<Stroke>>& glyphs() {
  static const std::vector<std::vector<Stroke>> g = {
      {{0.75, 0, 1.25, 3}},                                      // I
      {{0, 0, 0.5, 3}, {0.5, 0, 2, 0.5}},                        // L
      {{0.75, 0, 1.25, 2.5}, {0, 2.5, 2, 3}},                    // T
      {{0, 0, 0.5, 3}, {1.5, 0, 2, 3}, {0.5, 1.25, 1.5, 1.75}},  // H
      {{0, 0, 0.5, 3}, {0.5, 0, 2, 0.5}, {0.5, 1.25, 1.6, 1.75}, {0.5, 2.5, 2, 3}},  // E
      {{0, 0, 0.5, 3}, {0.5, 1.25, 1.6, 1.75}, {0.5, 2.5, 2, 3}},                    // F
      {{0, 0.5, 0.5, 3}, {1.5, 0.5, 2, 3}, {0, 0, 2, 0.5}},                          // U
      {{1.5, 0.5, 2, 3}, {0, 0, 2, 0.5}, {0, 0.5, 0.5, 1.25}},                       // J
  };
  return g;
}

BodyDesc letter(int index, const Vec3& p, const Quat& q) {
  const double unit = 0.01;    // glyph unit (m): letters 2 × 3 cm
  const double depth = 0.005;  // (m)
  const auto& strokes = glyphs()[index % glyphs().size()];
  BodyDesc b;
  b.name = "letter_" + std::to_string(index);
  b.position = p;
  b.orientation = q;
  b.density = kIronDensity;
  static const render::Color palette[] = {{0.85f, 0.35f, 0.2f}, {0.2f, 0.5f, 0.85f},
                                          {0.95f, 0.75f, 0.2f}, {0.3f, 0.7f, 0.35f},
                                          {0.6f, 0.35f, 0.75f}};
  b.color = palette[index % 5];
  for (const Stroke& st : strokes) {
    const Vec3 c((0.5 * (st.x0 + st.x1) - 1.0) * unit, (0.5 * (st.y0 + st.y1) - 1.5) * unit, 0);
    const Vec3 h(0.5 * (st.x1 - st.x0) * unit, 0.5 * (st.y1 - st.y0) * unit, 0.5 * depth);
    b.shapes.push_back({ShapeKind::Box, c, Quat::Identity(), h});
    MomentDesc m;
    m.offset = c;
    m.volume = 8.0 * h.x() * h.y() * h.z();
    m.Ms = kIronMs;
    b.moments.push_back(m);
  }
  return b;
}

SceneDesc alphabets(const SceneParams& p) {
  SceneDesc s;
  s.name = "alphabets";
  // no sleep: the letters on the magnet rattle and seldom sleep, and in the one ensemble run
  // that ejected a letter (E +5.4 J) short naps had changed the trajectory (energy.md)
  s.description = "100 iron letters in mid-air gathered by an invisible, excessively strong moment";
  s.modelling_level =
      "letters = 1–4 boxes, 1 induced moment per box; central moment: static, invisible, "
      "with an invisible sphere collider of radius 2 cm; no gravity, no ground";
  const int N = p.count > 0 ? p.count : 100;
  const double pitch = 0.06;  // (m) grid pitch: letters 3 cm tall start 3 cm apart
  // beyond 100 letters (--count) the grid repeats, each repeat 2 cm higher
  const double repeat_shift = 0.02;  // (m)
  std::mt19937 rng(2018);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < N; ++k) {
    const int i = k % 5, j = (k / 5) % 5, l = (k / 25) % 4, extra = k / 100;
    const Vec3 pos((i - 2) * pitch, (j - 2) * pitch, (l - 1.5) * pitch + extra * repeat_shift);
    const Quat q = axis_angle(kPi * u(rng), Vec3(u(rng), u(rng), u(rng)).normalized());
    s.bodies.push_back(letter(k, pos, q));
  }
  const double Rc = 0.02;  // (m) radius of the invisible collider around the central moment
  BodyDesc c = magnet_body("centre", BodyType::Static, Vec3::Zero(), ShapeKind::Sphere, Vec3(Rc, Rc, Rc),
                           {permanent_moment(sphere_volume(Rc), Vec3(0, 0, 300.0 * p.strength))});
  c.visible = false;
  c.color = BodyDesc{}.color;  // never drawn
  s.bodies.push_back(c);
  s.options.gravity = Vec3::Zero();
  s.options.ground = false;
  // one moment per 3 cm stroke: two strokes crossing put moments ~5 mm apart, inside each
  // other's equivalent sphere (radius 5.6 mm); soften the dipole sum at that scale
  s.options.magnetics.field.softening = 0.005;  // (m)
  s.options.quickstep_iterations = 50;
  s.options.max_substeps = 16;  // see above: letters arrive at up to 15 m/s
  s.camera.eye = Eigen::Vector3f(0.386f, -0.471f, 0.257f);  // the grid at 7 cm pitch framed as before, × 6/7
  s.camera.target = Eigen::Vector3f(0, 0, 0);
  s.default_seconds = 3.0;
  // the grid's corners start 0.19 m from the centre (3-D, no gravity): beyond 0.3 m a
  // letter is flying away, not gathering
  s.escape_radius = 0.3;  // (m)
  return s;
}

// ---------------------------------------------------------------------------------------
// falling_magnet — 1032 iron balls (radius 5 mm) stacked 12×12 per layer; a heavy N52
// sphere magnet (radius 2.2 cm, 49 A·m² = 1.1e6 A/m · 4/3 π (2.2 cm)³, 0.33 kg) falls onto
// them from 8 cm above the top. Sized for the classic force (the default): the 2 cm magnet of
// 33.5 A·m² that eq. 4 needed holds under 600 balls with it (tools/findings/falling_magnet.md).
SceneDesc falling_magnet(const SceneParams& p) {
  SceneDesc s;
  s.name = "falling_magnet";
  s.options.sleep = true;  // resting islands leave the step (engine/sleep.cpp)
  s.description = "a heavy sphere magnet falls onto 1032 stacked iron balls";
  s.modelling_level =
      "1 induced moment per ball; magnet: dynamic sphere with 1 permanent moment (torque on "
      "it from the balls' field)";
  const int N = p.count > 0 ? p.count : 1032;
  const double r = 0.005;
  const int side = 12;  // balls per row, 144 per layer
  stack_balls(&s, N, side, r, kStackGap, 0, 0);
  const int layers = (N + side * side - 1) / (side * side);
  const double top = layers * 2 * r * (1.0 + kStackGap);
  const double R = 0.022;  // (m)
  // 8 cm above the pile, a few mm off the central column: it lands between balls, not on
  // one ball's top (a symmetric landing would be a knife-edge start)
  const Vec3 drop(0.004, -0.003, top + 0.08 + R);  // (m)
  BodyDesc mag = magnet_body("magnet", BodyType::Dynamic, drop, ShapeKind::Sphere, Vec3(R, R, R),
                             {permanent_moment(sphere_volume(R), Vec3(0, 0, -kN52M * sphere_volume(R) * p.strength))});  // 49 A·m², down
  mag.density = 7500.0;  // NdFeB (kg/m³)
  s.bodies.push_back(mag);
  // eq. 4 (--method ours) breaks action = reaction: with a dynamic magnet the magnet and its
  // balls would propel themselves, so its forces are applied pairwise antisymmetrized (no
  // effect on the classic force, which balances already)
  s.options.reaction_symmetric_forces = true;
  // rolling resistance on the ground, ρ = 0.2 r (c_rr = 0.2, a ball on a soft mat): without
  // it the collapsed block of balls rolls away for ever
  s.options.rolling_friction = kRollingCoefficient * r;
  // 50 QuickStep iterations: at ODE's 20 the heap's friction does not converge and it creeps
  s.options.quickstep_iterations = 50;
  // point dipoles, no softening: under the classic force a softening of 2.5 mm did not
  // help the heap come to rest (tools/findings/energy.md)
  // up to 8 rigid sub-steps where bodies touching each other move fast (the impact and the
  // collapse; the motion term only)
  s.options.max_substeps = 8;
  s.options.substep_load = false;
  s.camera.eye = Eigen::Vector3f(0.26f, -0.32f, 0.22f);
  s.camera.target = Eigen::Vector3f(0, 0, 0.03f);
  s.default_seconds = 2.0;
  // the pile spans ±5.5 cm; a ball 1 m sideways from the magnet was thrown off the table
  s.escape_radius = 1.0;  // (m)
  return s;
}

// ---------------------------------------------------------------------------------------
// sakura_tree — 2500 iron balls (radius 4 mm) fall from a 50×50 grid 40 cm up onto a static
// tree of capsules whose 8 branch ends each carry an N52 sphere magnet (radius 1.75 cm,
// 24.7 A·m² = 1.1e6 A/m · 4/3 π (1.75 cm)³, |H| = 2M/3 ≈ 0.46 Ms at its poles). Sized for
// the classic force (the default): the 1.2 cm magnets eq. 4 needed hold about 200 balls with
// it, 1.7 cm about 387 and these about 398 (tools/findings/energy.md).
SceneDesc sakura_tree(const SceneParams& p) {
  SceneDesc s;
  s.name = "sakura_tree";
  s.options.sleep = true;  // resting islands leave the step (engine/sleep.cpp)
  s.description = "2500 iron balls fall onto a tree whose branch ends are magnets";
  s.modelling_level =
      "1 induced moment per ball; tree: static capsules (trunk, 2 levels of branches); 8 "
      "static sphere magnets at the branch ends, 1 permanent moment each";
  const int N = p.count > 0 ? p.count : 2500;
  const double r = 0.004;
  BodyDesc tree;
  tree.name = "tree";
  tree.type = BodyType::Static;
  tree.color = {0.45f, 0.30f, 0.18f};
  std::vector<BodyDesc> tips;
  auto capsule = [&](const Vec3& a, const Vec3& b, double rad) {
    const Vec3 d = b - a;
    ShapeDesc sh;
    sh.kind = ShapeKind::Capsule;
    sh.offset = 0.5 * (a + b);
    sh.rotation = Quat::FromTwoVectors(Vec3::UnitZ(), d.normalized());
    sh.size = Vec3(rad, 0.5 * d.norm(), 0);
    tree.shapes.push_back(sh);
  };
  // the tree (m, rad): a 16 cm trunk (radius 12 mm) forks into 4 branches (7 mm) that reach
  // 7 cm out and 7 cm up, turned 0.3 rad so none lies along x or y (the sheet of balls above
  // is aligned with them); each ends in 2 twigs (4 mm) 6 cm out and 5 cm up, ±0.45 rad apart
  const Vec3 base(0, 0, 0), fork(0, 0, 0.16);
  const double trunk_r = 0.012, branch_r = 0.007, twig_r = 0.004;
  const double branch_turn = 0.3, branch_out = 0.07, branch_up = 0.07;
  const double twig_spread = 0.45, twig_out = 0.06, twig_up = 0.05;
  capsule(base, fork, trunk_r);
  for (int i = 0; i < 4; ++i) {
    const double a = kPi / 2 * i + branch_turn;
    const Vec3 mid = fork + Vec3(branch_out * mag::dmath::cos(a), branch_out * mag::dmath::sin(a), branch_up);
    capsule(fork, mid, branch_r);
    for (int k = -1; k <= 1; k += 2) {
      const double b = a + twig_spread * k;
      const Vec3 tip = mid + Vec3(twig_out * mag::dmath::cos(b), twig_out * mag::dmath::sin(b), twig_up);
      capsule(mid, tip, twig_r);
      // the branch end: an N52 sphere magnet of radius Rt magnetized along the branch, a
      // static body of its own (coloured as a magnet); its collider keeps iron at ≥ Rt + r
      // from the dipole
      const double Rt = 0.0175;  // (m)
      const Vec3 m = kN52M * sphere_volume(Rt) * p.strength * (tip - mid).normalized();  // 24.7 A·m²
      tips.push_back(magnet_body("tip_magnet_" + std::to_string(tips.size()), BodyType::Static, tip,
                                 ShapeKind::Sphere, Vec3(Rt, Rt, Rt), {permanent_moment(sphere_volume(Rt), m)}));
    }
  }
  s.bodies.push_back(tree);
  for (const BodyDesc& t : tips) s.bodies.push_back(t);
  // one square sheet, centred over the tree (above 2500 balls it only widens: stacked in
  // sheets 3 cm apart, 10,000 balls blew up at t ≈ 0.22 s, up to 228 m/s, with the direct
  // sum and Barnes–Hut alike — the upper sheets pile onto the balls held at the tips)
  const int side = static_cast<int>(std::ceil(std::sqrt(N)));
  for (int k = 0; k < N; ++k) {
    const int layer = k / (side * side), in = k % (side * side);
    const int i = in % side, j = in / side;
    const double pitch = 0.011;        // (m) 3 mm between 8 mm balls
    // rows shifted by 0, 1.3, 2.6 mm in turn: a sheet aligned with nothing below, so the
    // balls do not land in lock-step columns on the twigs
    const double row_shift = 0.0013;   // (m)
    const double drop_height = 0.40;   // (m) above the ground, 14 cm above the twig ends
    const double sheet_gap = 0.03;     // (m) between sheets beyond side² balls (--count)
    const Vec3 pos((i - 0.5 * (side - 1)) * pitch + row_shift * (j % 3),
                   (j - 0.5 * (side - 1)) * pitch, drop_height + layer * sheet_gap);
    s.bodies.push_back(iron_ball("ball_" + std::to_string(k), pos, r));
  }
  s.options.rolling_friction = kRollingCoefficient * r;  // as falling_magnet: balls can rest
  // no bounded pairs: their clamp has a kink exactly at contact, where the resting balls
  // sit, and there E = K + U_g + U* jitters by ±0.03 J a step; without it E only falls
  // rolling resistance between two balls too (the same ρ): a ball hanging on one neighbour
  // at a tip rolls to and fro on it without loss otherwise
  s.options.rolling_friction_bodies = kRollingCoefficient * r;
  // up to 8 rigid sub-steps per frame, by motion and by load: balls held at a tip are
  // pressed into their contacts at ~10^4 m/s^2 (x1) to ~5·10^4 (x3), and with one step per
  // frame the x3 pile blew up at QuickStep W 1.0 / 20 iterations (tools/findings/energy.md)
  s.options.max_substeps = 8;
  s.camera.eye = Eigen::Vector3f(0.55f, -0.65f, 0.45f);
  s.camera.target = Eigen::Vector3f(0, 0, 0.17f);
  s.default_seconds = 2.0;
  // the sheet spans ±0.27 m over the trunk (the 8 tip magnets centre on it horizontally):
  // beyond 0.5 m of the trunk a ball was thrown
  s.escape_radius = 0.5;  // (m)
  return s;
}

// ---------------------------------------------------------------------------------------
// crystal_balls — 178 fixed iron balls (radius 5 mm) on a sphere of radius 5 cm (Fibonacci
// lattice) around a 6 cm bar magnet of 3 permanent moments. strength 1 = the strong magnet
// (4000 A·m² in all; |H| up to 6.1 Ms at the balls nearest the poles, at the ground truth);
// the weak magnet is strength 0.05 (|H| up to 0.24 Ms). Measured: experiments fig8,
// fig8.json's max_H_over_Ms.
SceneDesc crystal_balls(const SceneParams& p) {
  SceneDesc s;
  s.name = "crystal_balls";
  s.description = "178 fixed iron balls around a bar magnet (paper Figs. 7–8)";
  s.modelling_level =
      "balls: static spheres with 1 induced moment each (fixed in space, only M moves); "
      "bar magnet: static box with 3 permanent moments along its axis";
  const int N = p.count > 0 ? p.count : 178;
  const double r = 0.005, R = 0.05;
  const Vec3 centre(0, 0, 0.1);  // (m) the bar's centre, above the (unused) ground
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < N; ++k) {
    const double z = 1.0 - 2.0 * (k + 0.5) / N;
    const double rho = std::sqrt(1.0 - z * z);
    const Vec3 pos(R * rho * mag::dmath::cos(golden * k), R * rho * mag::dmath::sin(golden * k), R * z);
    BodyDesc b = iron_ball("ball_" + std::to_string(k), pos + centre, r);
    b.type = BodyType::Static;
    s.bodies.push_back(b);
  }
  // the bar: 12 × 12 × 60 mm, one moment per third of it at the third's centre
  std::vector<MomentDesc> thirds;
  for (int k = -1; k <= 1; ++k)
    thirds.push_back(permanent_moment(0.012 * 0.012 * 0.02, Vec3(0, 0, 4000.0 / 3.0 * p.strength), Vec3(0, 0, 0.02 * k)));
  s.bodies.push_back(magnet_body("bar_magnet", BodyType::Static, centre, ShapeKind::Box, Vec3(0.006, 0.006, 0.03), thirds));
  s.options.gravity = Vec3::Zero();
  s.camera.eye = Eigen::Vector3f(0.12f, -0.16f, 0.16f);
  s.camera.target = Eigen::Vector3f(0, 0, 0.1f);
  s.default_seconds = 0.05;
  s.escape_radius = 0.0;  // static balls: escape is not measured
  return s;
}

}  // namespace

const std::vector<SceneEntry>& registry() {
  static const std::vector<SceneEntry> r = {
      {"balls_up", "243 iron balls pulled up by a fixed cube magnet (paper Fig. 3)", balls_up},
      {"alphabets", "100 iron letters gathered by an invisible strong moment (Fig. 4)", alphabets},
      {"falling_magnet", "a heavy magnet falls onto 1032 iron balls (Fig. 5)", falling_magnet},
      {"sakura_tree", "2500 iron balls fall onto a magnetic tree (Fig. 6)", sakura_tree},
      {"crystal_balls", "178 fixed balls around a bar magnet (Figs. 7–8)", crystal_balls},
  };
  return r;
}

const SceneEntry* find_scene(const std::string& name) {
  for (const SceneEntry& e : registry())
    if (name == e.name) return &e;
  return nullptr;
}

}  // namespace magsim::scenes
