#include "render/scene_renderer.h"

#include <cmath>
#include <utility>

namespace softtled {

namespace {
// Unit tangents (t1, t2) with t1 x t2 = n; t1 follows +x where it can, so the slope's
// grid turns with it.
void plane_basis(Vec3 n, Vec3& t1, Vec3& t2) {
  Vec3 ref = std::fabs(n.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 0, 1};
  t1 = normalize(ref - n * dot(ref, n));
  t2 = cross(n, t1);
  t2 = t2 * -1.f;  // right-handed (t1, n, t2) like (x, y, z) for the floor
}

constexpr float kTwoPi = 6.28318530717958647692f;

void push_vertex(std::vector<float>& out, Vec3 p, Vec3 n) {
  const float v[kBodyFloatsPerVertex] = {p.x, p.y, p.z, n.x, n.y, n.z, 0.f, 0.f};
  out.insert(out.end(), v, v + kBodyFloatsPerVertex);
}

// Unit vectors u, v with (u, v, w) orthonormal.
void basis_of(Vec3 w, Vec3& u, Vec3& v) {
  const Vec3 ref = std::fabs(w.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  u = normalize(cross(w, ref));
  v = cross(w, u);
}

// A band of quads between rings of points around axis w: ring k has centre c[k] and
// polar angle theta[k] (from +w), radius r; normals point away from the ring's centre.
void rings(const std::vector<Vec3>& c, const std::vector<float>& theta, float r, Vec3 w, std::vector<float>& out) {
  constexpr int kSlices = 32;
  Vec3 u, v;
  basis_of(w, u, v);
  auto normal = [&](int k, int j) {
    const float phi = kTwoPi * float(j) / kSlices;
    return w * std::cos(theta[k]) + (u * std::cos(phi) + v * std::sin(phi)) * std::sin(theta[k]);
  };
  for (std::size_t k = 0; k + 1 < c.size(); ++k)
    for (int j = 0; j < kSlices; ++j) {
      const Vec3 n00 = normal(int(k), j), n01 = normal(int(k), j + 1), n10 = normal(int(k) + 1, j),
                 n11 = normal(int(k) + 1, j + 1);
      const Vec3 p00 = c[k] + n00 * r, p01 = c[k] + n01 * r, p10 = c[k + 1] + n10 * r, p11 = c[k + 1] + n11 * r;
      push_vertex(out, p00, n00), push_vertex(out, p10, n10), push_vertex(out, p11, n11);
      push_vertex(out, p00, n00), push_vertex(out, p11, n11), push_vertex(out, p01, n01);
    }
}
}  // namespace

void obstacle_triangles(const RenderObstacle& o, std::vector<float>& out) {
  constexpr int kStacks = 16;  // per full sphere; a capsule's cap has half of them
  std::vector<Vec3> c;
  std::vector<float> theta;
  auto world = [&](Vec3 q) {  // R q
    return Vec3{o.R[0] * q.x + o.R[1] * q.y + o.R[2] * q.z, o.R[3] * q.x + o.R[4] * q.y + o.R[5] * q.z,
                o.R[6] * q.x + o.R[7] * q.y + o.R[8] * q.z};
  };
  if (o.shape == RenderObstacle::Shape::kMesh) {  // flat-shaded: the collision surface as it is
    if (!o.triangles) return;
    const std::vector<float>& t = *o.triangles;
    for (std::size_t f = 0; f + 9 <= t.size(); f += 9) {
      const Vec3 p[3] = {world(Vec3{t[f], t[f + 1], t[f + 2]}), world(Vec3{t[f + 3], t[f + 4], t[f + 5]}),
                         world(Vec3{t[f + 6], t[f + 7], t[f + 8]})};
      const Vec3 n = normalize(cross(p[1] - p[0], p[2] - p[0]));
      for (const Vec3& q : p) push_vertex(out, o.center + q, n);
    }
    return;
  }
  if (o.shape == RenderObstacle::Shape::kBox) {
    for (int axis = 0; axis < 3; ++axis)
      for (float side : {-1.f, 1.f}) {
        Vec3 n{0, 0, 0}, a{0, 0, 0}, b{0, 0, 0};
        n[axis] = side;
        a[(axis + 1) % 3] = o.half[(axis + 1) % 3];
        b[(axis + 2) % 3] = o.half[(axis + 2) % 3];
        if (side < 0) std::swap(a, b);  // counter-clockwise seen from outside
        const Vec3 f = n * o.half[axis];
        const Vec3 q[4] = {f - a - b, f + a - b, f + a + b, f - a + b};
        const Vec3 wn = world(n);
        for (int t : {0, 1, 2, 0, 2, 3}) push_vertex(out, o.center + world(q[t]), wn);
      }
    return;
  }
  if (o.shape == RenderObstacle::Shape::kSphere) {
    for (int k = 0; k <= kStacks; ++k) {
      c.push_back(o.center);
      theta.push_back(0.5f * kTwoPi * float(k) / kStacks);
    }
    rings(c, theta, o.radius, Vec3{0, 1, 0}, out);
    return;
  }
  // Capsule: the cap around b (polar angles 0..90 degrees from the axis a -> b), the
  // cylinder between the two equators, the cap around a (90..180 degrees).
  const Vec3 ab = o.b - o.center;
  const Vec3 w = length(ab) > 0 ? normalize(ab) : Vec3{0, 1, 0};
  for (int k = 0; k <= kStacks / 2; ++k) c.push_back(o.b), theta.push_back(0.5f * kTwoPi * float(k) / kStacks);
  for (int k = kStacks / 2; k <= kStacks; ++k) c.push_back(o.center), theta.push_back(0.5f * kTwoPi * float(k) / kStacks);
  rings(c, theta, o.radius, w, out);
}

SceneRenderer::SceneRenderer()
    : body_("body.vert", "body.frag"),
      flat_("body.vert", "flat.frag"),
      plane_("plane.vert", "plane.frag"),
      background_("background.vert", "background.frag"),
      line_flat_("line.vert", "flat.frag") {
  const float quad[] = {-1, -1, 1, -1, 1, 1, -1, -1, 1, 1, -1, 1};
  glGenVertexArrays(1, &quad_vao_);
  glBindVertexArray(quad_vao_);
  glGenBuffers(1, &quad_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, quad_vbo_);
  glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  glGenVertexArrays(1, &empty_vao_);
  glGenVertexArrays(1, &line_vao_);
  glBindVertexArray(line_vao_);
  glGenBuffers(1, &line_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glGenVertexArrays(1, &obstacle_vao_);
  glBindVertexArray(obstacle_vao_);
  glGenBuffers(1, &obstacle_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, obstacle_vbo_);
  {  // the body's vertex layout (body_buffer.h), so the body's shaders draw obstacles too
    const GLsizei stride = sizeof(float) * kBodyFloatsPerVertex;
    for (int a = 0; a < 4; ++a) glEnableVertexAttribArray(GLuint(a));
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(0));
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(3 * sizeof(float)));
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(6 * sizeof(float)));
    glVertexAttribPointer(3, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(7 * sizeof(float)));
  }
  glBindVertexArray(0);
  check_gl("creating the scene renderer");
}

