// tools/paper/common.cpp — the helpers every experiment shares (experiments.hpp).
#include "tools/paper/experiments.hpp"

#include <algorithm>
#include <filesystem>
#include <sstream>

namespace magsim::experiments {

std::vector<mag::Method> dynamics_methods() {
  std::vector<mag::Method> v = {mag::Method::Ours, mag::Method::OursRealigned,
                                mag::Method::Kim2018, mag::Method::DampingLLG};
  mag::Method a;
  if (mag::parse_method("anderson", &a)) v.push_back(a);
  return v;
}

std::vector<mag::Method> parse_methods(const std::string& list) {
  if (list == "all") return dynamics_methods();
  std::vector<mag::Method> v;
  std::stringstream ss(list);
  std::string name;
  while (std::getline(ss, name, ',')) {
    mag::Method m;
    if (!mag::parse_method(name, &m)) throw CLI::ValidationError("--methods", mag::kMethodNames.unknown("method", name));
    v.push_back(m);
  }
  return v;
}

/// Options that run exactly `iters` sweeps of method m (tol unreachable: the window is
/// fixed, e_M is what the experiments record).
mag::DynamicsOptions window(mag::Method m, int iters, double dt) {
  mag::DynamicsOptions d;
  d.method = m;
  d.dt = dt;
  d.max_iter = iters;
  d.tol = 1e-300;
  return d;
}

mag::MomentSet crystal(double strength) {
  magsim::scenes::SceneParams p;
  p.strength = strength;
  return magsim::scenes::moment_set_at_rest(magsim::scenes::find_scene("crystal_balls")->build(p));
}

void ensure_dir(const std::string& d) {
  std::error_code ec;
  std::filesystem::create_directories(d, ec);
  if (ec) throw std::runtime_error("cannot create " + d + ": " + ec.message());
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::vector<double> parse_doubles(const std::string& list, const std::string& flag) {
  std::vector<double> v;
  std::stringstream ss(list);
  std::string x;
  while (std::getline(ss, x, ',')) {
    try {
      v.push_back(std::stod(x));
    } catch (const std::exception&) {
      throw CLI::ValidationError(flag, "not a number: " + x);
    }
  }
  return v;
}

RelativeDifference relative_difference(const mag::MomentSet& kinds, const std::vector<Vec3>& ref,
                                       const std::vector<Vec3>& other) {
  double sum = 0, mx = 0;
  int n = 0;
  for (std::size_t j = 0; j < kinds.size(); ++j) {
    if (kinds.kind[j] != mag::MomentKind::Induced) continue;
    const double d = (ref[j] - other[j]).norm() / ref[j].norm();
    sum += d;
    mx = std::max(mx, d);
    ++n;
  }
  return {sum / n, mx};
}

std::vector<SpeedRun> method_runs(const std::vector<mag::Method>& methods, int iters,
                                  const mag::FieldOptions& field) {
  std::vector<SpeedRun> v;
  for (mag::Method m : methods) {
    SpeedRun r{mag::method_name(m), window(m, iters)};
    r.opt.field = field;
    v.push_back(r);
  }
  return v;
}

std::map<std::string, double> speed_curves(std::ostream& csv, const std::string& label,
                                           const mag::MomentSet& start,
                                           const std::vector<SpeedRun>& runs,
                                           const std::vector<Vec3>& gt_tanh,
                                           const std::vector<Vec3>& gt_kim, int repeat) {
  std::map<std::string, double> out;
  for (const SpeedRun& r : runs) {
    const auto& gt = mag::curve_of(r.opt.method) == mag::Curve::Kim ? gt_kim : gt_tanh;
    std::vector<double> per_sweep;
    for (int k = 0; k < repeat; ++k) {
      mag::MomentSet s = start;
      mag::MagWorkspace ws;
      const auto t0 = Clock::now();
      const mag::RelaxStats st = mag::relax_magnetization(&s, r.opt, &ws);
      per_sweep.push_back(ms_since(t0) / std::max(1, st.iterations));
    }
    const double sweep_ms = median(per_sweep);
    mag::MomentSet s = start;
    mag::MagWorkspace ws;
    mag::relax_magnetization(&s, r.opt, &ws, [&](int k, const mag::MomentSet& cur) {
      csv << label << ',' << r.name << ',' << k << ',' << k * sweep_ms << ','
          << mag::magnetization_error(cur, gt) << '\n';
    });
    std::printf("speed %-11s %-22s %.4f ms per sweep\n", label.c_str(), r.name.c_str(), sweep_ms);
    out[r.name] = sweep_ms;
  }
  return out;
}

NewtonTrace newton_trace(const mag::MomentSet& start, mag::Curve curve,
                         const mag::FieldOptions& field, int repeat, double tol) {
  NewtonTrace tr;
  std::vector<std::vector<double>> step_ms;
  for (int r = 0; r < repeat; ++r) {
    mag::MomentSet s = start;
    for (int k = 0; k < 60; ++k) {
      const auto t0 = Clock::now();
      const mag::ExactStats st = mag::solve_exact(&s, curve, field, 0.0, 1);
      if (static_cast<int>(step_ms.size()) <= k) step_ms.emplace_back();
      step_ms[k].push_back(ms_since(t0));
      if (r == 0) tr.iterate.push_back(s.M);
      if (st.residual <= tol) {
        tr.converged = true;
        break;
      }
    }
    if (r == 0) tr.solution = s;
  }
  double cum = 0;
  for (std::size_t k = 0; k < tr.iterate.size(); ++k) tr.ms.push_back(cum += median(step_ms[k]));
  return tr;
}

void newton_rows(std::ostream& csv, const std::string& label, const NewtonTrace& tr,
                 const std::vector<Vec3>& gt) {
  mag::MomentSet s = tr.solution;
  for (std::size_t k = 0; k < tr.iterate.size(); ++k) {
    s.M = tr.iterate[k];
    csv << label << ",exact," << -1 << ',' << tr.ms[k] << ',' << mag::magnetization_error(s, gt)
        << '\n';
  }
}

}  // namespace magsim::experiments
