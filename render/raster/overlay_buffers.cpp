#include "render/raster/overlay_buffers.h"

#include <cmath>
#include <cstddef>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

#include "render/core/image.h"
#include "render/raster/gl_error.h"

namespace limn::render::raster {

namespace {

constexpr GLuint kPositionAttribute = 0;
constexpr GLuint kColorAttribute = 1;

// One end of a segment as the line program reads it.
struct LineVertex {
  Vec3f position;
  uint8_t color[4];
};
static_assert(sizeof(LineVertex) == 16, "LineVertex must be tightly packed");

bool isBuiltInPass(const std::string& name) {
  for (const char* builtIn :
       {pass::kColor, pass::kMask, pass::kDepth, pass::kNormal, pass::kWireframe}) {
    if (name == builtIn) return true;
  }
  return false;
}

}  // namespace

void validateOverlays(const std::vector<LineOverlay>& overlays) {
  std::set<std::string> names;
  for (const LineOverlay& overlay : overlays) {
    const std::string what = "raster: overlay \"" + overlay.pass + "\"";
    if (overlay.pass.empty()) throw std::invalid_argument("raster: an overlay has no pass name");
    if (isBuiltInPass(overlay.pass)) {
      throw std::invalid_argument(what + " has the name of a built-in pass");
    }
    if (!names.insert(overlay.pass).second) {
      throw std::invalid_argument(what + " is named twice");
    }
    if (overlay.points.size() % 2 != 0) {
      throw std::invalid_argument(what + " has an odd number of points (" +
                                  std::to_string(overlay.points.size()) + ")");
    }
    if (overlay.colors.size() != overlay.segmentCount()) {
      throw std::invalid_argument(what + " has " + std::to_string(overlay.colors.size()) +
                                  " colours for " + std::to_string(overlay.segmentCount()) +
                                  " segments");
    }
    for (const Vec3f& p : overlay.points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        throw std::invalid_argument(what + " has a non-finite point");
      }
    }
  }
}

OverlayBuffers::OverlayBuffers() {
  glCreateBuffers(1, &vertices_);
  glCreateVertexArrays(1, &array_);
  glVertexArrayVertexBuffer(array_, 0, vertices_, 0, sizeof(LineVertex));
  glVertexArrayAttribFormat(array_, kPositionAttribute, 3, GL_FLOAT, GL_FALSE,
                            offsetof(LineVertex, position));
  glVertexArrayAttribFormat(array_, kColorAttribute, 4, GL_UNSIGNED_BYTE, GL_TRUE,
                            offsetof(LineVertex, color));
  glVertexArrayAttribBinding(array_, kPositionAttribute, 0);
  glVertexArrayAttribBinding(array_, kColorAttribute, 0);
  glEnableVertexArrayAttrib(array_, kPositionAttribute);
  glEnableVertexArrayAttrib(array_, kColorAttribute);
  checkGl("creating the overlay buffers");
}

OverlayBuffers::~OverlayBuffers() {
  glDeleteVertexArrays(1, &array_);
  glDeleteBuffers(1, &vertices_);
}

void OverlayBuffers::upload(const std::vector<LineOverlay>& overlays) {
  std::vector<LineVertex> data;
  first_.clear();
  counts_.clear();
  for (const LineOverlay& overlay : overlays) {
    if (data.size() + overlay.points.size() >
        static_cast<size_t>(std::numeric_limits<GLint>::max())) {
      throw std::invalid_argument("raster: too many overlay segments for one render");
    }
    first_.push_back(static_cast<GLint>(data.size()));
    counts_.push_back(static_cast<GLsizei>(overlay.points.size()));
    for (size_t i = 0; i < overlay.points.size(); ++i) {
      const auto& c = overlay.colors[i / 2];
      data.push_back({overlay.points[i], {c[0], c[1], c[2], c[3]}});
    }
  }
  glNamedBufferData(vertices_, static_cast<GLsizeiptr>(data.size() * sizeof(LineVertex)),
                    data.empty() ? nullptr : data.data(), GL_STREAM_DRAW);
  checkGl("uploading the overlays (out of GPU memory?)");
}

void OverlayBuffers::draw(size_t index) const {
  if (counts_[index] == 0) return;
  glBindVertexArray(array_);
  glDrawArrays(GL_LINES, first_[index], counts_[index]);
}

}  // namespace limn::render::raster
