#include "render/raster/shaders.h"

#include <cstdio>

#include "render/core/shading.h"

namespace limn::render::raster {

std::string glslFloat(float value) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(value));
  std::string text = buf;
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

namespace {

std::string glslVec3(const float v[3]) {
  return "vec3(" + glslFloat(v[0]) + ", " + glslFloat(v[1]) + ", " + glslFloat(v[2]) + ")";
}

// shading::srgbToLinear in GLSL: the shaders take sRGB colours (albedos, line colours) and
// write linear light.
const char* kToLinear = R"(
vec3 toLinear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}
)";

std::string shadingConstants() {
  using namespace shading;
  return std::string(kToLinear) + "const vec3 kFrontAlbedo = " + glslVec3(kFrontAlbedo) + ";\n" +
         "const vec3 kBackAlbedo = " + glslVec3(kBackAlbedo) + ";\n" +
         "const float kAmbient = " + glslFloat(kAmbient) + ";\n" +
         "const float kDiffuse = " + glslFloat(kDiffuse) + ";\n" +
         "const float kSpecular = " + glslFloat(kSpecular) + ";\n" +
         "const float kShininess = " + glslFloat(kShininess) + ";\n";
}

}  // namespace

std::string surfaceVertexShader() {
  return R"(#version 450 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aTexcoord;
layout(location = 3) in vec3 aAlbedo;  // negative: the front albedo
uniform mat4 uViewProjection;
uniform vec3 uEye;
uniform vec3 uForward;
out vec3 vFromEye;  // p - eye: small numbers near the eye keep the face normal precise
out vec3 vNormal;
out vec2 vTexcoord;
out vec3 vAlbedo;
out float vDepth;   // affine in p, so perspective-correct interpolation makes it exact
void main() {
  vFromEye = aPosition - uEye;
  vNormal = aNormal;
  vTexcoord = aTexcoord;
  vAlbedo = aAlbedo;
  vDepth = dot(vFromEye, uForward);
  gl_Position = uViewProjection * vec4(aPosition, 1.0);
}
)";
}

std::string surfaceFragmentShader() {
  return std::string(R"(#version 450 core
in vec3 vFromEye;
in vec3 vNormal;
in vec2 vTexcoord;
in vec3 vAlbedo;
in float vDepth;
uniform vec3 uForward;
uniform bool uPerspective;
uniform bool uSmooth;
uniform bool uNormalMap;
uniform sampler2D uNormalTexture;
layout(location = 0) out vec4 oColor;
layout(location = 1) out float oDepth;
layout(location = 2) out vec4 oNormal;
)") + shadingConstants() +
         R"(
void main() {
  // The geometric normal from screen derivatives. cross(dFdx, dFdy) always faces the viewer;
  // back-facing triangles (clockwise on screen) get it flipped so it follows their winding.
  // Computed before any branch: derivatives need uniform control flow.
  vec3 face = cross(dFdx(vFromEye), dFdy(vFromEye));
  float faceLength = length(face);
  vec3 toEye = uPerspective ? normalize(-vFromEye) : -uForward;
  face = faceLength > 0.0 ? face / faceLength : toEye;
  if (!gl_FrontFacing) face = -face;
  vec3 n = face;
  float smoothLength = length(vNormal);
  if (uSmooth && smoothLength > 0.0) n = vNormal / smoothLength;
  if (uNormalMap) {
    // Bilinear between texel normals, renormalised. Level 0 explicitly: there are no mipmaps,
    // and implicit derivatives are undefined in this branch.
    vec3 mapped = textureLod(uNormalTexture, vTexcoord, 0.0).xyz;
    float mappedLength = length(mapped);
    if (mappedLength > 0.0) n = mapped / mappedLength;
  }

  // shading::shade(): headlight Blinn-Phong, the half vector is toEye. The side the pixel sees
  // is the triangle's (its winding), not the interpolated normal's: near the outline of a
  // tessellation the smooth normal of a front-facing triangle turns a little away from the eye
  // (it is the limit surface's, whose outline lies elsewhere), and taking its side would paint
  // a fringe with the back albedo. There the light falls to zero, as at the limit's outline.
  float ndotv = dot(n, toEye);
  vec3 front = vAlbedo.x >= 0.0 ? vAlbedo : kFrontAlbedo;
  vec3 albedo = toLinear(gl_FrontFacing ? front : kBackAlbedo);
  float c = max(gl_FrontFacing ? ndotv : -ndotv, 0.0);
  float spec = pow(c, kShininess);
  vec3 rgb = clamp(albedo * (kAmbient + kDiffuse * c) + kSpecular * spec, 0.0, 1.0);

  oColor = vec4(rgb, 1.0);
  oDepth = vDepth;
  oNormal = vec4(n, 0.0);
}
)";
}

