#version 330 core
// The body's render vertices (sim/surface_render.h): position [m], normal, |u| [m],
// contact state (0 free, 1 stick, 2 slide). u_model is the identity for the body itself
// and a planar-shadow projection when the same vertices draw its shadow.
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in float a_umag;
layout(location = 3) in float a_contact;

uniform mat4 u_view_proj;
uniform mat4 u_model;
uniform int u_color_mode;   // 0 shaded, 1 displacement |u|, 2 contact state
uniform float u_umax;       // |u| at the top of the colour map [m]
uniform vec3 u_base_color;

out vec3 v_pos;
out vec3 v_normal;
out vec3 v_color;

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

void main() {
  vec4 w = u_model * vec4(a_pos, 1.0);
  v_pos = w.xyz / w.w;
  v_normal = a_normal;
  if (u_color_mode == 1) {
    v_color = turbo(a_umag / max(u_umax, 1e-9));
  } else if (u_color_mode == 2) {
    const vec3 free_c = vec3(0.40, 0.58, 0.90);
    const vec3 stick_c = vec3(0.15, 0.78, 0.30);
    const vec3 slide_c = vec3(0.93, 0.22, 0.18);
    v_color = a_contact < 0.5 ? free_c : (a_contact < 1.5 ? stick_c : slide_c);
  } else {
    v_color = u_base_color;
  }
  gl_Position = u_view_proj * w;
}
