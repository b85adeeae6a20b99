precision highp float;

uniform vec3 u_eyeDirection;

in vec3 v_normal;
in vec3 v_color;
in float v_weight;

out vec4 outColor;

// Heat map of a weight in [0, 1]: dark blue (0) through cyan, yellow to red (1).
vec3 heat(float w) {
  vec3 c0 = vec3(0.08, 0.10, 0.45);
  vec3 c1 = vec3(0.0, 0.75, 0.85);
  vec3 c2 = vec3(0.98, 0.85, 0.15);
  vec3 c3 = vec3(0.85, 0.10, 0.08);
  if (w < 1.0 / 3.0) return mix(c0, c1, w * 3.0);
  if (w < 2.0 / 3.0) return mix(c1, c2, w * 3.0 - 1.0);
  return mix(c2, c3, clamp(w * 3.0 - 2.0, 0.0, 1.0));
}

void main() {
  vec3 n = normalize(v_normal);
  // Two-sided head light: open meshes and flipped faces stay visible.
  float diffuse = abs(dot(n, u_eyeDirection));
  vec3 base = v_weight >= 0.0 ? heat(v_weight) : v_color;
  outColor = vec4(base * (0.35 + 0.65 * diffuse), 1.0);
}
