#include "render/patches/gpu_tessellation.h"

#include <opensubdiv/osd/glslPatchShaderSource.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/core/parallel.h"
#include "render/raster/gl_api.h"
#include "render/raster/gl_error.h"
#include "render/raster/shader_program.h"

namespace limn::render::patches {

namespace {

using raster::checkGl;
using raster::ShaderProgram;
using raster::ShaderStage;

// Storage buffer bindings, as the shaders declare them.
enum Binding : GLuint {
  kPoints = 0,        // float x, y, z per point of PatchSet::points()
  kPatchInfo = 1,     // int per patch: first index in kPointIndices, Far type, param fields 0, 1
  kPointIndices = 2,  // int: every patch's point indices
  kDomainFrames = 3,  // float per domain: origin, axisA, axisB
  kDomainSides = 4,   // int per domain: patch, then per side its first piece and piece count
  kPieces = 5,        // float per piece: end (fraction of the side), segments up to its end
  kLevels = 6,        // float per domain: GL's outer levels 0-3 and inner levels 0-1
  kBindings = 7
};
constexpr int kSideInts = 9;
constexpr int kLevelFloats = 6;
// One captured vertex: position, normal, patch-local (s, t) and the patch index.
struct CapturedVertex {
  float position[3], normal[3], local[2];
  int32_t patch;
};
static_assert(sizeof(CapturedVertex) == 9 * 4, "transform feedback writes 9 packed words");
// A batch is also cut where its worst-case triangle count passes this, which bounds the
// transform feedback buffer (36 bytes per captured vertex: 108 MB)...
constexpr size_t kMaxBatchTriangles = 1'000'000;
// ... and where the vertices the tessellator may generate pass this: llvmpipe (Mesa 22) numbers
// a draw's tessellated vertices with 16 bits, and a draw making more than 65,536 gets vertices
// of other patches (found by the limit-surface test: 80 domains of ~900 vertices failed, 64
// did not).
constexpr size_t kMaxBatchVertices = 60'000;

std::string vertexShader() {
  // Attribute-less: each GL patch is one vertex, whose number (counted from the draw's `first`)
  // is its domain. (gl_PrimitiveID in the control shader restarts within large draws on
  // llvmpipe.)
  return R"(#version 450 core
out int vDomain;
void main() {
  vDomain = gl_VertexID;
  gl_Position = vec4(0.0);
}
)";
}

std::string controlShader() {
  return R"(#version 450 core
layout(vertices = 1) out;
layout(std430, binding = 6) readonly buffer Levels { float levels[]; };
in int vDomain[];
out int tcDomain[];
void main() {
  int d = vDomain[0];
  tcDomain[gl_InvocationID] = d;
  for (int k = 0; k < 4; ++k) gl_TessLevelOuter[k] = levels[6 * d + k];
  gl_TessLevelInner[0] = levels[6 * d + 4];
  gl_TessLevelInner[1] = levels[6 * d + 5];
}
)";
}

