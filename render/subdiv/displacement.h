// Analytic displacement: the limit surface s(u, v) moved along its unit normal N(u, v) by a
// scalar field D read at the undisplaced point,
//
//   f(u, v) = s(u, v) + N(u, v) D(s(u, v)).
//
// D is a named procedural function of the point in space, so it is continuous across faces and
// patches whatever their parameterisation, and the patches and the reference displace the same
// surface. f's derivatives are exact:
//
//   f_u = s_u + N_u D + N (grad D . s_u),   f_v likewise,
//
// with N_u and N_v from the Weingarten equations (the shape operator, from the first and second
// fundamental forms of s), so normals of f follow the displacement without finite differences.
#pragma once

#include <string>

#include "render/core/vec.h"

namespace limn::render::subdiv {

// (The values are the GPU tessellator's: patches/gpu_tessellation.cpp.)
enum class DisplacementFunction {
  None = 0,
  // D = a sin(k x) sin(k y) sin(k z) about the mesh's centre: a lattice of bumps and dents.
  Bumps = 1,
  // D = a sin(k |p - centre|): concentric waves around the mesh's centre.
  Ripples = 2,
};

// What a request asks for, in the mesh's own scale: `amplitude` is a fraction of the control
// mesh's bounding-box diagonal, `frequency` the number of waves along that diagonal.
struct DisplacementSpec {
  DisplacementFunction function = DisplacementFunction::None;
  double amplitude = 0;
  double frequency = 0;

  bool enabled() const { return function != DisplacementFunction::None && amplitude != 0; }
  // Names the displacement for cache keys ("" when none).
  std::string key() const;
};

const char* displacementFunctionName(DisplacementFunction function);

// The limits a request is checked against: beyond them the bumps are steeper than the
// reference's outline search and the patches' dicing are made to resolve (the slope a * k
// stays below about 2.5).
inline constexpr double kMaxDisplacementAmplitude = 0.05;
inline constexpr double kMaxDisplacementFrequency = 8;

// A DisplacementSpec resolved against one mesh's bounds: world units.
class Displacement {
 public:
  Displacement() = default;
  Displacement(const DisplacementSpec& spec, const Bounds& controlBounds);

  bool enabled() const { return amplitude_ != 0; }
  // |D| never exceeds this: how far the surface may leave the undisplaced one.
  double reach() const { return std::fabs(amplitude_); }
  // D(p) and its gradient.
  double value(const Vec3& p, Vec3* gradient) const;
  // What value() computes with (the GPU tessellator's uniforms).
  DisplacementFunction function() const { return function_; }
  double amplitude() const { return amplitude_; }
  double wavenumber() const { return wavenumber_; }
  Vec3 centre() const { return centre_; }

 private:
  DisplacementFunction function_ = DisplacementFunction::None;
  double amplitude_ = 0;   // world units
  double wavenumber_ = 0;  // radians per world unit
  Vec3 centre_{0, 0, 0};
};

// A point of the undisplaced surface with its first and second derivatives.
struct SurfaceJet {
  Vec3 position, du, dv, duu, duv, dvv;
};

// Where OpenSubdiv 3.5's own second derivatives are not the patch's, the jet evaluators take
// them from its exact first derivatives instead: the Gregory end caps' (their rational
// blending is left out of the second derivatives: normals 1% off at isolation 6), and on Loop
// sub-triangles rotated by a half turn (the middle child of each split) Far and Bfr negate the
// second derivatives as they must the first, though a half turn leaves them unchanged. Far says
// which patch is which (the rotation is undone exactly); Bfr does not, so on irregular faces,
// whose patch trees hold both, they are central differences of the first derivatives.
inline constexpr double kSecondDerivativeStep = 1e-6;  // in the evaluator's parameters

// jet.duu, duv and dvv as central differences, over kSecondDerivativeStep, of
// `firstDerivatives(u, v, du, dv)`, the exact first derivatives at (u, v).
template <class FirstDerivatives>
void differenceSecondDerivatives(SurfaceJet& jet, double u, double v,
                                 const FirstDerivatives& firstDerivatives) {
  const double h = kSecondDerivativeStep;
  Vec3 du0, dv0, du1, dv1;
  firstDerivatives(u - h, v, du0, dv0);
  firstDerivatives(u + h, v, du1, dv1);
  jet.duu = (du1 - du0) / (2 * h);
  const Vec3 duvAlongU = (dv1 - dv0) / (2 * h);
  firstDerivatives(u, v - h, du0, dv0);
  firstDerivatives(u, v + h, du1, dv1);
  jet.dvv = (dv1 - dv0) / (2 * h);
  jet.duv = (duvAlongU + (du1 - du0) / (2 * h)) * 0.5;
}

// The displaced point and its first derivatives. False (outputs untouched) where s's normal is
// undefined (du x dv vanishes), for the caller to evaluate nearby.
bool displace(const Displacement& displacement, const SurfaceJet& s, Vec3& position, Vec3& du,
              Vec3& dv);

}  // namespace limn::render::subdiv
