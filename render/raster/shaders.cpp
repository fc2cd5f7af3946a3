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

std::string shadingConstants() {
  using namespace shading;
  return "const vec3 kFrontAlbedo = " + glslVec3(kFrontAlbedo) + ";\n" +
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
uniform mat4 uViewProjection;
uniform vec3 uEye;
uniform vec3 uForward;
out vec3 vFromEye;  // p - eye: small numbers near the eye keep the face normal precise
out vec3 vNormal;
out float vDepth;   // affine in p, so perspective-correct interpolation makes it exact
void main() {
  vFromEye = aPosition - uEye;
  vNormal = aNormal;
  vDepth = dot(vFromEye, uForward);
  gl_Position = uViewProjection * vec4(aPosition, 1.0);
}
)";
}

std::string surfaceFragmentShader() {
  return std::string(R"(#version 450 core
in vec3 vFromEye;
in vec3 vNormal;
in float vDepth;
uniform vec3 uForward;
uniform bool uPerspective;
uniform bool uSmooth;
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

  // shading::shade(): headlight Blinn-Phong, the half vector is toEye.
  float ndotv = dot(n, toEye);
  vec3 albedo = ndotv >= 0.0 ? kFrontAlbedo : kBackAlbedo;
  float c = abs(ndotv);
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
  return R"(#version 450 core
uniform vec4 uColor;
layout(location = 0) out vec4 oColor;
void main() { oColor = uColor; }
)";
}

}  // namespace limn::render::raster
