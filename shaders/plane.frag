#version 330 core
// Plane with an anti-aliased grid (minor and major lines, widths from fwidth) that fades
// out towards its edge; lit by the key light like the body.
in vec3 v_pos;
in vec2 v_local;

uniform vec3 u_normal;
uniform vec3 u_key_dir;
uniform vec3 u_color;
uniform vec3 u_line_color;
uniform vec2 u_origin;   // grid origin in plane coordinates [m] (lines stay put as the plane turns)
uniform float u_minor;   // grid spacing [m]
uniform float u_major;
uniform float u_half;
uniform int u_grid;

out vec4 frag_color;

float grid_line(vec2 p, float spacing, float width_px) {
  vec2 c = p / spacing;
  vec2 fw = max(fwidth(c), vec2(1e-6));
  vec2 g = abs(fract(c - 0.5) - 0.5) / fw;
  float line = 1.0 - clamp(min(g.x, g.y) - 0.5 * width_px + 0.5, 0.0, 1.0);
  // Fade lines out where they crowd closer than a few pixels (no moire in the distance).
  return line * (1.0 - smoothstep(0.12, 0.4, max(fw.x, fw.y)));
}

void main() {
  float light = 0.62 + 0.38 * max(dot(u_normal, u_key_dir), 0.0);
  vec3 c = u_color * light;
  if (u_grid != 0) {
    vec2 p = v_local - u_origin;
    float minor = grid_line(p, u_minor, 1.0);
    float major = grid_line(p, u_major, 1.6);
    c = mix(c, u_line_color * light, max(0.3 * minor, 0.7 * major));
  }
  float r = max(abs(v_local.x), abs(v_local.y)) / u_half;
  float alpha = 1.0 - smoothstep(0.7, 1.0, r);
  if (alpha < 0.01) discard;
  frag_color = vec4(c, alpha);
}
