// tools/cli/magsim_scene/outputs.cpp — the output folder, CSV quoting and summary.json's energy
// audit (outputs.hpp).
#include "tools/cli/magsim_scene/outputs.hpp"

#include <fstream>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

namespace magsim::scene_tool {

bool is_output_name(const std::string& f) {
  for (const char* n : kOutputNames)
    if (f == n) return true;
  // summary.json's temporary file (tools/cli/replace_file.hpp), left by a killed run
  if (f.size() == 20 && f.compare(0, 14, ".summary.json.") == 0) return true;
  // a frame's temporary file (render/png_io.cpp), left by a killed run: .frame_%06d.png.XXXXXX
  if (f.size() > 8 && f[0] == '.' && f.compare(f.size() - 7, 1, ".") == 0 && is_output_name(f.substr(1, f.size() - 8)) &&
      f.compare(1, 6, "frame_") == 0)
    return true;
  // frame_%06d.png (six or more digits)
  const std::size_t digits = f.size() >= 10 ? f.size() - 10 : 0;
  if (f.size() < 16 || f.compare(0, 6, "frame_") != 0 || f.compare(f.size() - 4, 4, ".png") != 0) return false;
  for (std::size_t i = 6; i < 6 + digits; ++i)
    if (f[i] < '0' || f[i] > '9') return false;
  return true;
}

std::string csv_field(const std::string& v) {
  if (v.find_first_of(",\"\r\n") == std::string::npos) return v;
  std::string q = "\"";
  for (char c : v) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

OutDirLock::~OutDirLock() {
  if (fd_ >= 0) ::close(fd_);
}

// Any failure here is an I/O error (exit 3), but for a folder another run holds (exit 1).
OutDirLock prepare_out_dir(const std::string& dir) {
  std::error_code ec;
  if (fs::is_symlink(fs::symlink_status(dir, ec)) && !fs::exists(dir, ec))
    throw IoError("--out " + dir + ": is a symbolic link to " + fs::read_symlink(dir, ec).string() +
                  ", which does not exist");
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw IoError("--out " + dir + ": exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec) throw IoError("--out " + dir + ": cannot create the directory (" + ec.message() + ")");
  const std::string lock_path = (fs::path(dir) / ".magsim.lock").string();
  OutDirLock lock(::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0666));
  if (lock.fd() < 0) throw IoError("--out " + dir + ": cannot create " + lock_path + " (" + errno_text() + ")");
  if (::flock(lock.fd(), LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK)
    throw UsageError("--out " + dir + ": another run is writing into this folder (it holds " + lock_path +
                     "); wait for it or choose another --out");
  const fs::path probe = fs::path(dir) / ".magsim_write_test";
  {
    std::ofstream f(probe);
    if (!f || !(f << "ok") || !f.flush()) throw IoError("--out " + dir + ": directory is not writable");
  }
  fs::remove(probe, ec);
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    if (!is_output_name(e.path().filename().string()) || e.is_directory(ec)) continue;
    if (!e.is_symlink(ec) && !e.is_regular_file(ec))  // a FIFO or device is not an old output
      throw IoError("--out " + dir + ": " + e.path().filename().string() + " is not a regular file; it is not replaced");
    if (!fs::remove(e.path(), ec) && ec)
      throw IoError("--out " + dir + ": cannot delete the old " + e.path().filename().string() + " (" + ec.message() + ")");
  }
  if (ec) throw IoError("--out " + dir + ": cannot list the directory (" + ec.message() + ")");
  return lock;
}




namespace {

json energy_flow_json(const engine::EnergyFlow& f) {
  return json{{"kinetic_change", f.kinetic_change},
              {"gravitational_change", f.gravitational_change},
              {"magnetic_work", f.magnetic_work},
              {"gravity_work", f.gravity_work},
              {"eddy_work", f.eddy_work},
              {"contact_work", f.contact_work},
              {"gravity_drift", f.gravity_drift},
              {"contact_work_in", f.contact_work_in},
              {"energy_created", f.energy_created},
              {"energy_dissipated", f.energy_dissipated}};
}

}  // namespace

// summary.json "energy": the audit at the end of the run (J); "last_step" = the increments
// of the final step; "escaped_bodies" = the escaped bodies' kinetic energy now and the
// magnetic and contact work done on them since t = 0 (net, and "_in": the positive steps).
// ΔK + ΔU_g = magnetic_work + eddy_work + contact_work − gravity_drift.
json energy_json(const engine::Simulation& sim) {
  const engine::EnergyAudit& e = sim.energy();
  json j = energy_flow_json(e.total);
  double k = 0.0, w_mag = 0.0, w_c = 0.0, w_mag_in = 0.0, w_c_in = 0.0;
  const std::vector<int> escaped = engine::escaped_bodies(sim.model(), sim.state());
  for (int b : escaped) {
    k += engine::kinetic_energy(sim.model(), sim.state(), b);
    w_mag += e.body_magnetic_work[b];
    w_c += e.body_contact_work[b];
    w_mag_in += e.body_magnetic_work_in[b];
    w_c_in += e.body_contact_work_in[b];
  }
  j["escaped_bodies"] = {{"count", escaped.size()}, {"kinetic", k},
                         {"magnetic_work", w_mag}, {"contact_work", w_c},
                         {"magnetic_work_in", w_mag_in}, {"contact_work_in", w_c_in}};
  j["kinetic"] = e.kinetic;
  j["gravitational"] = e.gravitational;
  j["initial_kinetic"] = e.initial_kinetic;
  j["initial_gravitational"] = e.initial_gravitational;
  j["magnetic_energy"] = e.magnetic_energy;
  // E = K + U_g + U*, what the steps created and dissipated of it (energy.hpp)
  j["total"] = engine::total_energy(e);
  j["initial_total"] = e.initial_total;
  j["created"] = e.total.energy_created;
  j["dissipated"] = e.total.energy_dissipated;
  const engine::SimOptions& o = sim.model().options;
  const bool conservative = sim.model().resolved.force_has_energy;
  j["conservative"] = conservative;
  j["guard"] = {{"enabled", o.energy_guard && conservative},
                {"available", conservative},
                {"note", conservative ? "" : "unavailable: eq. 4 (zeeman) is not the gradient of any energy"},
                {"tolerance", o.energy_guard_tolerance},
                {"floor", o.energy_guard_floor},
                {"max_substeps", o.energy_guard_max_substeps},
                {"retakes", e.guard_retakes},
                {"unresolved", e.guard_unresolved}};
  j["substeps"] = e.substeps;
  j["last_step"] = energy_flow_json(e.last);
  return j;
}


}  // namespace magsim::scene_tool