// What both evaluation shaders share: the buffers, Osd's patch basis, the pieces of a side and
// the evaluation of one vertex.
std::string evaluationCommon() {
  return "#define OSD_PATCH_BASIS_GLSL\n" +
         OpenSubdiv::Osd::GLSLPatchShaderSource::GetPatchBasisShaderSource() + R"(
layout(std430, binding = 0) readonly buffer Points { float points[]; };
layout(std430, binding = 1) readonly buffer PatchInfo { int patchInfo[]; };
layout(std430, binding = 2) readonly buffer PointIndices { int pointIndices[]; };
layout(std430, binding = 3) readonly buffer DomainFrames { float domainFrames[]; };
layout(std430, binding = 4) readonly buffer DomainSides { int domainSides[]; };
layout(std430, binding = 5) readonly buffer Pieces { float pieces[]; };
in int tcDomain[];
out vec3 tePosition;
out vec3 teNormal;
out vec2 teLocal;
flat out int tePatch;

// A vertex at t on side k (t = i / n from the side's first corner, n its segments in all):
// the pieces' segments follow one another, each spread evenly over its own part of the side.
float alongSide(int d, int side, float t) {
  int first = domainSides[9 * d + 1 + 2 * side], count = domainSides[9 * d + 2 + 2 * side];
  float total = pieces[2 * (first + count - 1) + 1];
  float i = round(t * total);
  float start = 0.0, before = 0.0;
  for (int k = 0; k < count; ++k) {
    float end = pieces[2 * (first + k)], upTo = pieces[2 * (first + k) + 1];
    if (i <= upTo) return start + (end - start) * (i - before) / (upTo - before);
    start = end;
    before = upTo;
  }
  return 1.0;
}

vec3 point(int i) { return vec3(points[3 * i], points[3 * i + 1], points[3 * i + 2]); }

// The patch's position and first and second derivatives at its own (s, t).
void evaluateJet(int p, vec2 st, out vec3 position, out vec3 ds, out vec3 dt, out vec3 dss,
                 out vec3 dst, out vec3 dtt) {
  float wP[20], wDs[20], wDt[20], wDss[20], wDst[20], wDtt[20];
  OsdPatchParam param = OsdPatchParamInit(patchInfo[4 * p + 2], patchInfo[4 * p + 3], 0.0);
  int n = OsdEvaluatePatchBasisNormalized(patchInfo[4 * p + 1], param, st.x, st.y,
                                          wP, wDs, wDt, wDss, wDst, wDtt);
  position = vec3(0.0);
  ds = vec3(0.0);
  dt = vec3(0.0);
  dss = vec3(0.0);
  dst = vec3(0.0);
  dtt = vec3(0.0);
  int first = patchInfo[4 * p];
  for (int i = 0; i < n; ++i) {
    vec3 c = point(pointIndices[first + i]);
    position += wP[i] * c;
    ds += wDs[i] * c;
    dt += wDt[i] * c;
    dss += wDss[i] * c;
    dst += wDst[i] * c;
    dtt += wDtt[i] * c;
  }
}

// Analytic displacement (subdiv/displacement.h): 0 none, 1 bumps, 2 ripples, in world units.
uniform int displacementFunction;
uniform float displacementAmplitude;
uniform float displacementWavenumber;
uniform vec3 displacementCentre;

float displacementAt(vec3 p, out vec3 gradient) {
  vec3 q = p - displacementCentre;
  float a = displacementAmplitude, k = displacementWavenumber;
  if (displacementFunction == 1) {
    vec3 s = sin(k * q), c = cos(k * q);
    gradient = a * k * vec3(c.x * s.y * s.z, s.x * c.y * s.z, s.x * s.y * c.z);
    return a * s.x * s.y * s.z;
  }
  float r = length(q);
  gradient = r > 0.0 ? q * (a * k * cos(k * r) / r) : vec3(0.0);
  return a * sin(k * r);
}

// f = s + N D(s) and its derivatives, N's from the Weingarten equations. The derivatives are
// the patch-local ones, which Osd's normalized basis gives with the right sign on rotated Loop
// triangles; a Gregory end cap's second derivatives are differences of its first (as on the
// CPU: Osd's leave out the rational blending). False where s's normal is undefined.
bool displace(int p, vec2 st, vec3 s, vec3 su, vec3 sv, vec3 suu, vec3 suv, vec3 svv,
              out vec3 position, out vec3 du, out vec3 dv) {
  int type = patchInfo[4 * p + 1];
  if (type == OSD_PATCH_DESCRIPTOR_GREGORY_BASIS ||
      type == OSD_PATCH_DESCRIPTOR_GREGORY_TRIANGLE) {
    const float h = 1e-3;
    vec3 q, a0, b0, a1, b1, ignored1, ignored2, ignored3;
    evaluateJet(p, st - vec2(h, 0.0), q, a0, b0, ignored1, ignored2, ignored3);
    evaluateJet(p, st + vec2(h, 0.0), q, a1, b1, ignored1, ignored2, ignored3);
    suu = (a1 - a0) / (2.0 * h);
    vec3 alongS = (b1 - b0) / (2.0 * h);
    evaluateJet(p, st - vec2(0.0, h), q, a0, b0, ignored1, ignored2, ignored3);
    evaluateJet(p, st + vec2(0.0, h), q, a1, b1, ignored1, ignored2, ignored3);
    svv = (b1 - b0) / (2.0 * h);
    suv = 0.5 * (alongS + (a1 - a0) / (2.0 * h));
  }
  vec3 c = cross(su, sv);
  float area = length(c);
  if (!(area > 1e-5 * (dot(su, su) + dot(sv, sv)))) return false;
  vec3 n = c / area;
  float E = dot(su, su), F = dot(su, sv), G = dot(sv, sv);
  float e = dot(suu, n), f = dot(suv, n), g = dot(svv, n);
  float det = E * G - F * F;
  vec3 nu = (su * (f * F - e * G) + sv * (e * F - f * E)) / det;
  vec3 nv = (su * (g * F - f * G) + sv * (f * F - g * E)) / det;
  vec3 gradient;
  float d = displacementAt(s, gradient);
  position = s + n * d;
  du = su + nu * d + n * dot(gradient, su);
  dv = sv + nv * d + n * dot(gradient, sv);
  return true;
}

// Position and first derivatives at the patch's (s, t), displaced when asked (PatchSet's
// evaluate(): where the normal is undefined, N from a point nudged towards the patch's centre).
void evaluatePatch(int p, vec2 st, out vec3 position, out vec3 ds, out vec3 dt) {
  vec3 dss, dst, dtt;
  evaluateJet(p, st, position, ds, dt, dss, dst, dtt);
  if (displacementFunction == 0) return;
  vec3 s = position, su = ds, sv = dt;
  if (displace(p, st, s, su, sv, dss, dst, dtt, position, ds, dt)) return;
  float centre = patchInfo[4 * p + 1] == OSD_PATCH_DESCRIPTOR_REGULAR ||
                 patchInfo[4 * p + 1] == OSD_PATCH_DESCRIPTOR_GREGORY_BASIS ? 0.5 : 1.0 / 3.0;
  vec2 near = mix(st, vec2(centre), 1e-3);
  vec3 q;
  evaluateJet(p, near, q, su, sv, dss, dst, dtt);
  if (displace(p, near, s, su, sv, dss, dst, dtt, position, ds, dt)) return;
  position = s;
}

vec2 toPatch(int d, vec2 ab) {
  vec2 origin = vec2(domainFrames[6 * d], domainFrames[6 * d + 1]);
  vec2 axisA = vec2(domainFrames[6 * d + 2], domainFrames[6 * d + 3]);
  vec2 axisB = vec2(domainFrames[6 * d + 4], domainFrames[6 * d + 5]);
  return origin + ab.x * axisA + ab.y * axisB;
}

// The CPU path's evaluateSample(): where the derivatives vanish (some end-cap corners), the
// normal a little way towards the domain's centre.
void emit(int d, vec2 ab, vec2 centreAb) {
  int p = domainSides[9 * d];
  vec2 st = toPatch(d, ab), centre = toPatch(d, centreAb);
  vec3 position, ds, dt;
  evaluatePatch(p, st, position, ds, dt);
  vec3 n = cross(ds, dt);
  for (float step = 1e-4; length(n) <= 1e-6 * length(ds) * length(dt) && step < 0.5;
       step *= 10.0) {
    vec3 ignored;
    evaluatePatch(p, mix(st, centre, step), ignored, ds, dt);
    n = cross(ds, dt);
  }
  float len = length(n);
  tePosition = position;
  teNormal = len > 0.0 ? n / len : vec3(0.0, 0.0, 1.0);
  teLocal = st;
  tePatch = p;
  gl_Position = vec4(position, 1.0);
}
)";
}

