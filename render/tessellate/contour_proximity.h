// Where two parts' contours come close in the image.
//
// Two surfaces whose outlines meet at a small angle theta in the image (a leg leaving the body,
// an arm along the side) leave a slit between them that closes where their outlines meet; a
// surface error delta moves that point along the slit by delta / sin(theta). A tessellation
// whose contour is 0.03 px off closes such a slit pixels early. The tessellators dice the faces
// that hold those contours finer, and only those: the rest of the outline takes the error as is.
#pragma once

#include <functional>
#include <vector>

#include "render/core/camera.h"
#include "render/core/vec.h"

namespace limn::render::tessellate {

// The length in pixels of the polyline a-m-b as if seen face-on at m's depth. Where a face
// holds a silhouette its normal lies in the image plane there, so an edge's sag shows at full
// size however foreshortened the edge itself is (a lathed head's ring edges, seen end-on at its
// side, project to a fraction of a pixel and bulge by 0.3 px each at 512^2): such edges are
// diced by this length, as if they faced the eye.
inline double unforeshortenedPixels(const Camera& camera, const Vec3& a, const Vec3& m,
                                    const Vec3& b) {
  return (length(m - a) + length(b - m)) * camera.pixelsPerUnit(camera.depthOf(m));
}

// How close two parts' contours must come, in pixels, for their faces to be diced finer: a
// slit narrower than this is where a contour's error moves the slit's end most.
constexpr double kCrowdedContourPx = 1;

// A straight piece of a contour in the image (pixels), held by one face or patch.
struct ContourPiece {
  Vec2 a, b;
  int owner = 0;
};

// Per owner (0 .. ownerCount - 1): whether one of its pieces comes within `distancePx` of a
// piece of another owner that `adjacent(i, j)` does not call its neighbour (neighbours' pieces
// meet where the contour crosses from one to the next). Pieces outside `[0, width] x [0,
// height]` by more than `distancePx` are left out.
std::vector<char> ownersNearAnotherContour(const std::vector<ContourPiece>& pieces, int ownerCount,
                                           double distancePx, int width, int height,
                                           const std::function<bool(int, int)>& adjacent);

// The pieces of contour on a closed loop of image points whose `facing` values (view direction
// against normal) change sign between neighbours: each sign change is placed by linear
// interpolation, and consecutive changes are joined (all consecutive pairs round the loop when
// there are more than two, as the loop alone cannot say which pairs belong together).
void appendContourPieces(const std::vector<Vec2>& points, const std::vector<double>& facing,
                         int owner, std::vector<ContourPiece>& out);

}  // namespace limn::render::tessellate
