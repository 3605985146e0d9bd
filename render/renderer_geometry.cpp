// render/renderer_geometry.cpp — what the renderer draws: the unit meshes and the sphere
// impostor quad (made once), and per frame the instance arrays gathered from the Frame,
// the spheres' back-to-front order with the hidden ones left out, and their upload.
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "render/renderer_impl.hpp"

namespace magsim::render {

namespace {

constexpr int kCylinderSegments = 40;
constexpr int kConeSegments = 32;

void push_mesh_instance(std::vector<float>& out, const Eigen::Vector3f& p,
                        const Eigen::Quaternionf& q, const Eigen::Vector3f& s, const Color& c) {
  out.insert(out.end(), {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w(), s.x(), s.y(), s.z(),
                         c.r, c.g, c.b});
}

void push_sphere_instance(std::vector<float>& out, const Eigen::Vector3f& p, float r,
                          const Color& c) {
  out.insert(out.end(), {p.x(), p.y(), p.z(), r, c.r, c.g, c.b, 1.0f});
}

}  // namespace

GpuMesh Renderer::Impl::upload_mesh(const Mesh& mesh) {
  GpuMesh g;
  g.index_count = GLsizei(mesh.indices.size());
  glGenVertexArrays(1, &g.vao);
  glBindVertexArray(g.vao);
  glGenBuffers(1, &g.vbo);
  glBindBuffer(GL_ARRAY_BUFFER, g.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.vertices.size() * sizeof(float)),
               mesh.vertices.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                        reinterpret_cast<const void*>(3 * sizeof(float)));
  glGenBuffers(1, &g.ibo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.ibo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.indices.size() * sizeof(std::uint32_t)),
               mesh.indices.data(), GL_STATIC_DRAW);
  glGenBuffers(1, &g.instances);
  glBindBuffer(GL_ARRAY_BUFFER, g.instances);
  const GLsizei stride = kMeshInstanceFloats * sizeof(float);
  const int sizes[4] = {3, 4, 3, 3};
  std::size_t offset = 0;
  for (int a = 0; a < 4; ++a) {
    glEnableVertexAttribArray(GLuint(2 + a));
    glVertexAttribPointer(GLuint(2 + a), sizes[a], GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(offset * sizeof(float)));
    glVertexAttribDivisor(GLuint(2 + a), 1);
    offset += std::size_t(sizes[a]);
  }
  glBindVertexArray(0);
  return g;
}

void Renderer::Impl::create_geometry() {
  box = upload_mesh(unit_box());
  cylinder = upload_mesh(unit_cylinder(kCylinderSegments));
  cone = upload_mesh(unit_cone(kConeSegments));

  // impostor quad (triangle strip) + per-sphere instance data, in two VAOs. (An octagon
  // would shade a fifth fewer fragments but made 10k-ball frames 25 % slower: llvmpipe's
  // per-triangle set-up costs more than the discarded corners.)
  const float quad[8] = {-1, -1, 1, -1, -1, 1, 1, 1};
  glGenBuffers(1, &quad_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, quad_vbo);
  glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
  glGenBuffers(1, &sphere_instances);
  glGenBuffers(1, &sphere_instances_all);
  for (auto [vao, instances] : {std::pair<GLuint*, GLuint>{&sphere_vao, sphere_instances},
                                std::pair<GLuint*, GLuint>{&sphere_vao_all, sphere_instances_all}}) {
    glGenVertexArrays(1, vao);
    glBindVertexArray(*vao);
    glBindBuffer(GL_ARRAY_BUFFER, quad_vbo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
    glBindBuffer(GL_ARRAY_BUFFER, instances);
    const GLsizei stride = kSphereInstanceFloats * sizeof(float);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, stride, nullptr);
    glVertexAttribDivisor(1, 1);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(4 * sizeof(float)));
    glVertexAttribDivisor(2, 1);
  }

  // the ground: world x, y of its triangles, rebuilt every frame
  glGenVertexArrays(1, &ground_vao);
  glBindVertexArray(ground_vao);
  glGenBuffers(1, &ground_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, ground_vbo);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
  glBindVertexArray(0);
}

