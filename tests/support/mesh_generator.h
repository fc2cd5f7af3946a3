// Hostile control meshes for fuzzing the engine (issue 23): small meshes that mix, several per
// mesh, what breaks subdivision code — non-manifold edges shared by 3-200 faces, non-manifold
// vertices (bow-ties, cones of sheets, fans and closed pieces welded at one vertex), valences 2
// to 512, n-gons up to maxFaceSize, holes, open sheets and Moebius strips, every boundary rule,
// creases and corners of every sharpness (0, semi-sharp, just under and over the infinite 10,
// huge), disconnected pieces, isolated vertices, zero-area faces, coincident vertices and
// faces, inconsistent winding, tiny and far-away pieces; Catmull-Clark, Loop (triangles only)
// and bilinear.
//
// Each mesh comes as a render::mesh::ControlMesh and as the OBJ text (with OpenSubdiv's `t` tag
// lines, written in the varied forms limn's OBJ reader accepts) that formats::readObj reads back
// as exactly that ControlMesh, so the same mesh can go through the HTTP API. A few meshes in a
// hundred are invalid on purpose (a crease off the mesh's edges, a face over maxFaceSize, a
// vertex over maxValence, a quad for Loop, ...): `refusal` says why, and limn must refuse them
// with a 4xx.
//
// The choices come from a ChoiceSource: a seed (SeededChoices: the same seed gives the same mesh
// on every standard library) or the bytes of a fuzz input (FuzzChoices: each choice consumes a
// few bytes, so libFuzzer's mutations steer it; an exhausted input gives the smallest choices).
// requestVariants() turns a mesh into the requests of every method, the same list for the
// fuzz target (fuzz/engine_fuzz.cpp) and the sweep through the server
// (tests/integration/generated_mesh_sweep_test.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "render/mesh/control_mesh.h"

namespace limn::testing {

// Where a generator's choices come from.
class ChoiceSource {
 public:
  virtual ~ChoiceSource() = default;
  // An integer in [lo, hi]; lo when the source is exhausted.
  int range(int lo, int hi);
  // A double in [0, 1); 0 when exhausted.
  virtual double unit() = 0;
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  // exp of a uniform log: scales and distances over orders of magnitude.
  double logUniform(double lo, double hi);
  // True with probability percent/100; false when exhausted.
  bool percent(int percent) { return range(0, 99) >= 100 - percent; }
  template <class T>
  const T& pick(const std::vector<T>& items) {
    return items[static_cast<size_t>(range(0, static_cast<int>(items.size()) - 1))];
  }

 protected:
  // `n` (1..64) random bits; 0 when exhausted.
  virtual uint64_t bits(int n) = 0;
};

class SeededChoices : public ChoiceSource {
 public:
  explicit SeededChoices(uint64_t seed) : rng_(seed) {}
  double unit() override;

 protected:
  uint64_t bits(int n) override;

 private:
  std::mt19937_64 rng_;
};

// Reads the fuzz input front to back: a choice of n bits takes ceil(n / 8) bytes.
class FuzzChoices : public ChoiceSource {
 public:
  FuzzChoices(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  double unit() override;
  size_t remaining() const { return size_ - pos_; }

 protected:
  uint64_t bits(int n) override;

 private:
  const uint8_t* data_;
  size_t size_, pos_ = 0;
};

struct GeneratorOptions {
  // Kept within so that every method at 32 x 32 stays cheap (the defaults of JobLimits are
  // far above these).
  int maxFaces = 400;
  int maxPieces = 5;
  // The highest valence made (faces around one vertex).
  int maxValence = 512;
  // The service's limits (its defaults), which valid meshes keep to and invalid ones exceed.
  int limitValence = 512;
  int maxFaceSize = 64;
  // Percent of meshes made invalid on purpose (`refusal` set).
  int invalidPercent = 4;
};

struct GeneratedMesh {
  render::mesh::ControlMesh mesh;
  std::string obj;  // reads back (formats::readObj) as `mesh`, unless `refusal` is set
  // What it is made of, for failure messages: "loop: fan(valence 300) book(17 pages) ...".
  std::string description;
  // Non-empty: the mesh is invalid on purpose and this says how ("crease off the edges"); the
  // service must answer 4xx.
  std::string refusal;
};

GeneratedMesh generateMesh(ChoiceSource& choices, const GeneratorOptions& options = {});
GeneratedMesh generateMesh(uint64_t seed, const GeneratorOptions& options = {});

// `text` as a JSON string literal, quotes included.
std::string jsonString(std::string_view text);
// {"format": "obj", "scheme": "...", "data": "<the OBJ text>"}
std::string objMeshJson(const GeneratedMesh& mesh);

// One request of a mesh to one endpoint.
struct RequestVariant {
  std::string path;    // "/v1/render", "/v1/tessellate", "/v1/silhouette", "/v1/compare"
  std::string accept;  // the Accept header ("" none)
  std::string label;   // "uniform masks level 2 reference", for failure messages
  std::string body;    // the JSON body, the mesh inline as OBJ
};

struct VariantOptions {
  int side = 32;              // camera width and height
  int referencePercent = 20;  // /v1/render requests that also ask for the reference
  int tessellatePercent = 50;
  int silhouettePercent = 50;
  int comparePercent = 25;
  // Off by default, because they make single requests cost seconds to a minute at 32 x 32
  // however small the mesh (both bounded only by the triangle limits; issue 23's findings):
  // the eye inside or right next to the surface (adaptive and patches dice edges by their
  // unclipped projected length, so edges near the eye reach maxTriangles), and a displaced
  // surface ray-cast by the reference (its tessellation resolves the bumps everywhere, up to
  // its 12M-triangle budget).
  bool eyeInside = false;
  bool displacedReference = false;
  // Method patches is left out for a mesh with a vertex of more faces than this: Far's patch
  // table around a vertex of valence n costs about n^3.7 and cannot be cancelled (valence 128:
  // 3 s, 256: 31 s, 512 — the default maxValence — 400 s; issue 23's findings).
  int maxPatchesValence = 128;
};

// Every method on /v1/render: coarse; uniform by engine opensubdiv, masks and factored at one
// level 0-3; adaptive; silhouette; patches diced by the CPU and by the GPU (unless a vertex is
// over maxPatchesValence); limit — some with
// "reference": true, with random outputs, shadings, cameras and params within the limits. Then
// (by the percentages) /v1/tessellate of one method, /v1/silhouette, and /v1/compare of a few.
std::vector<RequestVariant> requestVariants(const GeneratedMesh& mesh, ChoiceSource& choices,
                                            const VariantOptions& options = {});

}  // namespace limn::testing