// Quads: (a, b) = gl_TessCoord.xy; sides 0-3 run (0,0)-(1,0)-(1,1)-(0,1)-(0,0).
std::string quadEvaluationShader() {
  return "#version 450 core\nlayout(quads, equal_spacing, ccw) in;\n" + evaluationCommon() + R"(
void main() {
  int d = tcDomain[0];
  vec2 ab = gl_TessCoord.xy;
  if (ab.y == 0.0) {
    ab.x = alongSide(d, 0, ab.x);
  } else if (ab.x == 1.0) {
    ab.y = alongSide(d, 1, ab.y);
  } else if (ab.y == 1.0) {
    ab.x = 1.0 - alongSide(d, 2, 1.0 - ab.x);
  } else if (ab.x == 0.0) {
    ab.y = 1.0 - alongSide(d, 3, 1.0 - ab.y);
  }
  emit(d, ab, vec2(0.5));
}
)";
}

// Triangles: barycentric (u, v, w) with corner 0 at u = 1, corner 1 at v = 1, corner 2 at
// w = 1, so (a, b) = (v, w); side 0 is w = 0, side 1 u = 0, side 2 v = 0.
std::string triangleEvaluationShader() {
  return "#version 450 core\nlayout(triangles, equal_spacing, ccw) in;\n" + evaluationCommon() +
         R"(
void main() {
  int d = tcDomain[0];
  vec3 b = gl_TessCoord;
  if (b.z == 0.0) {
    float t = alongSide(d, 0, b.y);
    b = vec3(1.0 - t, t, 0.0);
  } else if (b.x == 0.0) {
    float t = alongSide(d, 1, b.z);
    b = vec3(0.0, 1.0 - t, t);
  } else if (b.y == 0.0) {
    float t = alongSide(d, 2, b.x);
    b = vec3(t, 0.0, 1.0 - t);
  }
  emit(d, b.yz, vec2(1.0 / 3.0));
}
)";
}

