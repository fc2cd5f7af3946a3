// Camera: a resolved pinhole (perspective) or orthographic camera with an image size.
//
// Conventions used everywhere in limn (raster, reference, metrics):
//  - pixel (i, j) covers [i, i+1] x [j, j+1], row j = 0 is the TOP row of the image;
//  - the ray of a pixel goes through its centre (i + 0.5, j + 0.5);
//  - "depth" is linear depth along the viewing direction (eye-space distance, not NDC).
// CameraSpec holds what a request said; resolveCamera() fills what it left out from the
// surface's bounds (the default frames the bounding sphere from +Z). An Orbit places the eye
// by angles around the target instead of by position.
#pragma once

#include <array>
#include <optional>

#include "render/core/vec.h"

namespace limn::render {

enum class Projection { Perspective, Orthographic };

// The eye on a sphere around the target: azimuth about +Y from +Z towards +X, elevation up
// from the XZ plane (degrees), distance in bounding-sphere radii (none: the default framing).
// Azimuth 0, elevation 0 is the default view from +Z.
struct Orbit {
  double azimuthDeg = 0, elevationDeg = 0;
  std::optional<double> distance;
};

struct CameraSpec {
  std::optional<Vec3> eye, target, up;
  std::optional<Orbit> orbit;  // an alternative to eye (not both)
  std::optional<double> fovYDeg;
  std::optional<Projection> projection;
  std::optional<double> orthoHeight;
  std::optional<int> width, height;
};

struct Ray {
  Vec3 origin;
  Vec3 direction;  // unit length
};

class Camera {
 public:
  Camera(Vec3 eye, Vec3 target, Vec3 up, double fovYDeg, Projection projection, double orthoHeight,
         int width, int height, double nearPlane, double farPlane);

  // The same view at `factor` times the resolution in each direction (for supersampled masks).
  Camera scaled(int factor) const;

  Ray rayThrough(double px, double py) const;  // continuous pixel coordinates
  // Pixel coordinates (x right, y down) and linear depth of a world point.
  Vec3 project(const Vec3& p) const;
  double depthOf(const Vec3& p) const { return dot(p - eye_, forward_); }
  // Direction from the eye towards p (perspective) or the view direction (orthographic),
  // not normalised: the contour function is g = dot(n, viewVector(p)).
  Vec3 viewVector(const Vec3& p) const;
  // Size in pixels of one world unit seen at linear depth `depth`.
  double pixelsPerUnit(double depth) const;

  // Column-major 4x4 matrices for OpenGL (view, and projection with [near, far]).
  std::array<float, 16> viewMatrix() const;
  std::array<float, 16> projectionMatrix() const;

  const Vec3& eye() const { return eye_; }
  const Vec3& target() const { return target_; }
  const Vec3& up() const { return up_; }
  const Vec3& forward() const { return forward_; }
  const Vec3& right() const { return right_; }
  const Vec3& trueUp() const { return trueUp_; }
  double fovYDeg() const { return fovYDeg_; }
  Projection projection() const { return projection_; }
  double orthoHeight() const { return orthoHeight_; }
  int width() const { return width_; }
  int height() const { return height_; }
  double nearPlane() const { return near_; }
  double farPlane() const { return far_; }

 private:
  Vec3 eye_, target_, up_;
  double fovYDeg_;
  Projection projection_;
  double orthoHeight_;
  int width_, height_;
  double near_, far_;
  Vec3 forward_, right_, trueUp_;
  double tanHalfFov_;
};

// The image side a spec without width or height gets.
inline constexpr int kDefaultImageSide = 512;

// Fills what the spec leaves out: target = bounds centre, eye on +Z at a distance that frames
// the bounding sphere, up = +Y, 35 degrees, perspective, 512 x 512; orthoHeight frames the
// sphere. Near and far planes enclose the bounding sphere. With an orbit, the eye sits at its
// angles and distance from the target and `up` defaults to the sphere's local up (tilted with
// the elevation, so the view stays upright over the poles).
Camera resolveCamera(const CameraSpec& spec, const Bounds& bounds);

}  // namespace limn::render
