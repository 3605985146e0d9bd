// Tests for magsim-scene --gltf (tools/gltf/gltf_writer.hpp): the file read back with tinygltf
// has the node, mesh and channel counts of the scene, one key accessor at the times of
// states.csv, translations equal to states.csv's, and the exit codes of a bad path, a failed
// run and a file above glTF's 4 GiB.
#include "tests/tools/cli/run_command.hpp"
#include "tools/gltf/gltf_meshes.hpp"

#include <catch2/catch.hpp>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using magsim::test::CommandResult;
using magsim::test::scratch;

CommandResult run_scene(const std::string& args) { return magsim::test::run_command(MAGSIM_SCENE_BIN, args); }

struct Row {
  int frame, body;
  double t, x, y, z;
};

// states.csv of the scenes here: no quoted names
std::vector<Row> read_states(const std::string& path) {
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);
  std::vector<Row> rows;
  while (std::getline(f, line)) {
    std::stringstream s(line);
    std::string cell[11];
    for (std::string& c : cell) std::getline(s, c, ',');
    rows.push_back({std::stoi(cell[0]), std::stoi(cell[2]), std::stod(cell[1]), std::stod(cell[4]), std::stod(cell[5]),
                    std::stod(cell[6])});
  }
  return rows;
}

tinygltf::Model load(const std::string& path) {
  tinygltf::Model m;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const bool ok = loader.LoadBinaryFromFile(&m, &err, &warn, path);
  INFO(err << warn);
  REQUIRE(ok);
  return m;
}

// accessor i's floats
std::vector<float> floats(const tinygltf::Model& m, int i) {
  const tinygltf::Accessor& a = m.accessors[i];
  const tinygltf::BufferView& v = m.bufferViews[a.bufferView];
  REQUIRE(a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT);
  const int width = a.type == TINYGLTF_TYPE_SCALAR ? 1 : a.type == TINYGLTF_TYPE_VEC3 ? 3 : 4;
  std::vector<float> out(a.count * width);
  std::memcpy(out.data(), m.buffers[v.buffer].data.data() + v.byteOffset + a.byteOffset, out.size() * 4);
  return out;
}

std::set<std::string> names_in(const std::string& dir) {
  std::set<std::string> n;
  for (const auto& e : fs::directory_iterator(dir)) n.insert(e.path().filename().string());
  return n;
}

}  // namespace

TEST_CASE("magsim-scene --gltf: counts, key times and translations against states.csv", "[tools][gltf]") {
  const std::string out = scratch("gltf_two"), glb = scratch("gltf_two/two.glb");
  const CommandResult r = run_scene(std::string(MAGSIM_SOURCE_DIR) + "/scenes/examples/two_balls.json --seconds 0.3 "
                                    "--no-render --out " + out + " --gltf " + glb + " --gltf-channels m_norm,speed");
  INFO(r.out);
  REQUIRE(r.code == 0);
  const tinygltf::Model m = load(glb);
  const std::vector<Row> rows = read_states(out + "/states.csv");
  // 3 bodies (a static magnet, two balls) with a shape and a channel node each, ground, camera
  CHECK(m.nodes.size() == 3 + 3 + 3 + 1 + 1);
  CHECK(m.meshes.size() == 3);  // the box, one sphere for both balls, the ground
  REQUIRE(m.animations.size() == 1);
  const tinygltf::Animation& anim = m.animations[0];
  CHECK(anim.channels.size() == 2 * 2 + 3);  // translation + rotation per ball, a scale per body
  std::set<int> inputs;
  for (const tinygltf::AnimationSampler& s : anim.samplers) {
    inputs.insert(s.input);
    CHECK(s.interpolation == "LINEAR");
  }
  REQUIRE(inputs.size() == 1);  // one time accessor
  const std::vector<float> keys = floats(m, *inputs.begin());
  std::map<int, double> time_of;
  for (const Row& row : rows) time_of[row.frame] = row.t;
  REQUIRE(keys.size() == time_of.size());
  for (const auto& [f, t] : time_of) CHECK(keys[f] == static_cast<float>(t));
  // the translations, back in magsim's axes: glTF (x, y, z) = magsim (x, z, −y)
  int checked = 0;
  for (const tinygltf::AnimationChannel& c : anim.channels) {
    if (c.target_path != "translation") continue;
    const int body = c.target_node;  // node b is body b
    REQUIRE(m.nodes[body].extras.Get("magsim_body").GetNumberAsInt() == body);
    const std::vector<float> v = floats(m, anim.samplers[c.sampler].output);
    for (const Row& row : rows) {
      if (row.body != body) continue;
      CHECK(std::abs(v[3 * row.frame] - row.x) <= 1e-6);
      CHECK(std::abs(-v[3 * row.frame + 2] - row.y) <= 1e-6);
      CHECK(std::abs(v[3 * row.frame + 1] - row.z) <= 1e-6);
      ++checked;
    }
  }
  CHECK(checked == 2 * static_cast<int>(time_of.size()));
  // the magnet's extras; its m_norm channel is its moment, 1 A·m², and it does not move
  const tinygltf::Value& ex = m.nodes[0].extras;
  CHECK(ex.Get("type").Get<std::string>() == "static");
  CHECK(ex.Get("moment").Get(2).GetNumberAsDouble() == 1.0);
  CHECK(m.asset.extras.Get("complete").Get<bool>());
  CHECK(m.asset.extras.Get("frames").GetNumberAsInt() == static_cast<int>(time_of.size()));
}