std::string solidVertexShader() {
  return R"(#version 450 core
layout(location = 0) in vec3 aPosition;
uniform mat4 uViewProjection;
void main() { gl_Position = uViewProjection * vec4(aPosition, 1.0); }
)";
}

std::string solidFragmentShader() {
  return std::string(R"(#version 450 core
uniform vec4 uColor;  // sRGB, straight alpha
layout(location = 0) out vec4 oColor;
)") + kToLinear +
         R"(
void main() { oColor = vec4(toLinear(uColor.rgb), uColor.a); }
)";
}

std::string lineVertexShader() {
  return R"(#version 450 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec4 aColor;
uniform mat4 uViewProjection;
uniform vec3 uEye;
uniform vec3 uForward;
uniform bool uPerspective;
uniform float uBias;
out vec4 vColor;
void main() {
  // Towards the eye along the view ray: the point stays on its pixel, only its depth changes.
  vec3 p = uPerspective ? uEye + (aPosition - uEye) * (1.0 - uBias) : aPosition - uForward * uBias;
  vColor = aColor;
  gl_Position = uViewProjection * vec4(p, 1.0);
}
)";
}

std::string lineGeometryShader() {
  return R"(#version 450 core
layout(lines) in;
layout(triangle_strip, max_vertices = 4) out;
in vec4 vColor[];
flat out vec4 gColor;
uniform vec2 uViewport;
uniform float uHalfWidth;

// Clip-space offset of `pixels` at a vertex with this w.
vec4 offset(vec2 pixels, float w) { return vec4(pixels / (0.5 * uViewport) * w, 0.0, 0.0); }

void main() {
  vec4 a = gl_in[0].gl_Position;
  vec4 b = gl_in[1].gl_Position;
  // Cut the segment at the near plane (reversed depth: z <= w in front of it) before dividing
  // by w, which is not positive behind the eye.
  float da = a.w - a.z, db = b.w - b.z;
  if (da < 0.0 && db < 0.0) return;
  if (da < 0.0) a = mix(a, b, da / (da - db));
  if (db < 0.0) b = mix(b, a, db / (db - da));

  vec2 sa = a.xy / a.w * 0.5 * uViewport;
  vec2 sb = b.xy / b.w * 0.5 * uViewport;
  vec2 along = sb - sa;
  float len = length(along);
  along = len > 1e-6 ? along / len : vec2(1.0, 0.0);  // seen end-on: a square
  vec2 side = vec2(-along.y, along.x) * uHalfWidth;
  along *= uHalfWidth;
  gColor = vColor[0];
  gl_Position = a + offset(-along - side, a.w); EmitVertex();
  gl_Position = a + offset(-along + side, a.w); EmitVertex();
  gl_Position = b + offset(along - side, b.w); EmitVertex();
  gl_Position = b + offset(along + side, b.w); EmitVertex();
  EndPrimitive();
}
)";
}

std::string lineFragmentShader() {
  return std::string(R"(#version 450 core
flat in vec4 gColor;  // sRGB, straight alpha
layout(location = 3) out vec4 oOverlay;
)") + kToLinear +
         R"(
void main() { oOverlay = vec4(toLinear(gColor.rgb), gColor.a); }
)";
}

}  // namespace limn::render::raster
