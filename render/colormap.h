#pragma once
// The colour maps of shaders/colormap.glsl in C++ (the same coefficients and states): the
// legend test compares the rendered bar with turbo_rgb, and the viewer's panel colours its
// contact labels with contact_rgb. Keep the two files in step.
#include <algorithm>

#include "render/math3d.h"

namespace softtled {

// Turbo colour map, polynomial fit (A. Mikhailov, Google AI blog, 2019); x clamped to [0, 1].
inline Vec3 turbo_rgb(float x) {
  const double t = std::clamp(double(x), 0.0, 1.0), t2 = t * t, t3 = t2 * t, t4 = t2 * t2, t5 = t3 * t2;
  auto poly = [&](double c0, double c1, double c2, double c3, double c4, double c5) {
    return float(c0 + c1 * t + c2 * t2 + c3 * t3 + c4 * t4 + c5 * t5);
  };
  return {poly(0.13572138, 4.61539260, -42.66032258, 132.13108234, -152.94239396, 59.28637943),
          poly(0.09140261, 2.19418839, 4.84296658, -14.18503333, 4.27729857, 2.82956604),
          poly(0.10667330, 12.64194608, -60.58204836, 110.36276771, -89.90310912, 27.34824973)};
}

// Contact state: 0 free (blue), 1 sticking (green), 2 sliding (red).
inline Vec3 contact_rgb(float state) {
  if (state < 0.5f) return {0.40f, 0.58f, 0.90f};
  if (state < 1.5f) return {0.15f, 0.78f, 0.30f};
  return {0.93f, 0.22f, 0.18f};
}

}  // namespace softtled
