#version 330 core
// u_mode 0: one colour with alpha; 1: turbo(v_value) (the |u| bar, per fragment, the
// body's own function); 2: contact_color(v_value) (the contact map's swatches).
in float v_value;

uniform int u_mode;
uniform vec4 u_color;

out vec4 frag_color;

#include "colormap.glsl"

void main() {
  if (u_mode == 1) frag_color = vec4(turbo(v_value), 1.0);
  else if (u_mode == 2) frag_color = vec4(contact_color(v_value), 1.0);
  else frag_color = u_color;
}
