// tools/python/state.cpp — magsim.State and its pickle (state.hpp).
#include "tools/python/state.hpp"

#include "scenes/scene_file.hpp"
#include "tools/python/common.hpp"

#include <pybind11/stl.h>

#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <type_traits>

namespace magsim::python {

namespace {

constexpr char kMagic[8] = {'m', 'a', 'g', 's', 't', '0', '0', '2'};

// Plain bytes of trivially copyable values and of vectors of them (Vec3 and Quat are
// fixed-size Eigen types of plain doubles).
struct Writer {
  std::string out;
  void put(const engine::Vec3& v) {
    for (int i = 0; i < 3; ++i) put(v[i]);
  }
  void put(const engine::Quat& q) {
    for (int i = 0; i < 4; ++i) put(q.coeffs()[i]);
  }
  void put(const std::pair<int, int>& p) {
    put(p.first);
    put(p.second);
  }
  template <class T>
  void put(const T& x) {
    static_assert(std::is_trivially_copyable_v<T>);
    out.append(reinterpret_cast<const char*>(&x), sizeof x);
  }
  template <class T>
  void put(const std::vector<T>& v) {
    put(static_cast<std::uint64_t>(v.size()));
    for (const T& x : v) put(x);
  }
};

struct Reader {
  const std::string& in;
  std::size_t at = 0;
  void get(engine::Vec3* v) {
    for (int i = 0; i < 3; ++i) get(&(*v)[i]);
  }
  void get(engine::Quat* q) {
    for (int i = 0; i < 4; ++i) get(&q->coeffs()[i]);
  }
  void get(std::pair<int, int>* p) {
    get(&p->first);
    get(&p->second);
  }
  template <class T>
  void get(T* x) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (in.size() - at < sizeof(T)) throw std::invalid_argument("magsim.State: truncated bytes");
    std::memcpy(static_cast<void*>(x), in.data() + at, sizeof(T));
    at += sizeof(T);
  }
  template <class T>
  void get(std::vector<T>* v) {
    std::uint64_t n = 0;
    get(&n);
    if (n > in.size() - at) throw std::invalid_argument("magsim.State: truncated bytes");
    v->resize(n);
    for (T& x : *v) get(&x);
  }
};

// every member of engine::State, in its declaration order
template <class IO, class S>
void fields(IO& io, S& s) {
  auto f = [&io](auto& x) {
    if constexpr (std::is_same_v<IO, Writer>) io.put(x);
    else io.get(&x);
  };
  // a comma fold runs left to right: the bytes keep this order
  auto each = [&f](auto&... x) { (f(x), ...); };
  each(s.step, s.pos, s.quat, s.vel, s.angvel, s.enabled, s.mag.M1, s.mag.M2, s.mag.M, s.mag.seeded,
       s.contact_pairs, s.dvel, s.mag_accel, s.contact_depth, s.eddy.B, s.eddy.h, s.still_time,
       s.still_vel, s.still_angvel, s.sleep_island, s.H_sleep, s.magnetized);
}

}  // namespace

std::uint64_t scene_fingerprint(const engine::SceneDesc& scene) {
  const std::string text = scenes::scene_to_json(scene)["bodies"].dump();
  std::uint64_t h = 1469598103934665603ull;
  for (const char c : text) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  return h;
}

std::string to_bytes(const State& st) {
  Writer w;
  w.out.append(kMagic, sizeof kMagic);
  w.put(st.fingerprint);
  fields(w, st.s);
  return w.out;
}

State from_bytes(const std::string& b) {
  if (b.size() < sizeof kMagic || std::memcmp(b.data(), kMagic, sizeof kMagic) != 0)
    throw std::invalid_argument("magsim.State: not a state's bytes");
  Reader r{b, sizeof kMagic};
  State st;
  r.get(&st.fingerprint);
  fields(r, st.s);
  if (r.at != b.size()) throw std::invalid_argument("magsim.State: trailing bytes");
  return st;
}

void bind_state(py::module_& m) {
  py::class_<State>(m, "State",
                    "A copy of a simulation's whole state (Simulation.get_state); set_state restores it exactly, "
                    "pickle keeps it.")
      .def_property_readonly("steps", [](const State& st) { return st.s.step; })
      .def_property_readonly("nbody", [](const State& st) { return st.s.pos.size(); })
      .def("state_hash", [](const State& st) { return engine::state_hash(st.s); },
           "The hash of Simulation.state_hash() at this state.")
      .def(py::pickle([](const State& st) { return py::bytes(to_bytes(st)); },
                      [](const py::bytes& b) {
                        try {
                          return from_bytes(std::string(b));
                        } catch (const std::invalid_argument& e) {
                          raise_builtin(PyExc_ValueError, e.what());
                        }
                      }))
      .def("__repr__", [](const State& st) {
        char h[19];
        std::snprintf(h, sizeof h, "%016" PRIx64, engine::state_hash(st.s));
        return "<magsim.State step " + std::to_string(st.s.step) + ", hash " + h + ">";
      });
}

}  // namespace magsim::python