ShaderProgram makeProgram(const char* name, const std::string& evaluationSource) {
  return ShaderProgram(name,
                       {{GL_VERTEX_SHADER, vertexShader()},
                        {GL_TESS_CONTROL_SHADER, controlShader()},
                        {GL_TESS_EVALUATION_SHADER, evaluationSource}},
                       {"tePosition", "teNormal", "teLocal", "tePatch"});
}

void requireLimit(GLenum name, int needed, const char* what) {
  GLint value = 0;
  glGetIntegerv(name, &value);
  checkGl("querying the tessellation limits");
  if (value < needed) {
    throw std::runtime_error(std::string("gpu tessellation needs ") + std::to_string(needed) + " " +
                             what + "; this OpenGL has " + std::to_string(value));
  }
}

template <typename T>
void fill(GLuint buffer, const std::vector<T>& data) {
  // Never empty: a zero-sized storage buffer cannot be bound.
  static const T kNothing{};
  glNamedBufferData(buffer, static_cast<GLsizeiptr>(std::max<size_t>(data.size(), 1) * sizeof(T)),
                    data.empty() ? &kNothing : data.data(), GL_STREAM_DRAW);
}

// GL's levels for a domain from its sides' segments: outer[k] is the edge u = 0, v = 0, u = 1,
// v = 1 for quads, u = 0, v = 0, w = 0 for triangles (see the evaluation shaders' sides).
std::array<float, kLevelFloats> glLevels(bool triangle, const std::array<int, 4>& side) {
  if (triangle) {
    const int inner = std::max({side[0], side[1], side[2]});
    return {static_cast<float>(side[1]), static_cast<float>(side[2]),
            static_cast<float>(side[0]), 1.0f,
            static_cast<float>(inner),   1.0f};
  }
  return {static_cast<float>(side[3]),
          static_cast<float>(side[0]),
          static_cast<float>(side[1]),
          static_cast<float>(side[2]),
          static_cast<float>(std::max(side[0], side[2])),
          static_cast<float>(std::max(side[1], side[3]))};
}

