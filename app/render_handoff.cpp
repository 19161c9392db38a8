#include "app/render_handoff.h"

#include <algorithm>
#include <limits>

#include "sim/core/input_error.h"
#include "sim/fem/surface_render.h"

namespace softtled {

static_assert(kBodyFloatsPerVertex == kRenderFloatsPerVertex,
              "render/body_buffer.h and sim/fem/surface_render.h must agree on the vertex layout");

std::unique_ptr<BodyVertexBuffer> make_body_buffer(const SurfaceTopology& topo) {
  return std::make_unique<BodyVertexBuffer>(int(topo.node.size()), topo.tri);
}

static_assert(kBodyScalarSlot == 6, "render/body_buffer.h's colour scalar is slot 6 of sim/fem/surface_render.h's vertex");

void write_body_vertices(Simulation& sim, BodyVertexBuffer& body, ColorMode color) {
  float* dst = body.map(sim.render_buffer_on_device());
  sim.write_render_vertices(dst, color == ColorMode::kVonMises ? RenderScalar::kVonMises : RenderScalar::kDisplacement);
  body.unmap();
}

std::vector<RenderPlane> render_planes(const std::vector<PlaneSpec>& planes) {
  std::vector<RenderPlane> r;
  for (const PlaneSpec& p : planes)
    r.push_back({{float(p.point[0]), float(p.point[1]), float(p.point[2])},
                  {float(p.normal[0]), float(p.normal[1]), float(p.normal[2])}});
  return r;
}

std::vector<RenderObstacle> render_obstacles(const std::vector<ObstacleSpec>& obstacles) {
  std::vector<RenderObstacle> r;
  auto v3 = [](const double* p) { return Vec3{float(p[0]), float(p[1]), float(p[2])}; };
  for (const ObstacleSpec& o : obstacles) {
    RenderObstacle q;
    q.shape = o.shape == kObstacleBox       ? RenderObstacle::Shape::kBox
              : o.shape == kObstacleCapsule ? RenderObstacle::Shape::kCapsule
              : o.shape == kObstacleMesh    ? RenderObstacle::Shape::kMesh
                                            : RenderObstacle::Shape::kSphere;
    if (o.shape == kObstacleMesh && o.sdf) {
      auto t = std::make_shared<std::vector<float>>();
      const SurfaceMesh& s = o.sdf->surface;
      t->reserve(s.tri.size() * 3);
      for (int v : s.tri)
        for (int k = 0; k < 3; ++k) t->push_back(float(s.xyz[3 * v + k]));
      q.triangles = std::move(t);
    }
    q.center = v3(o.center);
    q.b = v3(o.b);
    q.half = v3(o.half);
    q.radius = float(o.radius);
    for (int k = 0; k < 9; ++k) q.R[k] = float(o.R[k]);
    r.push_back(q);
  }
  return r;
}

namespace {
void rest_bounds(const Simulation& sim, Vec3& lo, Vec3& hi) {
  const auto& X = sim.mesh().X;
  const float inf = std::numeric_limits<float>::infinity();
  lo = {inf, inf, inf};
  hi = {-inf, -inf, -inf};
  for (std::size_t i = 0; i < X.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], float(X[i + k]));
      hi[k] = std::max(hi[k], float(X[i + k]));
    }
}
}  // namespace

Camera default_camera(const Simulation& sim) {
  Vec3 lo, hi;
  rest_bounds(sim, lo, hi);
  const Vec3 c = (lo + hi) * 0.5f;
  const float r = 0.5f * length(hi - lo);
  Camera cam;
  cam.azimuth_deg = 30;
  cam.elevation_deg = 18;
  cam.frame(c - Vec3{0, 0.15f * r, 0}, r, 0.8f);
  return cam;
}

float default_plane_half(const Simulation& sim) {
  Vec3 lo, hi;
  rest_bounds(sim, lo, hi);
  return 2.5f * length(hi - lo);
}

const std::vector<std::string>& color_mode_names() {
  static const std::vector<std::string> names = {"shaded", "displacement", "contact", "von_mises"};
  return names;
}

const std::string& color_mode_name(ColorMode c) { return color_mode_names().at(std::size_t(c)); }

ColorMode parse_color_mode(const std::string& name, const std::string& option) {
  const std::vector<std::string>& names = color_mode_names();
  for (std::size_t k = 0; k < names.size(); ++k)
    if (name == names[k]) return ColorMode(int(k));
  throw InputError(option + " '" + name + "': use shaded, displacement, contact or von_mises");
}

ColorLegend color_legend(const RenderStyle& style) {
  ColorLegend lg;
  if (style.color == ColorMode::kDisplacement) {
    lg.map = LegendMap::kTurbo;
    lg.title = "displacement";  // "|u|" reads as "lul" in stb_easy_font
    lg.unit = "mm";
    lg.component = "magnitude";
    lg.colormap = "turbo";
    lg.min = 0;
    lg.max = double(style.umax) * 1e3;  // the shader maps a_scalar / u_scalar_max, clamped to [0, 1]
  } else if (style.color == ColorMode::kVonMises) {
    lg.map = LegendMap::kTurbo;
    lg.title = "von Mises";
    lg.unit = "kPa";
    lg.component = "Cauchy";  // of sigma = P F^T / J, the nodal mean (von_mises.h)
    lg.colormap = "turbo";
    lg.min = 0;
    lg.max = double(style.vmmax) * 1e-3;  // the shader maps a_scalar / u_scalar_max
  } else if (style.color == ColorMode::kContact) {
    lg.map = LegendMap::kContactState;
    lg.title = "contact";
    lg.categories = {"free", "sticking", "sliding"};  // states 0, 1, 2 (contact_color)
  }
  return lg;
}

}  // namespace softtled
