// The silhouette method from seeded random views (issue 10's harness as a test; the benchmark
// bench/silhouette_views_bench.cpp prints the full distribution at 1024^2): every one of the
// project's own shapes and of the corpus's Catmull-Clark and Loop shapes, seen from four random
// cameras at 512^2 (perspective and orthographic, any up vector, 1.5-4 bounding radii away),
// against the exact reference. What a user would notice: an outline off by more than a pixel.
//   closed shapes: every view within 1 px;
//   open shapes (boundaries, holes, non-manifold edges): every view within 3 px, and at most one
//   of the four over 1 px.
// and on closed shapes no band of wrong-side pixels (back faces or wrong-sided normals showing
// along a contour, tests/support/wrong_side.h) beyond kMaxBandPixels.
// A failure prints the camera, which reproduces the view through /v1/render.
//
// Known open case (issue 10's closing note), held to what it reaches today so that it cannot get
// worse unseen: one open corpus shape with two of four views at 1.25 px (loop_triangle_edgecorner:
// boundary corners seen edge-on).
#include <gtest/gtest.h>

#include <cstdio>

#include "render/pipeline/compare.h"
#include "render/raster/rasterizer.h"
#include "render/subdiv/limit_surface.h"
#include "tests/support/random_views.h"
#include "tests/support/shapes.h"
#include "tests/support/wrong_side.h"

namespace limn::testing {
// GoogleTest names a parameter by this rather than by dumping its bytes.
void PrintTo(const NamedMesh& shape, std::ostream* out) { *out << shape.name; }
}  // namespace limn::testing

namespace limn::render {
namespace {

constexpr int kViews = 4;
constexpr int kSide = 512;
constexpr uint64_t kSeed = 7;
constexpr long kMaxBandPixels = 100;

struct Allowance {
  double maxPx;
  int viewsOverOnePixel;
};

Allowance allowanceFor(const std::string& shape, bool closed) {
  if (shape == "loop_triangle_edgecorner") return {1.5, 2};
  return closed ? Allowance{1.0, 0} : Allowance{3.0, 1};
}

std::vector<testing::NamedMesh> everyShape() {
  std::vector<testing::NamedMesh> shapes = testing::ownShapes();
  for (auto& s : testing::corpusShapes()) shapes.push_back(std::move(s));
  return shapes;
}

class SilhouetteViews : public ::testing::TestWithParam<testing::NamedMesh> {};

TEST_P(SilhouetteViews, OutlineWithinAPixelFromRandomViews) {
  const testing::NamedMesh& shape = GetParam();
  pipeline::CompareJob job;
  job.mesh = shape.mesh;
  subdiv::LimitSurface surface(shape.mesh);
  for (const auto& view : testing::randomViews(surface.bounds(), kViews,
                                               testing::viewSeed(kSeed, shape.name), kSide)) {
    job.cameras.push_back(view.camera);
  }
  job.methods.push_back({pipeline::Method::Silhouette, {}, Shading::Smooth});
  job.outputs = {.color = true};
  raster::Rasterizer rasterizer;
  pipeline::RenderContext context{.rasterizer = &rasterizer};
  pipeline::CompareResult result = pipeline::compare(job, {}, context, CancelToken());

  const bool closed = testing::isClosedClass(testing::shapeClass(shape.mesh));
  const Allowance allowed = allowanceFor(shape.name, closed);
  int overOnePixel = 0;
  for (size_t c = 0; c < result.rows.size(); ++c) {
    const pipeline::CompareRow& row = result.rows[c];
    const std::string camera = testing::describeCamera(job.cameras[c]);
    ASSERT_FALSE(row.error) << row.error->message << "\ncamera " << camera;
    const double px = row.metrics.silhouette->hausdorffPx;
    overOnePixel += px > 1.0;
    EXPECT_LE(px, allowed.maxPx) << shape.name << " view " << c << "\ncamera " << camera;
    const testing::WrongSide wrong = testing::wrongSidePixels(
        *row.images.find(pass::kColor), *result.references[c].images.find(pass::kColor));
    std::printf("%s view %zu: %.3f px, %ld wrong-side px, %ld in bands\n", shape.name.c_str(), c,
                px, wrong.pixels, wrong.inBands);
    if (closed) {
      EXPECT_LE(wrong.inBands, kMaxBandPixels)
          << shape.name << " view " << c << "\ncamera " << camera;
    }
  }
  EXPECT_LE(overOnePixel, allowed.viewsOverOnePixel) << shape.name;
}

INSTANTIATE_TEST_SUITE_P(Shapes, SilhouetteViews, ::testing::ValuesIn(everyShape()),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace limn::render
