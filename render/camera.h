#pragma once
// Orbit camera: looks at `target` from `distance`, azimuth about +y, elevation above the
// x-z plane. Shared by the viewer (mouse-driven, app/viewer_camera.h) and headless renders.
#include <algorithm>
#include <cmath>

#include "render/math3d.h"

namespace softtled {

struct Camera {
  Vec3 target{0, 0, 0};
  float distance = 0.06f;     // [m]
  float azimuth_deg = 30;     // about +y, 0: looking along -z
  float elevation_deg = 20;
  float fovy_deg = 35;
  float shift_x = 0;          // lens shift in NDC: moves the image centre right (a side panel)

  Vec3 eye() const {
    const float a = azimuth_deg * 3.14159265f / 180, e = elevation_deg * 3.14159265f / 180;
    return target + Vec3{std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)} * distance;
  }
  Mat4 view() const { return look_at(eye(), target, {0, 1, 0}); }
  Mat4 proj(float aspect) const {
    Mat4 p = perspective(fovy_deg * 3.14159265f / 180, aspect, distance * 0.02f, distance * 20.f);
    p(0, 2) -= shift_x;  // x_ndc += shift_x (w_clip = -z_eye)
    return p;
  }

  // Frames a sphere (centre, radius) so it fills about `fill` of the view height.
  void frame(Vec3 centre, float radius, float fill = 0.55f) {
    target = centre;
    distance = radius / std::sin(fovy_deg * 3.14159265f / 360) / fill;
  }

  // World-space ray through pixel (px, py) of a w x h viewport (py down, as mice report).
  void ray(float px, float py, int w, int h, Vec3& origin, Vec3& dir) const {
    const Mat4 inv = inverse(proj(float(w) / float(std::max(h, 1))) * view());
    const float nx = 2 * (px + 0.5f) / w - 1, ny = 1 - 2 * (py + 0.5f) / h;
    const Vec3 a = transform_point(inv, {nx, ny, -1}), b = transform_point(inv, {nx, ny, 1});
    origin = a;
    dir = normalize(b - a);
  }
};

}  // namespace softtled