// What GL makes of a domain at most: an inner grid of at most (levels + 2)^2 points, two
// triangles per cell, and one point and one triangle per outer segment.
struct DomainBound {
  size_t triangles = 0, vertices = 0;
};
DomainBound domainBound(bool triangle, const std::array<float, kLevelFloats>& levels) {
  const size_t outer =
      static_cast<size_t>(levels[0] + levels[1] + levels[2] + (triangle ? 0.0f : levels[3]));
  const size_t a = static_cast<size_t>(levels[4]) + 2;
  const size_t b = triangle ? a : static_cast<size_t>(levels[5]) + 2;
  return {2 * a * b + outer, a * b + outer};
}

// The draw state the tessellator sets, undone however it leaves (the rasterizer draws next).
struct DrawState {
  DrawState(GLuint framebuffer, GLuint vertexArray) {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glBindVertexArray(vertexArray);
    glPatchParameteri(GL_PATCH_VERTICES, 1);
    glEnable(GL_RASTERIZER_DISCARD);
  }
  ~DrawState() {
    glDisable(GL_RASTERIZER_DISCARD);
    glBindVertexArray(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  DrawState(const DrawState&) = delete;
  DrawState& operator=(const DrawState&) = delete;
};

}  // namespace

struct GpuPatchTessellator::Impl {
  int domainsPerDraw;
  int maxTessLevel = 0;
  ShaderProgram quads{makeProgram("quad patch", quadEvaluationShader())};
  ShaderProgram triangles{makeProgram("triangle patch", triangleEvaluationShader())};
  GLuint vertexArray = 0;
  GLuint buffers[kBindings] = {};
  GLuint feedback = 0;
  size_t feedbackBytes = 0;
  GLuint writtenQuery = 0, generatedQuery = 0;
  // Nothing is rasterised, but a draw needs a complete framebuffer and a surfaceless context
  // has no default one: a 1 x 1 framebuffer without attachments.
  GLuint framebuffer = 0;

  explicit Impl(int batch) : domainsPerDraw(std::max(1, batch)) {
    glGetIntegerv(GL_MAX_TESS_GEN_LEVEL, &maxTessLevel);
    glCreateFramebuffers(1, &framebuffer);
    glNamedFramebufferParameteri(framebuffer, GL_FRAMEBUFFER_DEFAULT_WIDTH, 1);
    glNamedFramebufferParameteri(framebuffer, GL_FRAMEBUFFER_DEFAULT_HEIGHT, 1);
    glCreateVertexArrays(1, &vertexArray);
    glCreateBuffers(kBindings, buffers);
    glCreateBuffers(1, &feedback);
    glCreateQueries(GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN, 1, &writtenQuery);
    glCreateQueries(GL_PRIMITIVES_GENERATED, 1, &generatedQuery);
    checkGl("creating the gpu tessellation objects");
  }
  ~Impl() {
    glDeleteQueries(1, &writtenQuery);
    glDeleteQueries(1, &generatedQuery);
    glDeleteBuffers(1, &feedback);
    glDeleteBuffers(kBindings, buffers);
    glDeleteVertexArrays(1, &vertexArray);
    glDeleteFramebuffers(1, &framebuffer);
  }