TEST_CASE("magsim-scene --gltf: balls share one mesh, letters are nodes of boxes", "[tools][gltf]") {
  const std::string glb = scratch("gltf_balls.glb");
  REQUIRE(run_scene("balls_up --count 40 --steps 20 --no-render --out " + scratch("gltf_balls") + " --gltf " + glb).code == 0);
  const tinygltf::Model m = load(glb);
  CHECK(m.meshes.size() == 3);            // ball, magnet, ground
  CHECK(m.nodes.size() == 41 + 41 + 2);   // bodies, their shapes, ground and camera
  CHECK(m.animations[0].channels.size() == 2 * 40);
  const std::string letters = scratch("gltf_letters.glb");
  REQUIRE(run_scene("alphabets --count 4 --steps 20 --no-render --out " + scratch("gltf_letters") + " --gltf " + letters).code == 0);
  const tinygltf::Model a = load(letters);
  std::size_t shapes = 0;
  for (int b = 0; b < 5; ++b) shapes += a.nodes[b].children.size();
  CHECK(shapes > 4);  // a letter is several boxes
  CHECK(a.nodes.size() == 5 + shapes + 1);  // no ground in alphabets: bodies, shapes, camera
}

TEST_CASE("magsim-scene --gltf: an unwritable path is exit 3 and leaves no file", "[tools][gltf]") {
  const std::string dir = scratch("gltf_unwritable");
  fs::create_directories(dir);
  std::ofstream(dir + "/plain_file") << "x";
  const std::set<std::string> before = names_in(dir);
  const CommandResult r = run_scene("balls_up --count 5 --steps 5 --no-render --out " + dir + "/out --gltf " + dir +
                                    "/plain_file/run.glb");
  INFO(r.out);
  CHECK(r.code == 3);
  CHECK(r.out.find("--gltf") != std::string::npos);
  std::set<std::string> after = names_in(dir);
  after.erase("out");  // --out's folder, made before
  CHECK(after == before);
  // a folder where the file should be is bad input: exit 1
  fs::create_directories(dir + "/folder.glb");
  CHECK(run_scene("balls_up --count 5 --steps 5 --no-render --out " + dir + "/out --gltf " + dir + "/folder.glb").code == 1);
  CHECK(run_scene("balls_up --steps 5 --no-render --out " + dir + "/out --gltf " + dir + "/x.gltf").code == 1);
  CHECK(run_scene("balls_up --steps 5 --no-render --out " + dir + "/out --gltf-channels speed").code == 1);
  CHECK(run_scene("balls_up --steps 5 --no-render --out " + dir + "/out --gltf " + dir + "/y.glb --gltf-channels mass").code == 1);
}

