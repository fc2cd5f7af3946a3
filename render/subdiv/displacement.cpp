#include "render/subdiv/displacement.h"

#include <cmath>
#include <numbers>
#include <sstream>

namespace limn::render::subdiv {

const char* displacementFunctionName(DisplacementFunction function) {
  switch (function) {
    case DisplacementFunction::None:
      return "none";
    case DisplacementFunction::Bumps:
      return "bumps";
    case DisplacementFunction::Ripples:
      return "ripples";
  }
  return "?";
}

std::string DisplacementSpec::key() const {
  if (!enabled()) return "";
  std::ostringstream out;
  out.precision(17);
  out << displacementFunctionName(function) << ":" << amplitude << ":" << frequency;
  return out.str();
}

Displacement::Displacement(const DisplacementSpec& spec, const Bounds& controlBounds) {
  if (!spec.enabled() || controlBounds.empty()) return;
  const double diagonal = controlBounds.diagonal();
  function_ = spec.function;
  amplitude_ = spec.amplitude * diagonal;
  wavenumber_ = diagonal > 0 ? 2 * std::numbers::pi * spec.frequency / diagonal : 0;
  centre_ = controlBounds.center();
}

double Displacement::value(const Vec3& p, Vec3* gradient) const {
  const Vec3 q = p - centre_;
  const double k = wavenumber_, a = amplitude_;
  switch (function_) {
    case DisplacementFunction::None:
      break;
    case DisplacementFunction::Bumps: {
      const double sx = std::sin(k * q.x), sy = std::sin(k * q.y), sz = std::sin(k * q.z);
      if (gradient) {
        *gradient = Vec3{std::cos(k * q.x) * sy * sz, sx * std::cos(k * q.y) * sz,
                         sx * sy * std::cos(k * q.z)} *
                    (a * k);
      }
      return a * sx * sy * sz;
    }
    case DisplacementFunction::Ripples: {
      const double r = length(q);
      // At the centre the gradient's direction is undefined; its size is a k there.
      if (gradient) *gradient = r > 0 ? q * (a * k * std::cos(k * r) / r) : Vec3{0, 0, 0};
      return a * std::sin(k * r);
    }
  }
  if (gradient) *gradient = Vec3{0, 0, 0};
  return 0;
}

bool displace(const Displacement& displacement, const SurfaceJet& s, Vec3& position, Vec3& du,
              Vec3& dv) {
  const Vec3 cross_uv = cross(s.du, s.dv);
  const double area = length(cross_uv);
  const double scale = dot(s.du, s.du) + dot(s.dv, s.dv);
  if (!(area > 1e-10 * scale)) return false;
  const Vec3 n = cross_uv / area;
  // First (E, F, G) and second (e, f, g) fundamental forms.
  const double E = dot(s.du, s.du), F = dot(s.du, s.dv), G = dot(s.dv, s.dv);
  const double e = dot(s.duu, n), f = dot(s.duv, n), g = dot(s.dvv, n);
  const double det = E * G - F * F;  // = area^2 > 0
  // Weingarten: N_u = ((fF - eG) s_u + (eF - fE) s_v) / det, N_v likewise.
  const Vec3 nu = (s.du * (f * F - e * G) + s.dv * (e * F - f * E)) / det;
  const Vec3 nv = (s.du * (g * F - f * G) + s.dv * (f * F - g * E)) / det;
  Vec3 gradient;
  const double d = displacement.value(s.position, &gradient);
  position = s.position + n * d;
  du = s.du + nu * d + n * dot(gradient, s.du);
  dv = s.dv + nv * d + n * dot(gradient, s.dv);
  return true;
}

}  // namespace limn::render::subdiv
