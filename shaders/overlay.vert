#version 330 core
// 2D overlays in pixels (the colour legend: panel, bar, swatches, ticks, text), origin at
// the top left, y down.
layout(location = 0) in vec2 a_px;
layout(location = 1) in float a_value;  // colour-map input (u_mode 1, 2)

uniform vec2 u_viewport;  // [px]

out float v_value;

void main() {
  v_value = a_value;
  gl_Position = vec4(2.0 * a_px.x / u_viewport.x - 1.0, 1.0 - 2.0 * a_px.y / u_viewport.y, 0.0, 1.0);
}
