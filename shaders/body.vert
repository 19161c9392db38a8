#version 330 core
// The body's render vertices (sim/fem/surface_render.h): position [m], normal, the colour
// scalar (|u| [m] or von Mises [Pa], whichever the app asked the simulation for), contact
// state (0 free, 1 stick, 2 slide). u_model is the identity for the body itself and a
// planar-shadow projection when the same vertices draw its shadow.
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in float a_scalar;
layout(location = 3) in float a_contact;

uniform mat4 u_view_proj;
uniform mat4 u_model;
uniform int u_color_mode;     // 0 shaded, 1 displacement |u|, 2 contact state, 3 von Mises
uniform float u_scalar_max;   // the colour scalar at the top of the map (0 at the bottom)
uniform vec3 u_base_color;

out vec3 v_pos;
out vec3 v_normal;
out vec3 v_color;

#include "colormap.glsl"

void main() {
  vec4 w = u_model * vec4(a_pos, 1.0);
  v_pos = w.xyz / w.w;
  v_normal = a_normal;
  if (u_color_mode == 1 || u_color_mode == 3) {
    v_color = turbo(a_scalar / max(u_scalar_max, 1e-9));
  } else if (u_color_mode == 2) {
    v_color = contact_color(a_contact);
  } else {
    v_color = u_base_color;
  }
  gl_Position = u_view_proj * w;
}
