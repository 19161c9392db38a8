#version 330 core
// Lit body: hemispheric ambient, a key and a fill light (Blinn-Phong), a soft rim.
in vec3 v_pos;
in vec3 v_normal;
in vec3 v_color;

uniform vec3 u_eye;
uniform vec3 u_key_dir;  // towards the key light, unit

out vec4 frag_color;

void main() {
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
  vec3 v = normalize(u_eye - v_pos);
  vec3 fill_dir = normalize(vec3(-u_key_dir.x, 0.35, -u_key_dir.z));
  float hemi = 0.5 + 0.5 * n.y;
  vec3 ambient = mix(vec3(0.20, 0.19, 0.20), vec3(0.42, 0.45, 0.52), hemi);
  float key = max(dot(n, u_key_dir), 0.0);
  float fill = max(dot(n, fill_dir), 0.0);
  vec3 h = normalize(u_key_dir + v);
  float spec = pow(max(dot(n, h), 0.0), 40.0) * (key > 0.0 ? 1.0 : 0.0);
  float rim = pow(1.0 - max(dot(n, v), 0.0), 3.0);
  vec3 c = v_color * (ambient + 0.78 * key * vec3(1.0, 0.97, 0.92) + 0.22 * fill * vec3(0.85, 0.9, 1.0)) +
           0.28 * spec * vec3(1.0) + 0.10 * rim * vec3(0.9, 0.95, 1.0);
  frag_color = vec4(clamp(c, 0.0, 1.0), 1.0);
}