// Frame → instance arrays. Capsules are a cylinder plus two sphere impostors (exact round
// caps); arrows are a cylinder shaft plus a cone head.
void Renderer::Impl::gather(const Frame& frame) {
  spheres.clear();
  boxes.clear();
  cylinders.clear();
  cones.clear();
  for (const Shape& s : frame.shapes) {
    const Eigen::Quaternionf q = s.orientation.normalized();
    switch (s.type) {
      case ShapeType::Sphere:
        push_sphere_instance(spheres, s.position, s.size.x(), s.color);
        break;
      case ShapeType::Box:
        push_mesh_instance(boxes, s.position, q, s.size, s.color);
        break;
      case ShapeType::Cylinder:
        push_mesh_instance(cylinders, s.position, q,
                           Eigen::Vector3f(s.size.x(), s.size.x(), s.size.y()), s.color);
        break;
      case ShapeType::Capsule: {
        const Eigen::Vector3f axis = q * Eigen::Vector3f(0.0f, 0.0f, s.size.y());
        push_mesh_instance(cylinders, s.position, q,
                           Eigen::Vector3f(s.size.x(), s.size.x(), s.size.y()), s.color);
        push_sphere_instance(spheres, s.position + axis, s.size.x(), s.color);
        push_sphere_instance(spheres, s.position - axis, s.size.x(), s.color);
        break;
      }
    }
  }
  for (const Arrow& a : frame.arrows) {
    const float len = a.vec.norm();
    if (len <= 0.0f) continue;
    const Eigen::Vector3f dir = a.vec / len;
    const float r = a.radius > 0.0f ? a.radius : 0.04f * len;
    const float head_r = 2.2f * r;
    const float head_len = std::min(0.45f * len, 5.0f * r);
    const float shaft_len = len - head_len;
    const Eigen::Quaternionf q = Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), dir);
    push_mesh_instance(cylinders, a.origin + 0.5f * shaft_len * dir, q,
                       Eigen::Vector3f(r, r, 0.5f * shaft_len), a.color);
    push_mesh_instance(cones, a.origin + shaft_len * dir, q,
                       Eigen::Vector3f(head_r, head_r, head_len), a.color);
  }
}

// Back to front by the power of the eye with respect to each sphere, |c − e|² − r²: for
// disjoint spheres this is a valid visibility order, so blending the edges in this order
// composites them correctly. Spheres certainly hidden behind others are left out; the
// others get their ambient-occlusion factor.
void Renderer::Impl::sort_spheres(const Frame& frame) {
  const Eigen::Vector3f& eye = frame.camera.eye;
  const std::size_t n = spheres.size() / kSphereInstanceFloats;
  sphere_order.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float* s = &spheres[i * kSphereInstanceFloats];
    const float dx = s[0] - eye.x(), dy = s[1] - eye.y(), dz = s[2] - eye.z();
    sphere_order[i] = {dx * dx + dy * dy + dz * dz - s[3] * s[3], std::uint32_t(i)};
  }
  std::sort(sphere_order.begin(), sphere_order.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  front_to_back.resize(n);
  for (std::size_t k = 0; k < n; ++k) front_to_back[k] = sphere_order[n - 1 - k].second;
  camera_occlusion.run_perspective(spheres.data(), kSphereInstanceFloats, front_to_back, eye,
                                   view, frame.camera.fov_y_deg, rw, rh, 4, &sphere_visible);
  ambient_occlusion.run(spheres.data(), kSphereInstanceFloats, n, 7, sphere_visible.data());
  sorted_spheres.clear();
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t i = sphere_order[k].second;
    if (!sphere_visible[i]) continue;
    const float* s = &spheres[std::size_t(i) * kSphereInstanceFloats];
    sorted_spheres.insert(sorted_spheres.end(), s, s + kSphereInstanceFloats);
  }
}

void Renderer::Impl::upload_instances() {
  auto upload = [](GLuint buffer, const std::vector<float>& data) {
    glBindBuffer(GL_ARRAY_BUFFER, buffer);
    // orphan the old storage so the driver need not wait for the last frame
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)),
                 data.empty() ? nullptr : data.data(), GL_STREAM_DRAW);
  };
  upload(sphere_instances, sorted_spheres);
  upload(sphere_instances_all, spheres);
  upload(box.instances, boxes);
  upload(cylinder.instances, cylinders);
  upload(cone.instances, cones);
  upload(ground_vbo, ground);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

InstanceCounts Renderer::Impl::count_instances(const Frame& frame) const {
  InstanceCounts n;
  n.spheres = GLsizei(spheres.size() / kSphereInstanceFloats);
  n.visible = GLsizei(sorted_spheres.size() / kSphereInstanceFloats);
  n.boxes = GLsizei(boxes.size() / kMeshInstanceFloats);
  n.cylinders = GLsizei(cylinders.size() / kMeshInstanceFloats);
  n.cones = GLsizei(cones.size() / kMeshInstanceFloats);
  n.meshes = n.boxes + n.cylinders + n.cones;
  n.shadows = frame.shadows && n.spheres + n.meshes > 0;
  return n;
}

}  // namespace magsim::render
