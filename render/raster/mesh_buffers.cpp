#include "render/raster/mesh_buffers.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/raster/gl_error.h"

namespace limn::render::raster {

namespace {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "Vec3f must be three packed floats");
static_assert(sizeof(Vec2f) == 2 * sizeof(float), "Vec2f must be two packed floats");

constexpr GLuint kPositionAttribute = 0;
constexpr GLuint kNormalAttribute = 1;
constexpr GLuint kTexcoordAttribute = 2;
constexpr GLuint kAlbedoAttribute = 3;

void checkIndices(const std::vector<uint32_t>& indices, size_t groupSize, size_t vertexCount,
                  const char* what) {
  if (indices.size() % groupSize != 0) {
    throw std::invalid_argument(std::string("raster: the number of ") + what + " indices (" +
                                std::to_string(indices.size()) + ") is not a multiple of " +
                                std::to_string(groupSize));
  }
  if (indices.size() > static_cast<size_t>(std::numeric_limits<GLsizei>::max())) {
    throw std::invalid_argument(std::string("raster: too many ") + what + " indices for one draw");
  }
  auto worst = std::max_element(indices.begin(), indices.end());
  if (worst != indices.end() && *worst >= vertexCount) {
    throw std::invalid_argument(std::string("raster: ") + what + " index " +
                                std::to_string(*worst) + " is out of range (" +
                                std::to_string(vertexCount) + " vertices)");
  }
}

template <typename T>
void fill(GLuint buffer, const std::vector<T>& data) {
  // Replacing the storage (rather than sub-updating) lets the driver orphan the old one.
  glNamedBufferData(buffer, static_cast<GLsizeiptr>(data.size() * sizeof(T)),
                    data.empty() ? nullptr : data.data(), GL_STREAM_DRAW);
}

void describePositions(GLuint array, GLuint positions) {
  glVertexArrayVertexBuffer(array, kPositionAttribute, positions, 0, sizeof(Vec3f));
  glVertexArrayAttribFormat(array, kPositionAttribute, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(array, kPositionAttribute, kPositionAttribute);
  glEnableVertexArrayAttrib(array, kPositionAttribute);
}

}  // namespace

MeshBuffers::MeshBuffers() {
  GLuint buffers[6];
  glCreateBuffers(6, buffers);
  positions_ = buffers[0];
  normals_ = buffers[1];
  triangleIndices_ = buffers[2];
  lineIndices_ = buffers[3];
  texcoords_ = buffers[4];
  albedo_ = buffers[5];
  glCreateVertexArrays(1, &triangleArray_);
  glCreateVertexArrays(1, &lineArray_);

  describePositions(triangleArray_, positions_);
  glVertexArrayVertexBuffer(triangleArray_, kNormalAttribute, normals_, 0, sizeof(Vec3f));
  glVertexArrayAttribFormat(triangleArray_, kNormalAttribute, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(triangleArray_, kNormalAttribute, kNormalAttribute);
  glVertexArrayVertexBuffer(triangleArray_, kTexcoordAttribute, texcoords_, 0, sizeof(Vec2f));
  glVertexArrayAttribFormat(triangleArray_, kTexcoordAttribute, 2, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(triangleArray_, kTexcoordAttribute, kTexcoordAttribute);
  glVertexArrayVertexBuffer(triangleArray_, kAlbedoAttribute, albedo_, 0, sizeof(Vec3f));
  glVertexArrayAttribFormat(triangleArray_, kAlbedoAttribute, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(triangleArray_, kAlbedoAttribute, kAlbedoAttribute);
  glVertexArrayElementBuffer(triangleArray_, triangleIndices_);

  describePositions(lineArray_, positions_);
  glVertexArrayElementBuffer(lineArray_, lineIndices_);
  checkGl("creating the mesh buffers");
}

MeshBuffers::~MeshBuffers() {
  GLuint arrays[2] = {triangleArray_, lineArray_};
  glDeleteVertexArrays(2, arrays);
  GLuint buffers[6] = {positions_, normals_, triangleIndices_, lineIndices_, texcoords_, albedo_};
  glDeleteBuffers(6, buffers);
}

void MeshBuffers::upload(const tessellate::TriangleMesh& mesh, bool withTexcoords) {
  const size_t vertexCount = mesh.positions.size();
  checkIndices(mesh.indices, 3, vertexCount, "triangle");
  checkIndices(mesh.lines, 2, vertexCount, "line");
  if (!mesh.normals.empty() && mesh.normals.size() != vertexCount) {
    throw std::invalid_argument("raster: " + std::to_string(mesh.normals.size()) + " normals for " +
                                std::to_string(vertexCount) + " vertices");
  }
  if (!mesh.texcoords.empty() && mesh.texcoords.size() != vertexCount) {
    throw std::invalid_argument("raster: " + std::to_string(mesh.texcoords.size()) +
                                " texture coordinates for " + std::to_string(vertexCount) +
                                " vertices");
  }

  if (!mesh.albedo.empty() && mesh.albedo.size() != vertexCount) {
    throw std::invalid_argument("raster: " + std::to_string(mesh.albedo.size()) +
                                " albedo colours for " + std::to_string(vertexCount) + " vertices");
  }

  fill(positions_, mesh.positions);
  fill(triangleIndices_, mesh.indices);
  fill(lineIndices_, mesh.lines);
  hasNormals_ = !mesh.normals.empty();
  if (hasNormals_) {
    fill(normals_, mesh.normals);
    glEnableVertexArrayAttrib(triangleArray_, kNormalAttribute);
  } else {
    // A zero normal makes the fragment shader fall back to the face normal.
    glDisableVertexArrayAttrib(triangleArray_, kNormalAttribute);
    glVertexAttrib3f(kNormalAttribute, 0.0f, 0.0f, 0.0f);
  }
  if (withTexcoords && !mesh.texcoords.empty()) {
    fill(texcoords_, mesh.texcoords);
    glEnableVertexArrayAttrib(triangleArray_, kTexcoordAttribute);
  } else {
    glDisableVertexArrayAttrib(triangleArray_, kTexcoordAttribute);
    glVertexAttrib2f(kTexcoordAttribute, 0.0f, 0.0f);
  }
  if (!mesh.albedo.empty()) {
    fill(albedo_, mesh.albedo);
    glEnableVertexArrayAttrib(triangleArray_, kAlbedoAttribute);
  } else {
    // A negative albedo makes the fragment shader use the front albedo.
    glDisableVertexArrayAttrib(triangleArray_, kAlbedoAttribute);
    glVertexAttrib3f(kAlbedoAttribute, -1.0f, -1.0f, -1.0f);
  }
  triangleIndexCount_ = static_cast<GLsizei>(mesh.indices.size());
  lineIndexCount_ = static_cast<GLsizei>(mesh.lines.size());
  checkGl("uploading the mesh (out of GPU memory?)");
}

void MeshBuffers::drawTriangles() const {
  if (triangleIndexCount_ == 0) return;
  glBindVertexArray(triangleArray_);
  glDrawElements(GL_TRIANGLES, triangleIndexCount_, GL_UNSIGNED_INT, nullptr);
}

void MeshBuffers::drawEdges() const {
  if (lineIndexCount_ > 0) {
    glBindVertexArray(lineArray_);
    glDrawElements(GL_LINES, lineIndexCount_, GL_UNSIGNED_INT, nullptr);
    return;
  }
  if (triangleIndexCount_ == 0) return;
  glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
  glBindVertexArray(triangleArray_);
  glDrawElements(GL_TRIANGLES, triangleIndexCount_, GL_UNSIGNED_INT, nullptr);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
}

}  // namespace limn::render::raster