  void upload(const PatchSet& set, const TessellationPlan& plan,
              std::vector<std::array<float, kLevelFloats>>& levels) {
    std::vector<float> points;
    points.reserve(set.points().size() * 3);
    for (const Vec3& p : set.points()) {
      points.insert(points.end(),
                    {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
    }
    std::vector<int32_t> info, indices;
    for (const Patch& patch : set.patches()) {
      info.insert(
          info.end(),
          {static_cast<int32_t>(indices.size()), static_cast<int32_t>(patch.type),
           static_cast<int32_t>(patch.param.field0), static_cast<int32_t>(patch.param.field1)});
      for (int index : set.pointIndices(patch)) indices.push_back(index);
    }
    std::vector<float> frames, pieces, levelData;
    std::vector<int32_t> sides;
    levels.clear();
    for (size_t d = 0; d < plan.domains.size(); ++d) {
      const PatchDomain& domain = plan.domains[d];
      frames.insert(frames.end(),
                    {static_cast<float>(domain.origin.x), static_cast<float>(domain.origin.y),
                     static_cast<float>(domain.axisA.x), static_cast<float>(domain.axisA.y),
                     static_cast<float>(domain.axisB.x), static_cast<float>(domain.axisB.y)});
      sides.push_back(domain.patch);
      std::array<int, 4> segments{1, 1, 1, 1};
      for (int k = 0; k < 4; ++k) {
        const std::vector<SidePiece>& side = plan.sides[d][k];
        sides.insert(sides.end(),
                     {static_cast<int32_t>(pieces.size() / 2), static_cast<int32_t>(side.size())});
        if (k >= domain.corners()) continue;
        int upTo = 0;
        for (const SidePiece& piece : side) {
          upTo += piece.segments;
          pieces.insert(pieces.end(), {static_cast<float>(piece.end), static_cast<float>(upTo)});
        }
        if (upTo > maxTessLevel) {
          throw std::logic_error("gpu tessellation: a side has " + std::to_string(upTo) +
                                 " segments, over GL_MAX_TESS_GEN_LEVEL");
        }
        segments[k] = upTo;
      }
      levels.push_back(glLevels(domain.triangle, segments));
      levelData.insert(levelData.end(), levels.back().begin(), levels.back().end());
    }
    fill(buffers[kPoints], points);
    fill(buffers[kPatchInfo], info);
    fill(buffers[kPointIndices], indices);
    fill(buffers[kDomainFrames], frames);
    fill(buffers[kDomainSides], sides);
    fill(buffers[kPieces], pieces);
    fill(buffers[kLevels], levelData);
    for (GLuint b = 0; b < kBindings; ++b)
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, b, buffers[b]);
    checkGl("uploading the patches for gpu tessellation");
  }

  // Domains [first, first + count) drawn in one call; their triangles' vertices appended.
  void drawBatch(size_t first, size_t count, size_t bound, std::vector<CapturedVertex>& out) {
    const size_t bytes = bound * 3 * sizeof(CapturedVertex);
    if (bytes > feedbackBytes) {
      glNamedBufferData(feedback, static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_READ);
      feedbackBytes = bytes;
    }
    glBindBufferRange(GL_TRANSFORM_FEEDBACK_BUFFER, 0, feedback, 0, static_cast<GLsizeiptr>(bytes));
    glBeginQuery(GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN, writtenQuery);
    glBeginQuery(GL_PRIMITIVES_GENERATED, generatedQuery);
    glBeginTransformFeedback(GL_TRIANGLES);
    glDrawArrays(GL_PATCHES, static_cast<GLint>(first), static_cast<GLsizei>(count));
    glEndTransformFeedback();
    glEndQuery(GL_PRIMITIVES_GENERATED);
    glEndQuery(GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN);
    GLuint64 written = 0, generated = 0;
    glGetQueryObjectui64v(writtenQuery, GL_QUERY_RESULT, &written);
    glGetQueryObjectui64v(generatedQuery, GL_QUERY_RESULT, &generated);
    checkGl("drawing the patches through the tessellation stages");
    if (written != generated) {
      throw std::logic_error("gpu tessellation: the transform feedback buffer overflowed");
    }
    const size_t at = out.size();
    out.resize(at + written * 3);
    glGetNamedBufferSubData(feedback, 0,
                            static_cast<GLsizeiptr>(written * 3 * sizeof(CapturedVertex)),
                            out.data() + at);
    checkGl("reading back the tessellated patches");
  }
};

GpuPatchTessellator::GpuPatchTessellator(int domainsPerDraw) {
  requireLimit(GL_MAX_TESS_EVALUATION_SHADER_STORAGE_BLOCKS, 6,
               "storage buffers in the tessellation evaluation stage");
  requireLimit(GL_MAX_TESS_CONTROL_SHADER_STORAGE_BLOCKS, 1,
               "storage buffer in the tessellation control stage");
  impl_ = std::make_unique<Impl>(domainsPerDraw);
}

GpuPatchTessellator::~GpuPatchTessellator() = default;

int GpuPatchTessellator::maxTessLevel() const { return impl_->maxTessLevel; }

PatchMesh GpuPatchTessellator::tessellate(const PatchSet& set, const TessellationPlan& plan,
                                          const CancelToken& cancel, GpuTessellationStats* stats) {
  GpuTessellationStats counted;
  std::vector<std::array<float, kLevelFloats>> levels;
  impl_->upload(set, plan, levels);

  const bool triangle = set.scheme() == mesh::Scheme::Loop;
  const ShaderProgram& program = triangle ? impl_->triangles : impl_->quads;
  program.use();
  const subdiv::Displacement& displacement = set.displacement();
  program.setInt("displacementFunction", static_cast<int>(displacement.function()));
  program.setFloat("displacementAmplitude", static_cast<float>(displacement.amplitude()));
  program.setFloat("displacementWavenumber", static_cast<float>(displacement.wavenumber()));
  const Vec3 centre = displacement.centre();
  program.setVec3("displacementCentre", static_cast<float>(centre.x), static_cast<float>(centre.y),
                  static_cast<float>(centre.z));
  std::vector<CapturedVertex> captured;
  {
    const DrawState state(impl_->framebuffer, impl_->vertexArray);
    for (size_t first = 0; first < plan.domains.size();) {
      cancel.check();
      size_t count = 0;
      DomainBound bound;
      while (first + count < plan.domains.size() &&
             count < static_cast<size_t>(impl_->domainsPerDraw)) {
        const DomainBound more = domainBound(triangle, levels[first + count]);
        if (count > 0 && (bound.triangles + more.triangles > kMaxBatchTriangles ||
                          bound.vertices + more.vertices > kMaxBatchVertices)) {
          break;
        }
        bound.triangles += more.triangles;
        bound.vertices += more.vertices;
        ++count;
      }
      impl_->drawBatch(first, count, bound.triangles, captured);
      ++counted.draws;
      first += count;
    }
  }
  cancel.check();

  PatchMesh out;
  out.stats = plan.stats;
  tessellate::TriangleMesh& mesh = out.mesh;
  const size_t corners = captured.size(), triangles = corners / 3;
  mesh.positions.resize(corners);
  mesh.normals.resize(corners);
  mesh.indices.resize(corners);
  mesh.cornerUVs.resize(corners);
  mesh.triangleFaces.resize(triangles);
  out.trianglePatch.resize(triangles);
  const std::vector<Patch>& patches = set.patches();
  parallelFor(corners, 4096, [&](size_t begin, size_t end) {
    for (size_t c = begin; c < end; ++c) {
      const CapturedVertex& v = captured[c];
      if (v.patch < 0 || static_cast<size_t>(v.patch) >= patches.size()) {
        throw std::logic_error("gpu tessellation: a vertex names no patch");
      }
      const Patch& patch = patches[v.patch];
      mesh.positions[c] = Vec3f{v.position[0], v.position[1], v.position[2]};
      mesh.normals[c] = Vec3f{v.normal[0], v.normal[1], v.normal[2]};
      mesh.indices[c] = static_cast<uint32_t>(c);
      const Vec2 uv = set.toFaceUV(patch, v.local[0], v.local[1]);
      mesh.cornerUVs[c] = Vec2f{static_cast<float>(uv.x), static_cast<float>(uv.y)};
      if (c % 3 == 0) {
        mesh.triangleFaces[c / 3] = patch.baseFace;
        out.trianglePatch[c / 3] = v.patch;
      }
    }
  });
  if (stats) *stats = counted;
  return out;
}

}  // namespace limn::render::patches
