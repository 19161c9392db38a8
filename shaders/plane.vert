#version 330 core
// A rigid contact plane drawn as a square around u_center; v_local is the position in the
// plane's own coordinates [m] (grid lines, fade-out towards the edge).
layout(location = 0) in vec2 a_uv;  // [-1, 1]^2

uniform mat4 u_view_proj;
uniform vec3 u_center;
uniform vec3 u_t1;      // unit tangents of the plane
uniform vec3 u_t2;
uniform float u_half;   // half side [m]

out vec3 v_pos;
out vec2 v_local;

void main() {
  v_local = a_uv * u_half;
  v_pos = u_center + u_t1 * v_local.x + u_t2 * v_local.y;
  gl_Position = u_view_proj * vec4(v_pos, 1.0);
}
