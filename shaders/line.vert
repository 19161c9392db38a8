#version 330 core
// World-space points for lines and markers (the drag spring).
layout(location = 0) in vec3 a_pos;
uniform mat4 u_view_proj;
void main() {
  gl_Position = u_view_proj * vec4(a_pos, 1.0);
  gl_PointSize = 7.0;
}
