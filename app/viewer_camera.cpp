#include "app/viewer_camera.h"

#include <algorithm>
#include <cmath>

namespace softtled {

void camera_orbit(Camera& cam, float dx, float dy) {
  cam.azimuth_deg = std::fmod(cam.azimuth_deg - 0.3f * dx, 360.f);
  cam.elevation_deg = std::clamp(cam.elevation_deg + 0.3f * dy, -85.f, 85.f);
}

void camera_pan(Camera& cam, float dx, float dy, int h) {
  const Vec3 f = normalize(cam.target - cam.eye());
  const Vec3 right = normalize(cross(f, {0, 1, 0}));
  const Vec3 up = cross(right, f);
  const float m_per_px = 2 * cam.distance * std::tan(cam.fovy_deg * 3.14159265f / 360) / float(std::max(h, 1));
  cam.target = cam.target - right * (dx * m_per_px) + up * (dy * m_per_px);
}

void camera_zoom(Camera& cam, float wheel) { cam.distance *= std::pow(0.88f, wheel); }

}  // namespace softtled
