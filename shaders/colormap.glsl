// The colour maps, shared by the body (body.vert) and the legend (overlay.frag) through
// `#include "colormap.glsl"` (render/shader.cpp resolves it); render/colormap.h mirrors
// them in C++ for the tests and the panel.

// Turbo colour map, polynomial fit (A. Mikhailov, Google AI blog, 2019).
vec3 turbo(float x) {
  const vec4 kr4 = vec4(0.13572138, 4.61539260, -42.66032258, 132.13108234);
  const vec4 kg4 = vec4(0.09140261, 2.19418839, 4.84296658, -14.18503333);
  const vec4 kb4 = vec4(0.10667330, 12.64194608, -60.58204836, 110.36276771);
  const vec2 kr2 = vec2(-152.94239396, 59.28637943);
  const vec2 kg2 = vec2(4.27729857, 2.82956604);
  const vec2 kb2 = vec2(-89.90310912, 27.34824973);
  x = clamp(x, 0.0, 1.0);
  vec4 v4 = vec4(1.0, x, x * x, x * x * x);
  vec2 v2 = v4.zw * v4.z;
  return vec3(dot(v4, kr4) + dot(v2, kr2), dot(v4, kg4) + dot(v2, kg2), dot(v4, kb4) + dot(v2, kb2));
}

// Contact state: 0 free (blue), 1 sticking (green), 2 sliding (red).
vec3 contact_color(float state) {
  const vec3 free_c = vec3(0.40, 0.58, 0.90);
  const vec3 stick_c = vec3(0.15, 0.78, 0.30);
  const vec3 slide_c = vec3(0.93, 0.22, 0.18);
  return state < 0.5 ? free_c : (state < 1.5 ? stick_c : slide_c);
}
