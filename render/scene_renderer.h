#pragma once
// Draws one frame: background gradient, contact planes with a grid, planar shadows of the
// body and the obstacles on each plane (stencil-masked so they never darken twice), the
// rigid obstacles, the lit body, and optional overlay lines (the viewer's drag spring);
// then, on request, the colour legend (render/color_legend.h).
// Same code for window and offscreen.
#include <memory>
#include <vector>

#include "render/body_buffer.h"
#include "render/camera.h"
#include "render/color_legend.h"
#include "render/shader.h"

namespace softtled {

// kDisplacement and kVonMises map the vertices' colour scalar (slot 6, body_buffer.h),
// which the producer fills with |u| or von Mises to match, through turbo from 0 to umax
// or vmmax.
enum class ColorMode : int { kShaded = 0, kDisplacement = 1, kContact = 2, kVonMises = 3 };

struct RenderStyle {
  ColorMode color = ColorMode::kShaded;
  float umax = 0.005f;            // |u| at the top of the displacement colour map [m]
  float vmmax = 1000.f;           // von Mises stress at the top of its colour map [Pa]
  bool shadows = true;
  bool grid = true;
  bool edges = false;             // mesh edges over the body
  Vec3 base_color{0.92f, 0.48f, 0.33f};
  Vec3 key_dir = normalize(Vec3{-0.35f, 1.0f, 0.55f});  // towards the key light
  float grid_minor = 0.002f, grid_major = 0.01f;        // [m]
};

// A contact plane as plain geometry (the app converts its simulation's planes).
struct RenderPlane {
  Vec3 point;   // a point on the plane [m]
  Vec3 normal;  // towards the free side (normalized when drawn)
};

// A rigid obstacle as plain geometry (the app converts its simulation's obstacles).
struct RenderObstacle {
  enum class Shape { kSphere, kBox, kCapsule, kMesh };
  Shape shape = Shape::kSphere;
  Vec3 center;   // sphere, box, mesh: centre (mesh: its frame's origin); capsule: end a [m]
  Vec3 b;        // capsule: end b [m]
  Vec3 half;     // box: half sides [m]
  float radius = 0;  // sphere, capsule [m]
  float R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // box, mesh: world = center + R local, row-major
  // mesh: 9 floats per triangle, its corners counter-clockwise from outside in the local
  // frame [m] (shared: the same surface every frame)
  std::shared_ptr<const std::vector<float>> triangles;
};

// Triangles of an obstacle's surface, 3 vertices each in the body's vertex layout
// (kBodyFloatsPerVertex floats: position, outward normal, colour scalar = 0, contact = 0), appended
// to out: a 32 x 16 UV sphere, a capsule of two such hemispheres and a cylinder, a box of
// 12 flat triangles.
void obstacle_triangles(const RenderObstacle& o, std::vector<float>& out);

struct OverlayLine {
  Vec3 a, b;
  Vec3 color{1, 1, 1};
};

class SceneRenderer {
 public:
  SceneRenderer();  // needs a current GL 3.3 context; compiles the shaders
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Draws into the currently bound framebuffer (viewport w x h). Planes are drawn as
  // squares of half side `plane_half` [m] centred where `focus` projects onto them.
  void draw(const Camera& cam, int w, int h, const BodyVertexBuffer& body, const std::vector<RenderPlane>& planes,
            Vec3 focus, float plane_half, const RenderStyle& style, const std::vector<OverlayLine>& lines = {},
            const std::vector<RenderObstacle>& obstacles = {});
  // The colour legend over the frame just drawn (nothing for LegendMap::kNone).
  void draw_legend(const ColorLegend& legend, int w, int h) { legend_.draw(legend, w, h); }

 private:
  ShaderProgram body_, flat_, plane_, background_, line_flat_;
  GLuint quad_vao_ = 0, quad_vbo_ = 0, empty_vao_ = 0, line_vao_ = 0, line_vbo_ = 0;
  GLuint obstacle_vao_ = 0, obstacle_vbo_ = 0;  // this frame's obstacle triangles
  std::vector<float> obstacle_verts_;
  LegendRenderer legend_;
};

}  // namespace softtled
