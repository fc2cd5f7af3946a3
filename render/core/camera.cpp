#include "render/core/camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace limn::render {

namespace {
double radians(double deg) { return deg * std::numbers::pi / 180.0; }
}  // namespace

Camera::Camera(Vec3 eye, Vec3 target, Vec3 up, double fovYDeg, Projection projection,
               double orthoHeight, int width, int height, double nearPlane, double farPlane)
    : eye_(eye),
      target_(target),
      up_(up),
      fovYDeg_(fovYDeg),
      projection_(projection),
      orthoHeight_(orthoHeight),
      width_(width),
      height_(height),
      near_(nearPlane),
      far_(farPlane) {
  forward_ = normalize(target - eye);
  right_ = normalize(cross(forward_, up));
  if (length(right_) == 0) {  // up parallel to the view: pick any perpendicular
    Vec3 alt = std::fabs(forward_.y) < 0.9 ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
    right_ = normalize(cross(forward_, alt));
  }
  trueUp_ = cross(right_, forward_);
  tanHalfFov_ = std::tan(radians(fovYDeg) * 0.5);
}

Camera Camera::scaled(int factor) const {
  return Camera(eye_, target_, up_, fovYDeg_, projection_, orthoHeight_, width_ * factor,
                height_ * factor, near_, far_);
}

Ray Camera::rayThrough(double px, double py) const {
  // Normalised device coordinates in [-1, 1], y up.
  double ndcX = 2.0 * px / width_ - 1.0;
  double ndcY = 1.0 - 2.0 * py / height_;
  double aspect = static_cast<double>(width_) / height_;
  if (projection_ == Projection::Perspective) {
    Vec3 dir = forward_ + right_ * (ndcX * tanHalfFov_ * aspect) + trueUp_ * (ndcY * tanHalfFov_);
    return {eye_, normalize(dir)};
  }
  double halfH = orthoHeight_ * 0.5;
  Vec3 origin = eye_ + right_ * (ndcX * halfH * aspect) + trueUp_ * (ndcY * halfH);
  return {origin, forward_};
}

Vec3 Camera::project(const Vec3& p) const {
  Vec3 d = p - eye_;
  double z = dot(d, forward_);
  double x = dot(d, right_);
  double y = dot(d, trueUp_);
  double aspect = static_cast<double>(width_) / height_;
  double ndcX, ndcY;
  if (projection_ == Projection::Perspective) {
    ndcX = x / (z * tanHalfFov_ * aspect);
    ndcY = y / (z * tanHalfFov_);
  } else {
    double halfH = orthoHeight_ * 0.5;
    ndcX = x / (halfH * aspect);
    ndcY = y / halfH;
  }
  return {(ndcX + 1.0) * 0.5 * width_, (1.0 - ndcY) * 0.5 * height_, z};
}

Vec3 Camera::viewVector(const Vec3& p) const {
  return projection_ == Projection::Perspective ? p - eye_ : forward_;
}

double Camera::pixelsPerUnit(double depth) const {
  if (projection_ == Projection::Perspective) {
    return height_ / (2.0 * std::max(depth, 1e-9) * tanHalfFov_);
  }
  return height_ / orthoHeight_;
}

std::array<float, 16> Camera::viewMatrix() const {
  // Rows of the rotation are right, trueUp, -forward (OpenGL looks down -Z).
  std::array<float, 16> m{};
  const Vec3 axes[3] = {right_, trueUp_, -forward_};
  for (int row = 0; row < 3; ++row) {
    m[0 * 4 + row] = static_cast<float>(axes[row].x);
    m[1 * 4 + row] = static_cast<float>(axes[row].y);
    m[2 * 4 + row] = static_cast<float>(axes[row].z);
    m[3 * 4 + row] = static_cast<float>(-dot(axes[row], eye_));
  }
  m[15] = 1.0f;
  return m;
}

std::array<float, 16> Camera::projectionMatrix() const {
  std::array<float, 16> m{};
  double aspect = static_cast<double>(width_) / height_;
  double n = near_, f = far_;
  if (projection_ == Projection::Perspective) {
    double t = 1.0 / tanHalfFov_;
    m[0] = static_cast<float>(t / aspect);
    m[5] = static_cast<float>(t);
    m[10] = static_cast<float>((f + n) / (n - f));
    m[11] = -1.0f;
    m[14] = static_cast<float>(2.0 * f * n / (n - f));
  } else {
    double halfH = orthoHeight_ * 0.5;
    m[0] = static_cast<float>(1.0 / (halfH * aspect));
    m[5] = static_cast<float>(1.0 / halfH);
    m[10] = static_cast<float>(-2.0 / (f - n));
    m[14] = static_cast<float>(-(f + n) / (f - n));
    m[15] = 1.0f;
  }
  return m;
}

Camera resolveCamera(const CameraSpec& spec, const Bounds& bounds) {
  Vec3 center = bounds.empty() ? Vec3{0, 0, 0} : bounds.center();
  double radius = std::max(bounds.diagonal() * 0.5, 1e-6);
  double fov = spec.fovYDeg.value_or(35.0);
  Projection projection = spec.projection.value_or(Projection::Perspective);
  Vec3 target = spec.target.value_or(center);
  // Distance at which the bounding sphere fills the vertical field of view with a margin.
  double distance = radius / std::sin(radians(fov) * 0.5) * 1.05;
  Vec3 eye = spec.eye.value_or(target + Vec3{0, 0, distance});
  Vec3 up = spec.up.value_or(Vec3{0, 1, 0});
  if (spec.orbit) {
    const double az = radians(spec.orbit->azimuthDeg), el = radians(spec.orbit->elevationDeg);
    const Vec3 toEye{std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az)};
    eye = target + toEye * (spec.orbit->distance ? *spec.orbit->distance * radius : distance);
    // d(toEye)/d(elevation): perpendicular to the view, "up" on the sphere at any elevation.
    up = spec.up.value_or(
        Vec3{-std::sin(el) * std::sin(az), std::cos(el), -std::sin(el) * std::cos(az)});
  }
  double orthoHeight = spec.orthoHeight.value_or(radius * 2.1);
  int width = spec.width.value_or(kDefaultImageSide);
  int height = spec.height.value_or(kDefaultImageSide);

  // Near/far enclose the bounding sphere as seen along the view direction.
  Vec3 forward = normalize(target - eye);
  double centerDepth = dot(center - eye, forward);
  double nearPlane = std::max(centerDepth - radius * 1.01, radius * 1e-3);
  double farPlane = std::max(centerDepth + radius * 1.01, nearPlane * 2.0);
  if (projection == Projection::Orthographic) {
    nearPlane = centerDepth - radius * 1.01;  // orthographic may look from inside: any sign
  }
  return Camera(eye, target, up, fov, projection, orthoHeight, width, height, nearPlane, farPlane);
}

}  // namespace limn::render
