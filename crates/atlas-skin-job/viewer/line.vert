// Lines and points: cut curves (skinned like the mesh) and the skeleton (already posed).
uniform mat4 u_viewProjection;
uniform float u_pointSize;

in vec3 a_position;

void main() {
  vec3 position;
  vec3 normal;
  skinVertex(a_position, vec3(0.0, 0.0, 1.0), position, normal);
  gl_Position = u_viewProjection * vec4(position, 1.0);
  // Pull lines slightly toward the eye so they are not hidden by the surface they lie on.
  gl_Position.z -= 0.002 * gl_Position.w;
  gl_PointSize = u_pointSize;
}