TEST_CASE("magsim-scene --gltf: a failed run writes the frames it has, with its error", "[tools][gltf]") {
  const std::string out = scratch("gltf_blow"), glb = scratch("gltf_blow.glb");
  const CommandResult r = run_scene(std::string(MAGSIM_SOURCE_DIR) + "/tests/tools/cli/inputs/blow_up.json --steps 50 "
                                    "--no-render --out " + out + " --gltf " + glb);
  INFO(r.out);
  REQUIRE(r.code == 2);
  const tinygltf::Model m = load(glb);
  const tinygltf::Value& ex = m.asset.extras;
  REQUIRE(ex.Get("error").IsString());
  CHECK(!ex.Get("error").Get<std::string>().empty());
  CHECK(!ex.Get("complete").Get<bool>());
  std::set<int> frames;
  for (const Row& row : read_states(out + "/states.csv")) frames.insert(row.frame);
  CHECK(ex.Get("frames").GetNumberAsInt() == static_cast<int>(frames.size()));
  CHECK(m.accessors[m.animations[0].samplers[0].input].count == frames.size());
}

TEST_CASE("magsim-scene --gltf: a file above glTF's 4 GiB is refused before the run", "[tools][gltf]") {
  const std::string glb = scratch("gltf_huge.glb");
  // 20,000 balls × 100,002 frames × 28 bytes: 56 GB
  const CommandResult r = run_scene("balls_up --count 20000 --steps 100000 --fps 1000 --no-render --out " +
                                    scratch("gltf_huge") + " --gltf " + glb);
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("4 GiB") != std::string::npos);
  CHECK(r.out.find("100002 frames") != std::string::npos);
  CHECK(!fs::exists(glb));
}

TEST_CASE("glTF meshes: triangles face outwards, normals are unit and the axes are y-up", "[tools][gltf]") {
  using magsim::gltf::ShapeKind;
  using magsim::gltf::Vec3;
  const struct {
    ShapeKind kind;
    Vec3 size;
  } shapes[] = {{ShapeKind::Sphere, Vec3(0.005, 0, 0)}, {ShapeKind::Box, Vec3(0.01, 0.02, 0.03)},
                {ShapeKind::Capsule, Vec3(0.01, 0.04, 0)}, {ShapeKind::Cylinder, Vec3(0.02, 0.01, 0)}};
  for (const auto& sh : shapes) {
    const magsim::gltf::MeshData m = magsim::gltf::shape_mesh(sh.kind, sh.size);
    INFO(magsim::gltf::shape_kind_name(sh.kind));
    REQUIRE(m.indices.size() % 3 == 0);
    auto at = [&](const std::vector<float>& v, std::uint32_t i) { return Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]); };
    int inward = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
      const Vec3 a = at(m.positions, m.indices[t]), b = at(m.positions, m.indices[t + 1]), c = at(m.positions, m.indices[t + 2]);
      const Vec3 n = (b - a).cross(c - a);
      const Vec3 mean_normal = at(m.normals, m.indices[t]) + at(m.normals, m.indices[t + 1]) + at(m.normals, m.indices[t + 2]);
      if (n.norm() > 0 && n.dot(mean_normal) <= 0) ++inward;
    }
    CHECK(inward == 0);
    for (std::size_t i = 0; i < m.vertices(); ++i) CHECK(std::abs(at(m.normals, static_cast<std::uint32_t>(i)).norm() - 1) < 1e-6);
  }
  // a capsule along magsim's z lies along glTF's −y: its extent in y is 2 (r + half length)
  const magsim::gltf::MeshData cap = magsim::gltf::shape_mesh(ShapeKind::Capsule, Vec3(0.01, 0.04, 0));
  float lo = 0, hi = 0;
  for (std::size_t i = 0; i < cap.vertices(); ++i) {
    lo = std::min(lo, cap.positions[3 * i + 1]);
    hi = std::max(hi, cap.positions[3 * i + 1]);
  }
  CHECK(hi - lo == Approx(0.1).epsilon(1e-6));
}
