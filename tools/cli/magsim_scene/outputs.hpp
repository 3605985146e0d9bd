// tools/cli/magsim_scene/outputs.hpp — what a run writes: the output folder, states.csv and
// moments.csv with summary.json's per-frame series (Recorder), summary.json's energy audit,
// and the frames (FrameRenderer).
#pragma once

#include "engine/sleep.hpp"
#include "engine/simulation.hpp"
#include "tools/cli/magsim_scene/magsim_scene.hpp"
#ifdef MAGSIM_HAVE_RENDER
#include "render/frame_writer.hpp"
#include "render/renderer.hpp"
#endif

#include <nlohmann/json.hpp>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace magsim::scene_tool {

namespace fs = std::filesystem;
using nlohmann::json;

// The names this program writes into --out; a run deletes its own old outputs first (so a
// shorter rerun leaves no stale frame_*.png for make_video.sh) and never anything else.
inline const char* const kOutputNames[] = {"summary.json", "summary.json.tmp", "states.csv", "moments.csv"};
/// One of kOutputNames or frame_NNNNNN.png.
bool is_output_name(const std::string& f);

// RFC 4180: a field with a comma, quote or line break is quoted, quotes doubled; other
// fields are written as they are (so ordinary output does not change)
std::string csv_field(const std::string& v);
// The lock a run holds on its output folder (an flock on DIR/.magsim.lock) until it ends, so
// two runs never mix their files in one folder.
class OutDirLock {
 public:
  explicit OutDirLock(int fd) : fd_(fd) {}
  OutDirLock(OutDirLock&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
  OutDirLock(const OutDirLock&) = delete;
  OutDirLock& operator=(const OutDirLock&) = delete;
  ~OutDirLock();
  int fd() const { return fd_; }

 private:
  int fd_;
};
// Creates DIR (and parents), locks it (UsageError when another run holds it), checks that
// files can be written into it and deletes the outputs of an earlier run there (only this
// program's own names, see is_output_name; one that is not a regular file or a symlink is
// refused, not deleted).
OutDirLock prepare_out_dir(const std::string& dir);
// summary.json "energy" (outputs.cpp)
json energy_json(const engine::Simulation& sim);

// Per-frame output: states.csv and moments.csv rows, and the series of summary.json.
class Recorder {
 public:
  Recorder(const std::string& dir, const engine::Simulation& sim)
      : sim_(sim), states_path_((fs::path(dir) / "states.csv").string()),
        moments_path_((fs::path(dir) / "moments.csv").string()) {
    states_ = std::fopen(states_path_.c_str(), "w");
    if (!states_) throw IoError("cannot create " + states_path_ + " (" + errno_text() + ")");
    moments_ = std::fopen(moments_path_.c_str(), "w");
    if (!moments_) throw IoError("cannot create " + moments_path_ + " (" + errno_text() + ")");
    std::fprintf(states_, "frame,time,body,name,x,y,z,qw,qx,qy,qz\n");
    std::fprintf(moments_, "frame,time,moment,body,x,y,z,Mx,My,Mz,M1x,M1y,M1z,M2x,M2y,M2z\n");
    check();
  }
  /// Flushes and closes both files; throws IoError naming the file that failed.
  void close() {
    std::FILE* s = states_;
    std::FILE* m = moments_;
    states_ = moments_ = nullptr;
    errno = 0;
    const bool s_ok = std::fflush(s) == 0 && !std::ferror(s);
    const std::string s_err = errno_text();
    const bool s_closed = std::fclose(s) == 0;
    if (!s_ok || !s_closed) {
      std::fclose(m);
      throw IoError("writing " + states_path_ + " failed (" + s_err + ")");
    }
    errno = 0;
    const bool m_ok = std::fflush(m) == 0 && !std::ferror(m);
    const std::string m_err = errno_text();
    if (std::fclose(m) != 0 || !m_ok) throw IoError("writing " + moments_path_ + " failed (" + m_err + ")");
  }
  ~Recorder() {
    if (states_) std::fclose(states_);
    if (moments_) std::fclose(moments_);
  }
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Writes the current state as the next frame (x, y, z: centre of mass); false when this
  /// step was already written.
  bool frame() {
    if (sim_.steps() == last_step_) return false;
    last_step_ = sim_.steps();
    const int f = frames_++;
    const double t = sim_.time();
    const engine::Model& m = sim_.model();
    const engine::State& s = sim_.state();
    for (int b = 0; b < m.nbody; ++b) {
      const engine::Vec3& p = s.pos[b];
      const engine::Quat& q = s.quat[b];
      std::fprintf(states_, "%d,%.9g,%d,%s,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", f, t, b,
                   csv_field(m.body_name[b]).c_str(), p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
    }
    const mag::MomentDesc& ms = sim_.moments();
    const mag::Magnetization& mz = s.mag;
    for (int j = 0; j < m.nmoment; ++j) {
      const engine::Vec3& p = ms.position[j];
      std::fprintf(moments_, "%d,%.9g,%d,%d,%.10g,%.10g,%.10g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
                   f, t, j, m.moment_body[j], p.x(), p.y(), p.z(), mz.M[j].x(), mz.M[j].y(), mz.M[j].z(),
                   mz.M1[j].x(), mz.M1[j].y(), mz.M1[j].z(), mz.M2[j].x(), mz.M2[j].y(), mz.M2[j].z());
    }
    const engine::Metrics x = sim_.metrics();
    series_["time"].push_back(t);
    series_["kinetic_energy"].push_back(x.kinetic_energy);
    series_["max_speed"].push_back(x.max_speed);
    series_["bounding_radius"].push_back(x.bounding_radius);
    series_["magnet_radius"].push_back(x.magnet_radius);
    series_["attached"].push_back(x.attached);
    series_["held"].push_back(x.held);
    series_["held_max_speed"].push_back(held_speed(t));
    series_["escaped"].push_back(x.escaped);
    series_["iterations"].push_back(x.iterations);
    series_["momentum_norm"].push_back(x.momentum.norm());
    series_["contacts"].push_back(x.contacts);
    series_["substeps"].push_back(sim_.last_profile().substeps);
    series_["contact_depth"].push_back(sim_.state().contact_depth);  // the deepest overlap (m)
    series_["threads"].push_back(sim_.threads());
    series_["asleep"].push_back(engine::asleep_count(s));  // bodies asleep (options.sleep)
    check();
    // the energy audit (engine/energy.hpp): state functions and cumulative work (J), and the
    // last step's magnetic and contact work (J per step)
    const engine::EnergyAudit& e = sim_.energy();
    series_["energy_kinetic"].push_back(e.kinetic);
    series_["energy_gravitational"].push_back(e.gravitational);
    series_["energy_magnetic"].push_back(e.magnetic_energy);
    series_["energy_magnetic_work"].push_back(e.total.magnetic_work);
    series_["energy_contact_work"].push_back(e.total.contact_work);
    series_["energy_eddy_work"].push_back(e.total.eddy_work);
    series_["energy_gravity_work"].push_back(e.total.gravity_work);
    series_["energy_gravity_drift"].push_back(e.total.gravity_drift);
    series_["energy_step_magnetic_work"].push_back(e.last.magnetic_work);
    series_["energy_step_contact_work"].push_back(e.last.contact_work);
    series_["energy_total"].push_back(engine::total_energy(e));
    series_["energy_created"].push_back(e.total.energy_created);
    series_["energy_dissipated"].push_back(e.total.energy_dissipated);
    series_["guard_retakes"].push_back(e.guard_retakes);
    return true;
  }
  int frames() const { return frames_; }
  const json& series() const { return series_; }

 private:
  // The fastest held body (engine::held_bodies) as a viewer of the frames sees it: its
  // displacement since the previous frame over the frame time (m/s); 0 at the first frame,
  // which has no displacement yet.
  double held_speed(double t) {
    const engine::State& s = sim_.state();
    double v = 0.0;
    if (!prev_pos_.empty() && t > prev_t_)
      for (int b : engine::held_bodies(sim_.model(), s))
        v = std::max(v, (s.pos[b] - prev_pos_[b]).norm() / (t - prev_t_));
    prev_pos_ = s.pos;
    prev_t_ = t;
    return v;
  }

  // a failed write (full disk …) sets the stream's error flag; stop at the first
  void check() const {
    if (std::ferror(states_)) throw IoError("writing " + states_path_ + " failed (" + errno_text() + ")");
    if (std::ferror(moments_)) throw IoError("writing " + moments_path_ + " failed (" + errno_text() + ")");
  }

  const engine::Simulation& sim_;
  std::string states_path_, moments_path_;
  std::FILE* states_ = nullptr;
  std::FILE* moments_ = nullptr;
  long last_step_ = -1;
  int frames_ = 0;
  json series_ = json::object();
  std::vector<engine::Vec3> prev_pos_;  // the previous frame's centres (held_speed)
  double prev_t_ = 0.0;
};


// ---- rendering ----------------------------------------------------------------------
// With the renderer built in (MAGSIM_HAVE_RENDER) and without --no-render, every recorded
// frame is drawn: sim.frame(opts) → magsim::render::Renderer → DIR/frame_%06d.png, PNGs written by a
// background thread. crystal_balls (or --arrows) draws M1 (red) and M2 (blue) on every ball.
class FrameRenderer {
 public:
  FrameRenderer(bool render, int width, int height, int samples, const std::string& dir, bool arrows)
      : dir_(dir), enabled_(render) {
    if (!enabled_) return;
#ifdef MAGSIM_HAVE_RENDER
    renderer_ = std::make_unique<magsim::render::Renderer>(width, height, samples);
    writer_ = std::make_unique<magsim::render::FrameWriter>(4, 1);
    opts_.magnetization_arrows = arrows;
    opts_.arrow_scale = 2.2;  // reach out of the ball to be seen
#else
    (void)width, (void)height, (void)samples, (void)arrows;
    std::fprintf(stderr, "note: built without the renderer (MAGSIM_RENDER=OFF); continuing as --no-render\n");
    enabled_ = false;
#endif
  }
  void draw(const engine::Simulation& sim) {
    if (!enabled_) return;
#ifdef MAGSIM_HAVE_RENDER
    const auto t0 = std::chrono::steady_clock::now();
    renderer_->draw(sim.frame(opts_));
    ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    try {
      writer_->push(magsim::render::frame_path(dir_, index_++), renderer_->width(), renderer_->height(),
                    renderer_->pixels());
    } catch (const std::runtime_error& e) {  // an earlier frame could not be written: an I/O error
      throw IoError(std::string("writing frames: ") + e.what());
    }
#else
    (void)sim;
#endif
  }
  /// Waits for the PNG writer; throws its first error (a frame that could not be written).
  void finish() {
#ifdef MAGSIM_HAVE_RENDER
    if (writer_) writer_->finish();
#endif
  }
  bool enabled() const { return enabled_; }
  int frames() const { return index_; }
  const std::vector<double>& ms() const { return ms_; }

 private:
  std::string dir_;
  bool enabled_;
  int index_ = 0;
  std::vector<double> ms_;
  engine::FrameOptions opts_;
#ifdef MAGSIM_HAVE_RENDER
  std::unique_ptr<magsim::render::Renderer> renderer_;
  std::unique_ptr<magsim::render::FrameWriter> writer_;
#endif
};


}  // namespace magsim::scene_tool
