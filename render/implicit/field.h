// Scalar fields of implicit surfaces: primitives (Blinn's blobby atoms, Nishimura's metaballs,
// Wyvill's soft objects, a torus, a rounded cube, a custom expression) summed into one field
// F(p) = sum of +-w_i f_i(p); the surface is F = iso, inside where F > iso. Every primitive has
// bounded support (expressions are bounded by the caller's box), analytic gradients (central
// differences for expressions) and a Lipschitz bound, which the polygonisers use to find every
// component and the reference uses to step along rays without missing a root.
//
// Each primitive lives in its own local frame: q = S^-1 R^T (p - center - translate), with S the
// transform's scale and R its rotation (rotateDeg about x, then y, then z). Its falloff is a
// function of a "radius" r(q): |q| for the three blob kinds, the distance to the core circle for
// the torus, the superellipsoid norm (|x|^n + |y|^n + |z|^n)^(1/n) for the rounded cube. See
// docs/implicit.md for the formulas and defaults.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "render/core/vec.h"

namespace limn::render::implicit {

enum class PrimitiveType { Blobby, Metaball, Soft, Torus, Cube, Expression };

const char* primitiveTypeName(PrimitiveType type);

struct Transform {
  Vec3 scale{1, 1, 1};
  Vec3 rotateDeg{0, 0, 0};
  Vec3 translate{0, 0, 0};
};

struct Primitive {
  PrimitiveType type = PrimitiveType::Metaball;
  Vec3 center{0, 0, 0};
  // The falloff radius b: the support of metaballs, soft objects and the shaped primitives'
  // soft falloff; for blobby atoms the exponent is a = blobbiness / b^2.
  double radius = 1;
  double weight = 1;  // Blinn's b, Nishimura's d, Wyvill's a; the expression's factor
  bool negative = false;
  Transform transform;
  double blobbiness = 2;   // blobby: a = blobbiness / radius^2
  double majorRadius = 1;  // torus: radius of the core circle (about the local z axis)
  double exponent = 8;     // cube: n of |x|^n + |y|^n + |z|^n
  // expression: e(x, y, z) in local coordinates, negative inside; contributes weight * e^2
  // where e < 0 (0 elsewhere). A positive expression needs `bounds` (world box) when no other
  // primitive bounds the surface, since {e < 0} may be unbounded.
  std::string expression;
  Bounds bounds;
};

struct FieldSpec {
  std::vector<Primitive> primitives;
  double iso = 0.5;
};

class ExpressionSet;  // compiled expressions, one copy per evaluating thread (expression.h)

// A primitive made ready to evaluate: its frame, its support box and its Lipschitz bound.
struct PreparedPrimitive {
  Primitive spec;
  double sign = 1;                // -1 for negative primitives
  std::array<double, 9> toLocal;  // row-major S^-1 R^T
  Vec3 origin;                    // center + translate
  Bounds support;                 // world box outside which the contribution is below threshold
  double lipschitz = 0;           // of the signed contribution, world units
  int expressionIndex = -1;
  // Expressions: estimated slopes on a lattice of kSlopeCells^3 cells over slopeBox (field.cpp).
  // Each cell's value bounds the slope over every ball of radius slopeReach around its points.
  static constexpr int kSlopeCells = 32, kSlopeReach = 3;
  std::vector<float> slopes;
  Bounds slopeBox;
  double slopeReach = 0;
};

// The field, checked and prepared. Evaluation needs a FieldEvaluator (one per thread): custom
// expressions keep per-thread parser state.
class Field {
 public:
  // Throws InputError (invalid parameter, naming "field.primitives[i].<key>") for non-finite or
  // out-of-range values and expressions that do not compile.
  explicit Field(FieldSpec spec);
  ~Field();
  Field(Field&&) noexcept;

  double iso() const { return iso_; }
  const std::vector<PreparedPrimitive>& primitives() const { return primitives_; }
  // The union of the positive primitives' supports (where F can reach iso), or the expression
  // bounds; the polygonisers' domain and the reference's scene.
  const Bounds& bounds() const { return bounds_; }
  double lipschitz() const { return lipschitz_; }
  const ExpressionSet* expressions() const { return expressions_.get(); }
  // The largest reach for which FieldEvaluator::lipschitzNear stays local (expressions' slope
  // lattices); unbounded without expressions.
  double localReach() const;
  bool hasExpressions() const;

 private:
  void estimateSlopes(PreparedPrimitive& prim) const;

  std::vector<PreparedPrimitive> primitives_;
  double iso_;
  Bounds bounds_;
  double lipschitz_ = 0;
  std::unique_ptr<ExpressionSet> expressions_;
};

// Evaluates a Field on one thread.
class FieldEvaluator {
 public:
  explicit FieldEvaluator(const Field& field);
  ~FieldEvaluator();
  FieldEvaluator(FieldEvaluator&&) noexcept;

  // F(p) - iso: positive inside.
  double value(const Vec3& p);
  // F(p) - iso and its gradient.
  double valueAndGradient(const Vec3& p, Vec3& gradient);
  // A Lipschitz bound of F over the ball of radius `reach` around p (only primitives whose
  // support box comes within reach count).
  double lipschitzNear(const Vec3& p, double reach) const;
  // The surface's outward unit normal at p (-grad F normalised; zero where the gradient is).
  Vec3 normal(const Vec3& p);
  const Field& field() const { return field_; }

 private:
  double contribution(const PreparedPrimitive& prim, const Vec3& p, Vec3* gradient);
  static double slopeNear(const PreparedPrimitive& prim, const Vec3& p, double reach);
  const Field& field_;
  std::unique_ptr<ExpressionSet> expressions_;  // this thread's copy
};

// The root of F - iso on origin + t direction for t in [t0, t1], bracketed by f0 and f1 (F - iso
// at the ends, of opposite signs): Illinois regula falsi until the bracket is shorter than
// `tolerance` (in t) or 60 steps are done.
double rootOnSegment(FieldEvaluator& field, const Vec3& origin, const Vec3& direction, double t0,
                     double f0, double t1, double f1, double tolerance);

// Moves p onto the surface along the gradient (Newton steps), until |F - iso| / |grad F| is below
// `tolerance` (world units) or `maxSteps` are done; the steps are clamped to `maxStep` so a point
// never jumps to another sheet. Returns whether it converged.
bool projectToSurface(FieldEvaluator& field, Vec3& p, double tolerance, double maxStep,
                      int maxSteps = 20);

}  // namespace limn::render::implicit
