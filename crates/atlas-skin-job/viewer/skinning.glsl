// Skinning shared by the mesh and the line shaders.
//
// u_palette holds one row per joint (RGBA32F, 7 texels):
//   texels 0..3  columns of the joint matrix M_j = world_j * inverseBind_j
//   texel  4     real part q_j of the unit dual quaternion of M_j's rigid part
//   texel  5     dual part  q_e = 1/2 (t, 0) q_j
//   texel  6     (s_x, s_y, s_z, 0): column lengths of M_j's 3x3 block (M_j = [R_j S_j | t_j])
// Up to eight influences: a_joints0/a_weights0 (JOINTS_0/WEIGHTS_0) and a_joints1/a_weights1
// (JOINTS_1/WEIGHTS_1, constant zero weights when absent).

uniform highp sampler2D u_palette;
uniform int u_dqs;
uniform int u_skinned;

in uvec4 a_joints0;
in vec4 a_weights0;
in uvec4 a_joints1;
in vec4 a_weights1;

mat4 jointMatrix(uint j) {
  int row = int(j);
  return mat4(texelFetch(u_palette, ivec2(0, row), 0), texelFetch(u_palette, ivec2(1, row), 0),
              texelFetch(u_palette, ivec2(2, row), 0), texelFetch(u_palette, ivec2(3, row), 0));
}

// Linear blend skinning: v' = (sum_k w_k M_k) v.
mat4 blendedMatrix() {
  mat4 m = mat4(0.0);
  for (int k = 0; k < 4; k++) {
    if (a_weights0[k] > 0.0) m += a_weights0[k] * jointMatrix(a_joints0[k]);
    if (a_weights1[k] > 0.0) m += a_weights1[k] * jointMatrix(a_joints1[k]);
  }
  return m;
}

// Dual quaternion skinning (Kavan et al. 2007): blend the dual quaternions with signs aligned
// to the first influence's hemisphere, normalise by the real part's length, then apply the
// rigid transform to the linearly blended scale S p.
void dqsAccumulate(uint j, float w, vec4 pivot, inout vec4 real, inout vec4 dual, inout vec3 scale) {
  int row = int(j);
  vec4 r = texelFetch(u_palette, ivec2(4, row), 0);
  float s = dot(r, pivot) < 0.0 ? -w : w;
  real += s * r;
  dual += s * texelFetch(u_palette, ivec2(5, row), 0);
  scale += w * texelFetch(u_palette, ivec2(6, row), 0).xyz;
}

vec3 rotateByQuat(vec4 q, vec3 v) {
  return v + 2.0 * cross(q.xyz, cross(q.xyz, v) + q.w * v);
}

void skinVertex(vec3 position, vec3 normal, out vec3 skinnedPosition, out vec3 skinnedNormal) {
  if (u_skinned == 0) {
    skinnedPosition = position;
    skinnedNormal = normal;
    return;
  }
  if (u_dqs == 0) {
    mat4 m = blendedMatrix();
    skinnedPosition = (m * vec4(position, 1.0)).xyz;
    skinnedNormal = mat3(m) * normal;
    return;
  }
  vec4 pivot = texelFetch(u_palette, ivec2(4, int(a_joints0.x)), 0);
  vec4 real = vec4(0.0);
  vec4 dual = vec4(0.0);
  vec3 scale = vec3(0.0);
  for (int k = 0; k < 4; k++) {
    if (a_weights0[k] > 0.0) dqsAccumulate(a_joints0[k], a_weights0[k], pivot, real, dual, scale);
    if (a_weights1[k] > 0.0) dqsAccumulate(a_joints1[k], a_weights1[k], pivot, real, dual, scale);
  }
  float len = max(length(real), 1e-8);
  real /= len;
  dual /= len;
  vec3 translation = 2.0 * (real.w * dual.xyz - dual.w * real.xyz + cross(real.xyz, dual.xyz));
  skinnedPosition = rotateByQuat(real, scale * position) + translation;
  skinnedNormal = rotateByQuat(real, normal / max(scale, vec3(1e-8)));
}

// Weight of joint `j` at this vertex (0 when it is not among the influences).
float weightOf(int j) {
  float w = 0.0;
  for (int k = 0; k < 4; k++) {
    if (int(a_joints0[k]) == j) w += a_weights0[k];
    if (int(a_joints1[k]) == j) w += a_weights1[k];
  }
  return w;
}