SceneRenderer::~SceneRenderer() {
  glDeleteBuffers(1, &quad_vbo_);
  glDeleteBuffers(1, &line_vbo_);
  glDeleteVertexArrays(1, &quad_vao_);
  glDeleteVertexArrays(1, &empty_vao_);
  glDeleteVertexArrays(1, &line_vao_);
  glDeleteBuffers(1, &obstacle_vbo_);
  glDeleteVertexArrays(1, &obstacle_vao_);
}

void SceneRenderer::draw(const Camera& cam, int w, int h, const BodyVertexBuffer& body,
                         const std::vector<RenderPlane>& planes, Vec3 focus, float plane_half, const RenderStyle& st,
                         const std::vector<OverlayLine>& lines, const std::vector<RenderObstacle>& obstacles) {
  // The obstacles' triangles for this frame (a few thousand vertices; none without obstacles).
  obstacle_verts_.clear();
  for (const RenderObstacle& o : obstacles) obstacle_triangles(o, obstacle_verts_);
  const GLsizei obstacle_nvert = GLsizei(obstacle_verts_.size() / kBodyFloatsPerVertex);
  if (obstacle_nvert > 0) {
    glBindBuffer(GL_ARRAY_BUFFER, obstacle_vbo_);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(obstacle_verts_.size() * sizeof(float)), obstacle_verts_.data(),
                 GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
  }
  auto draw_obstacles = [&] {
    if (obstacle_nvert == 0) return;
    glBindVertexArray(obstacle_vao_);
    glDrawArrays(GL_TRIANGLES, 0, obstacle_nvert);
    glBindVertexArray(0);
  };
  glViewport(0, 0, w, h);
  glClearColor(0.1f, 0.1f, 0.1f, 1.f);
  glClearStencil(0);
  glDepthMask(GL_TRUE);
  glStencilMask(0xFF);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDisable(GL_STENCIL_TEST);

  const Mat4 vp = cam.proj(float(w) / float(h > 0 ? h : 1)) * cam.view();
  const Vec3 eye = cam.eye();
  const Mat4 identity;

  // Background: no depth.
  glDisable(GL_DEPTH_TEST);
  background_.use();
  const float top[3] = {0.80f, 0.84f, 0.90f}, bottom[3] = {0.50f, 0.54f, 0.61f};
  background_.set3("u_top", top);
  background_.set3("u_bottom", bottom);
  glBindVertexArray(empty_vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);

  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);

  // Planes: each marks its visible pixels in the stencil with its index + 1.
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glEnable(GL_STENCIL_TEST);
  glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  plane_.use();
  plane_.set_mat4("u_view_proj", vp.data());
  plane_.set3("u_key_dir", st.key_dir.data());
  const float pc[3] = {0.86f, 0.86f, 0.84f}, lc[3] = {0.45f, 0.47f, 0.50f};
  plane_.set3("u_color", pc);
  plane_.set3("u_line_color", lc);
  plane_.set("u_minor", st.grid_minor);
  plane_.set("u_major", st.grid_major);
  plane_.set("u_half", plane_half);
  plane_.set("u_grid", st.grid ? 1 : 0);
  glBindVertexArray(quad_vao_);
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const Vec3 n = normalize(planes[i].normal);
    const Vec3& p0 = planes[i].point;
    Vec3 t1, t2;
    plane_basis(n, t1, t2);
    const Vec3 c = focus - n * dot(focus - p0, n);
    const float origin[2] = {dot(p0 - c, t1), dot(p0 - c, t2)};
    plane_.set3("u_center", c.data());
    plane_.set3("u_t1", t1.data());
    plane_.set3("u_t2", t2.data());
    plane_.set3("u_normal", n.data());
    glUniform2fv(plane_.loc("u_origin"), 1, origin);
    glStencilFunc(GL_ALWAYS, int(i) + 1, 0xFF);
    glDrawArrays(GL_TRIANGLES, 0, 6);
  }

  // Planar shadows: the body flattened onto each plane along the key light, drawn only
  // where that plane is the visible surface; the stencil is zeroed as it is drawn, so
  // overlapping triangles darken a pixel once.
  if (st.shadows) {
    flat_.use();
    flat_.set_mat4("u_view_proj", vp.data());
    flat_.set("u_color_mode", 0);
    const float shadow[4] = {0.05f, 0.06f, 0.09f, 0.38f};
    flat_.set4("u_color", shadow);
    glStencilOp(GL_KEEP, GL_KEEP, GL_ZERO);
    glDepthMask(GL_FALSE);
    for (std::size_t i = 0; i < planes.size(); ++i) {
      const Vec3 n = normalize(planes[i].normal);
      const Vec3& p0 = planes[i].point;
      if (dot(n, st.key_dir) < 0.05f) continue;  // light grazing or behind the plane
      // Lifted a hair above the plane so the shadow wins the depth test.
      const Mat4 m = planar_shadow(n, dot(n, p0) + 2e-5f, st.key_dir);
      flat_.set_mat4("u_model", m.data());
      glStencilFunc(GL_EQUAL, int(i) + 1, 0xFF);
      body.draw();
      draw_obstacles();
    }
    glDepthMask(GL_TRUE);
  }
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_BLEND);

  // The obstacles: the body's shader, shaded in a neutral grey-blue.
  if (obstacle_nvert > 0) {
    body_.use();
    body_.set_mat4("u_view_proj", vp.data());
    body_.set_mat4("u_model", identity.data());
    body_.set("u_color_mode", 0);
    body_.set("u_scalar_max", st.umax);
    const float grey[3] = {0.55f, 0.60f, 0.68f};
    body_.set3("u_base_color", grey);
    body_.set3("u_eye", eye.data());
    body_.set3("u_key_dir", st.key_dir.data());
    draw_obstacles();
  }

  // The body.
  body_.use();
  body_.set_mat4("u_view_proj", vp.data());
  body_.set_mat4("u_model", identity.data());
  body_.set("u_color_mode", int(st.color));
  body_.set("u_scalar_max", st.color == ColorMode::kVonMises ? st.vmmax : st.umax);
  body_.set3("u_base_color", st.base_color.data());
  body_.set3("u_eye", eye.data());
  body_.set3("u_key_dir", st.key_dir.data());
  body.draw();

  if (st.edges) {
    flat_.use();
    flat_.set_mat4("u_model", identity.data());
    const float ec[4] = {0.1f, 0.1f, 0.12f, 0.35f};
    flat_.set4("u_color", ec);
    glEnable(GL_BLEND);
    glEnable(GL_POLYGON_OFFSET_LINE);
    glPolygonOffset(-1.f, -1.f);
    glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    body.draw();
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glDisable(GL_POLYGON_OFFSET_LINE);
    glDisable(GL_BLEND);
  }

  if (!lines.empty()) {
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_PROGRAM_POINT_SIZE);
    line_flat_.use();
    line_flat_.set_mat4("u_view_proj", vp.data());
    glBindVertexArray(line_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
    for (const auto& l : lines) {
      const float pts[6] = {l.a.x, l.a.y, l.a.z, l.b.x, l.b.y, l.b.z};
      glBufferData(GL_ARRAY_BUFFER, sizeof pts, pts, GL_STREAM_DRAW);
      const float c[4] = {l.color.x, l.color.y, l.color.z, 1.f};
      line_flat_.set4("u_color", c);
      glDrawArrays(GL_LINES, 0, 2);
      glDrawArrays(GL_POINTS, 0, 2);
    }
    glDisable(GL_PROGRAM_POINT_SIZE);
    glEnable(GL_DEPTH_TEST);
  }
  glBindVertexArray(0);
}

}  // namespace softtled
