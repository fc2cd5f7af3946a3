#include "render/subdiv/far_limit.h"

#include <opensubdiv/sdc/bilinearScheme.h>
#include <opensubdiv/sdc/catmarkScheme.h>
#include <opensubdiv/sdc/loopScheme.h>

#include "render/core/parallel.h"

namespace limn::render::subdiv {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

namespace {

// One vertex of a Far level as Sdc's mask queries see it (its VERTEX interface).
class Neighborhood {
 public:
  Neighborhood(const Far::TopologyLevel& level, int vertex) : level_(level), vertex_(vertex) {}
  int GetNumEdges() const { return level_.GetVertexEdges(vertex_).size(); }
  int GetNumFaces() const { return level_.GetVertexFaces(vertex_).size(); }
  float GetSharpness() const { return level_.GetVertexSharpness(vertex_); }
  float* GetSharpnessPerEdge(float sharpness[]) const {
    Far::ConstIndexArray edges = level_.GetVertexEdges(vertex_);
    for (int i = 0; i < edges.size(); ++i) sharpness[i] = level_.GetEdgeSharpness(edges[i]);
    return sharpness;
  }

 private:
  const Far::TopologyLevel& level_;
  int vertex_;
};

// Sdc's MASK interface over weights sized for one vertex's edges and faces.
class Mask {
 public:
  using Weight = double;
  void reserve(int edges, int faces) {
    edge_.assign(static_cast<size_t>(edges), 0.0);
    face_.assign(static_cast<size_t>(faces), 0.0);
  }
  double& VertexWeight(int) { return vertex_; }
  double& EdgeWeight(int i) { return edge_[static_cast<size_t>(i)]; }
  double& FaceWeight(int i) { return face_[static_cast<size_t>(i)]; }
  int GetNumVertexWeights() const { return 1; }
  int GetNumEdgeWeights() const { return edgeCount_; }
  int GetNumFaceWeights() const { return faceCount_; }
  void SetNumVertexWeights(int) {}
  void SetNumEdgeWeights(int n) { edgeCount_ = n; }
  void SetNumFaceWeights(int n) { faceCount_ = n; }
  bool AreFaceWeightsForFaceCenters() const { return false; }
  void SetFaceWeightsForFaceCenters(bool) {}

  // The weighted sum over the vertex, the far ends of its edges and its faces' opposite
  // vertices; smallest weights first, as Far adds them, for precision.
  FarPoint apply(const FarPoint* src, int vertex, const std::vector<int>& edgeEnds,
                 const std::vector<int>& faceOpposite) const {
    FarPoint out;
    for (int i = 0; i < faceCount_; ++i)
      out.AddWithWeight(src[faceOpposite[size_t(i)]], face_[size_t(i)]);
    for (int i = 0; i < edgeCount_; ++i)
      out.AddWithWeight(src[edgeEnds[size_t(i)]], edge_[size_t(i)]);
    out.AddWithWeight(src[vertex], vertex_);
    return out;
  }

 private:
  double vertex_ = 0;
  std::vector<double> edge_, face_;
  int edgeCount_ = 0, faceCount_ = 0;
};

template <Sdc::SchemeType kScheme>
void limitWith(const Far::TopologyRefiner& refiner, const FarPoint* src,
               std::vector<FarPoint>& limit, std::vector<FarPoint>& du, std::vector<FarPoint>& dv) {
  const Far::TopologyLevel& level = refiner.GetLevel(refiner.GetMaxLevel());
  const Sdc::Scheme<kScheme> scheme(refiner.GetSchemeOptions());
  const int vertexCount = level.GetNumVertices();
  limit.assign(size_t(vertexCount), FarPoint{});
  du.assign(size_t(vertexCount), FarPoint{});
  dv.assign(size_t(vertexCount), FarPoint{});
  // Every vertex's masks from its own neighbourhood: chunks of vertices in parallel, each with
  // its own buffers.
  parallelFor(vertexCount, 8192, [&](size_t begin, size_t end) {
    Mask position, tangent1, tangent2;
    std::vector<int> edgeEnds, faceOpposite;
    for (int v = static_cast<int>(begin); v < static_cast<int>(end); ++v) {
      Far::ConstIndexArray edges = level.GetVertexEdges(v);
      Far::ConstIndexArray faces = level.GetVertexFaces(v);
      if (edges.size() == 0) {
        limit[size_t(v)] = src[v];
        continue;
      }
      // Every mask has room for all of this vertex's edges and faces.
      for (Mask* mask : {&position, &tangent1, &tangent2})
        mask->reserve(edges.size(), faces.size());
      scheme.ComputeVertexLimitMask(Neighborhood(level, v), position, tangent1, tangent2,
                                    level.GetVertexRule(v));

      edgeEnds.resize(size_t(edges.size()));
      for (int i = 0; i < edges.size(); ++i) {
        Far::ConstIndexArray ends = level.GetEdgeVertices(edges[i]);
        edgeEnds[size_t(i)] = ends[0] == v ? ends[1] : ends[0];
      }
      faceOpposite.resize(size_t(faces.size()));
      Far::ConstLocalIndexArray inFace = level.GetVertexFaceLocalIndices(v);
      for (int i = 0; i < faces.size(); ++i) {
        Far::ConstIndexArray corners = level.GetFaceVertices(faces[i]);
        faceOpposite[size_t(i)] = corners[(inFace[i] + 2) % corners.size()];
      }
      limit[size_t(v)] = position.apply(src, v, edgeEnds, faceOpposite);
      du[size_t(v)] = tangent1.apply(src, v, edgeEnds, faceOpposite);
      dv[size_t(v)] = tangent2.apply(src, v, edgeEnds, faceOpposite);
    }
  });
}

}  // namespace

void limitOfLastLevel(const Far::TopologyRefiner& refiner, const FarPoint* src,
                      std::vector<FarPoint>& limit, std::vector<FarPoint>& du,
                      std::vector<FarPoint>& dv) {
  switch (refiner.GetSchemeType()) {
    case Sdc::SCHEME_CATMARK:
      return limitWith<Sdc::SCHEME_CATMARK>(refiner, src, limit, du, dv);
    case Sdc::SCHEME_LOOP:
      return limitWith<Sdc::SCHEME_LOOP>(refiner, src, limit, du, dv);
    case Sdc::SCHEME_BILINEAR:
      return limitWith<Sdc::SCHEME_BILINEAR>(refiner, src, limit, du, dv);
  }
}

}  // namespace limn::render::subdiv
