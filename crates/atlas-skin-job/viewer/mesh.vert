// Skinned mesh: colour by region, or a heat map of the selected joint's weight.
uniform mat4 u_viewProjection;
uniform int u_heatJoint;

in vec3 a_position;
in vec3 a_normal;
in vec3 a_color;

out vec3 v_position;
out vec3 v_normal;
out vec3 v_color;
out float v_weight;

void main() {
  vec3 position;
  vec3 normal;
  skinVertex(a_position, a_normal, position, normal);
  v_position = position;
  v_normal = normal;
  v_color = a_color;
  v_weight = u_heatJoint >= 0 ? weightOf(u_heatJoint) : -1.0;
  gl_Position = u_viewProjection * vec4(position, 1.0);
}
