#include "render/implicit/field.h"

#include <algorithm>
#include <cmath>

#include "render/core/error.h"
#include "render/implicit/expression.h"

namespace limn::render::implicit {

namespace {

constexpr double kPi = 3.14159265358979323846;
// max |d/dx (1 - 4x^6/9 + 17x^4/9 - 22x^2/9)| on [0, 1] is 1.5836 (at x = 0.5035), rounded up.
constexpr double kSoftSlope = 1.59;

[[noreturn]] void bad(size_t index, const std::string& key, const std::string& message) {
  throw InputError(
      InputError::Kind::InvalidParameter,
      "field.primitives[" + std::to_string(index) + "]" + (key.empty() ? "" : ".") + key, message);
}

void requireFinite(size_t index, const char* key, double value) {
  if (!std::isfinite(value)) bad(index, key, "must be a finite number");
}

void requireFinite(size_t index, const char* key, const Vec3& v) {
  if (!isFinite(v)) bad(index, key, "must be three finite numbers");
}

// R = Rz Ry Rx, angles in degrees.
std::array<double, 9> rotation(const Vec3& deg) {
  const double a = deg.x * kPi / 180, b = deg.y * kPi / 180, c = deg.z * kPi / 180;
  const double ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b),
               cc = std::cos(c), sc = std::sin(c);
  return {cc * cb,
          cc * sb * sa - sc * ca,
          cc * sb * ca + sc * sa,
          sc * cb,
          sc * sb * sa + cc * ca,
          sc * sb * ca - cc * sa,
          -sb,
          cb * sa,
          cb * ca};
}

Vec3 multiply(const std::array<double, 9>& m, const Vec3& v) {
  return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
          m[6] * v.x + m[7] * v.y + m[8] * v.z};
}

Vec3 multiplyTransposed(const std::array<double, 9>& m, const Vec3& v) {
  return {m[0] * v.x + m[3] * v.y + m[6] * v.z, m[1] * v.x + m[4] * v.y + m[7] * v.z,
          m[2] * v.x + m[5] * v.y + m[8] * v.z};
}

// Wyvill's soft-object polynomial of x2 = r^2 / b^2 (0 beyond b), and d/d(r^2).
double softFalloff(double r2, double b, double weight, double* dfdr2) {
  const double b2 = b * b;
  if (r2 >= b2) {
    *dfdr2 = 0;
    return 0;
  }
  const double x2 = r2 / b2;
  *dfdr2 = weight / b2 * ((-12.0 * x2 + 34.0) * x2 - 22.0) / 9.0;
  return weight * (1.0 + x2 * ((-4.0 * x2 + 17.0) * x2 - 22.0) / 9.0);
}

void validate(const Primitive& p, size_t i) {
  requireFinite(i, "center", p.center);
  requireFinite(i, "radius", p.radius);
  requireFinite(i, "weight", p.weight);
  requireFinite(i, "transform.scale", p.transform.scale);
  requireFinite(i, "transform.rotateDeg", p.transform.rotateDeg);
  requireFinite(i, "transform.translate", p.transform.translate);
  if (!(p.weight > 0)) bad(i, "weight", "must be > 0 (use \"negative\": true to subtract)");
  if (p.type != PrimitiveType::Expression && !(p.radius > 0)) bad(i, "radius", "must be > 0");
  const Vec3& s = p.transform.scale;
  const double largest = std::max({std::fabs(s.x), std::fabs(s.y), std::fabs(s.z)});
  if (std::min({std::fabs(s.x), std::fabs(s.y), std::fabs(s.z)}) < 1e-6 * largest || largest == 0) {
    bad(i, "transform.scale",
        "must not be zero along any axis (nor 1e6 times smaller than along "
        "another)");
  }
  switch (p.type) {
    case PrimitiveType::Blobby:
      if (!(p.blobbiness > 0 && p.blobbiness <= 1e6)) {
        bad(i, "blobbiness", "must be in (0, 1e6]");
      }
      break;
    case PrimitiveType::Torus:
      if (!(p.majorRadius >= 0 && std::isfinite(p.majorRadius))) {
        bad(i, "majorRadius", "must be a finite number >= 0");
      }
      break;
    case PrimitiveType::Cube:
      if (!(p.exponent >= 2 && p.exponent <= 64)) bad(i, "exponent", "must be in [2, 64]");
      break;
    case PrimitiveType::Expression:
      if (p.expression.empty()) bad(i, "expression", "is required for type \"expression\"");
      if (!p.bounds.empty() && (!isFinite(p.bounds.lo) || !isFinite(p.bounds.hi))) {
        bad(i, "bounds", "must be finite");
      }
      break;
    default:
      break;
  }
}

// Half extents, in local coordinates, of the box outside which a primitive contributes less than
// `threshold` (blobby atoms never reach 0: their support is where they can still matter).
Vec3 localHalfExtents(const Primitive& p, double threshold) {
  const double b = p.radius;
  switch (p.type) {
    case PrimitiveType::Blobby: {
      const double a = p.blobbiness / (b * b);
      const double r = p.weight > threshold ? std::sqrt(std::log(p.weight / threshold) / a) : 0;
      return {r, r, r};
    }
    case PrimitiveType::Metaball:
    case PrimitiveType::Soft:
    case PrimitiveType::Cube:
      return {b, b, b};
    case PrimitiveType::Torus:
      return {p.majorRadius + b, p.majorRadius + b, b};
    case PrimitiveType::Expression:
      break;
  }
  return {0, 0, 0};
}

// The world box of a local box centred on the primitive's origin.
Bounds worldBox(const PreparedPrimitive& prim, const std::array<double, 9>& toWorld,
                const Vec3& half) {
  Vec3 extent{0, 0, 0};
  for (int r = 0; r < 3; ++r) {
    double e = 0;
    for (int c = 0; c < 3; ++c) e += std::fabs(toWorld[3 * r + c]) * half[c];
    (r == 0 ? extent.x : r == 1 ? extent.y : extent.z) = e;
  }
  Bounds box;
  box.extend(prim.origin - extent);
  box.extend(prim.origin + extent);
  return box;
}

double localLipschitz(const Primitive& p) {
  const double w = p.weight, b = p.radius;
  switch (p.type) {
    case PrimitiveType::Blobby:
      return w * std::sqrt(2.0 * p.blobbiness / (b * b)) * std::exp(-0.5);
    case PrimitiveType::Metaball:
      return 2.0 * w / b;
    case PrimitiveType::Soft:
    case PrimitiveType::Torus:  // distance to the core circle has slope 1
    case PrimitiveType::Cube:   // the n-norm (n >= 2) has slope at most 1
      return kSoftSlope * w / b;
    case PrimitiveType::Expression:
      break;
  }
  return 0;
}

bool inside(const Bounds& box, const Vec3& p) {
  return p.x >= box.lo.x && p.x <= box.hi.x && p.y >= box.lo.y && p.y <= box.hi.y &&
         p.z >= box.lo.z && p.z <= box.hi.z;
}

double boxDistance(const Bounds& box, const Vec3& p) {
  const double dx = std::max({box.lo.x - p.x, 0.0, p.x - box.hi.x});
  const double dy = std::max({box.lo.y - p.y, 0.0, p.y - box.hi.y});
  const double dz = std::max({box.lo.z - p.z, 0.0, p.z - box.hi.z});
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

double minScale(const Transform& t) {
  return std::min({std::fabs(t.scale.x), std::fabs(t.scale.y), std::fabs(t.scale.z)});
}

Bounds infiniteBox() {
  Bounds box;
  box.lo = {-1e300, -1e300, -1e300};
  box.hi = {1e300, 1e300, 1e300};
  return box;
}

}  // namespace

const char* primitiveTypeName(PrimitiveType type) {
  switch (type) {
    case PrimitiveType::Blobby:
      return "blobby";
    case PrimitiveType::Metaball:
      return "metaball";
    case PrimitiveType::Soft:
      return "soft";
    case PrimitiveType::Torus:
      return "torus";
    case PrimitiveType::Cube:
      return "cube";
    case PrimitiveType::Expression:
      return "expression";
  }
  return "?";
}

Field::Field(FieldSpec spec) : iso_(spec.iso) {
  if (!(std::isfinite(iso_) && iso_ > 0)) {
    throw InputError(InputError::Kind::InvalidParameter, "field.iso",
                     "must be a finite number > 0 (the field is 0 far from every primitive, "
                     "which must be outside)");
  }
  if (spec.primitives.empty()) {
    throw InputError(InputError::Kind::InvalidParameter, "field.primitives",
                     "needs at least one primitive");
  }
  size_t positives = 0;
  for (size_t i = 0; i < spec.primitives.size(); ++i) {
    validate(spec.primitives[i], i);
    positives += !spec.primitives[i].negative;
  }
  if (positives == 0) {
    throw InputError(InputError::Kind::InvalidParameter, "field.primitives",
                     "has only negative primitives: the field never reaches iso");
  }
  // A point with F >= iso has a positive primitive contributing at least iso / positives there,
  // so those supports hold the whole surface. Influence (for Lipschitz bounds) reaches further.
  const double supportThreshold = iso_ / static_cast<double>(positives);
  const double influenceThreshold = 1e-9 * iso_;
  std::vector<std::string> sources, subjects;
  for (size_t i = 0; i < spec.primitives.size(); ++i) {
    const Primitive& p = spec.primitives[i];
    PreparedPrimitive prim;
    prim.spec = p;
    prim.sign = p.negative ? -1.0 : 1.0;
    const std::array<double, 9> r = rotation(p.transform.rotateDeg);
    const Vec3& s = p.transform.scale;
    std::array<double, 9> toWorld{}, toLocal{};
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) {
        toWorld[3 * row + col] = r[3 * row + col] * s[col];  // R S
        toLocal[3 * row + col] = r[3 * col + row] / s[row];  // S^-1 R^T
      }
    }
    prim.toLocal = toLocal;
    prim.origin = p.center + p.transform.translate;
    if (p.type == PrimitiveType::Expression) {
      prim.expressionIndex = static_cast<int>(sources.size());
      sources.push_back(p.expression);
      subjects.push_back("field.primitives[" + std::to_string(i) + "].expression");
      prim.support = p.bounds.empty() ? infiniteBox() : p.bounds;
    } else {
      prim.support = worldBox(prim, toWorld, localHalfExtents(p, supportThreshold));
      prim.lipschitz = localLipschitz(p) / minScale(p.transform);
      // Blobby atoms influence beyond their support; the others stop at it.
      if (p.type == PrimitiveType::Blobby) {
        prim.support = worldBox(prim, toWorld, localHalfExtents(p, influenceThreshold));
        Bounds domain = worldBox(prim, toWorld, localHalfExtents(p, supportThreshold));
        if (!p.negative && !domain.empty()) bounds_.extend(domain.lo), bounds_.extend(domain.hi);
      } else if (!p.negative) {
        bounds_.extend(prim.support.lo);
        bounds_.extend(prim.support.hi);
      }
    }
    primitives_.push_back(std::move(prim));
  }
  for (const PreparedPrimitive& prim : primitives_) {
    if (prim.spec.type == PrimitiveType::Expression && !prim.spec.negative &&
        !prim.spec.bounds.empty()) {
      bounds_.extend(prim.spec.bounds.lo);
      bounds_.extend(prim.spec.bounds.hi);
    }
  }
  for (size_t i = 0; i < primitives_.size(); ++i) {
    const PreparedPrimitive& prim = primitives_[i];
    if (prim.spec.type == PrimitiveType::Expression && !prim.spec.negative &&
        prim.spec.bounds.empty() && bounds_.empty()) {
      bad(i, "bounds",
          "a positive expression needs \"bounds\" ({\"min\": [x, y, z], \"max\": [x, y, z]}) "
          "when no other primitive bounds the surface");
    }
  }
  if (bounds_.empty()) {
    throw InputError(InputError::Kind::InvalidParameter, "field.iso",
                     "no primitive's field reaches iso: the surface is empty");
  }
  if (!sources.empty()) {
    expressions_ = std::make_unique<ExpressionSet>(std::move(sources), std::move(subjects));
  }
  for (PreparedPrimitive& prim : primitives_) {
    if (prim.spec.type == PrimitiveType::Expression) estimateSlopes(prim);
  }
  for (const PreparedPrimitive& prim : primitives_) lipschitz_ += prim.lipschitz;
}

// Expressions have no analytic bound: the slope of weight * e^2 is estimated on a lattice of
// kSlopeCells^3 cells over the domain, from central differences of e at the lattice points,
// spread to each cell's neighbours and doubled for safety (docs/implicit.md). Rays far from the
// expression's shape then step at the pace of the other primitives.
void Field::estimateSlopes(PreparedPrimitive& prim) const {
  constexpr int n = PreparedPrimitive::kSlopeCells;
  const Vec3 size = bounds_.hi - bounds_.lo;
  const Vec3 cell = size / n;
  const double h = 1e-4 * std::max(length(size), 1e-300);
  auto e = [&](const Vec3& p) {
    const Vec3 q = multiply(prim.toLocal, p - prim.origin);
    return expressions_->evaluate(prim.expressionIndex, q.x, q.y, q.z);
  };
  std::vector<double> atPoint((n + 1) * (n + 1) * (n + 1), 0.0);
  for (int k = 0; k <= n; ++k) {
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) {
        const Vec3 p = bounds_.lo + Vec3{cell.x * i, cell.y * j, cell.z * k};
        const Vec3 g{(e(p + Vec3{h, 0, 0}) - e(p - Vec3{h, 0, 0})) / (2 * h),
                     (e(p + Vec3{0, h, 0}) - e(p - Vec3{0, h, 0})) / (2 * h),
                     (e(p + Vec3{0, 0, h}) - e(p - Vec3{0, 0, h})) / (2 * h)};
        // d(w e^2)/dp = 2 w e grad e where e < 0; between the lattice points the spreading to
        // neighbouring cells and the factor of 2 stand in for a bound.
        const double value = e(p);
        if (value < 0) {
          atPoint[(k * (n + 1) + j) * (n + 1) + i] =
              2.0 * prim.spec.weight * std::fabs(value) * length(g);
        }
      }
    }
  }
  auto point = [&](int i, int j, int k) { return atPoint[(k * (n + 1) + j) * (n + 1) + i]; };
  std::vector<float> cells(n * n * n, 0.0f);
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        double largest = 0;
        for (int c = 0; c < 8; ++c) {
          largest = std::max(largest, point(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)));
        }
        cells[(k * n + j) * n + i] = static_cast<float>(largest);
      }
    }
  }
  // Spread each cell's slope to the cells within kSlopeReach + 1 (one for what lies between
  // lattice points, kSlopeReach so that one lookup bounds a ball of that many cells' radius),
  // axis by axis.
  constexpr int spread = PreparedPrimitive::kSlopeReach + 1;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<float> out(cells.size(), 0.0f);
    const int stride = axis == 0 ? 1 : axis == 1 ? n : n * n;
    for (int c = 0; c < n * n * n; ++c) {
      const int at = (c / stride) % n;
      float largest = 0;
      for (int d = -spread; d <= spread; ++d) {
        if (at + d >= 0 && at + d < n) largest = std::max(largest, cells[c + d * stride]);
      }
      out[c] = largest;
    }
    cells = std::move(out);
  }
  prim.slopes.resize(cells.size());
  prim.lipschitz = 0;
  for (size_t c = 0; c < cells.size(); ++c) {
    prim.slopes[c] = 2.0f * cells[c];  // the safety factor
    prim.lipschitz = std::max(prim.lipschitz, static_cast<double>(prim.slopes[c]));
  }
  const Vec3 cellSize = size / n;
  prim.slopeReach = PreparedPrimitive::kSlopeReach * std::min({cellSize.x, cellSize.y, cellSize.z});
  prim.slopeBox = bounds_;
}

Field::~Field() = default;
Field::Field(Field&&) noexcept = default;

bool Field::hasExpressions() const { return expressions_ != nullptr; }

FieldEvaluator::FieldEvaluator(const Field& field)
    : field_(field), expressions_(field.expressions() ? field.expressions()->clone() : nullptr) {}

FieldEvaluator::~FieldEvaluator() = default;
FieldEvaluator::FieldEvaluator(FieldEvaluator&&) noexcept = default;

double FieldEvaluator::contribution(const PreparedPrimitive& prim, const Vec3& p, Vec3* gradient) {
  const Primitive& s = prim.spec;
  const Vec3 q = multiply(prim.toLocal, p - prim.origin);
  const double w = s.weight, b = s.radius;
  double f = 0;
  Vec3 gq{0, 0, 0};  // gradient in local coordinates
  switch (s.type) {
    case PrimitiveType::Blobby: {
      const double a = s.blobbiness / (b * b);
      f = w * std::exp(-a * dot(q, q));
      gq = q * (-2.0 * a * f);
      break;
    }
    case PrimitiveType::Metaball: {
      const double r = length(q);
      if (r >= b) break;
      if (r <= b / 3) {
        f = w * (1.0 - 3.0 * r * r / (b * b));
        gq = q * (-6.0 * w / (b * b));
      } else {
        const double t = 1.0 - r / b;
        f = 1.5 * w * t * t;
        gq = q * (-3.0 * w * t / (b * r));
      }
      break;
    }
    case PrimitiveType::Soft: {
      double d;
      f = softFalloff(dot(q, q), b, w, &d);
      gq = q * (2.0 * d);
      break;
    }
    case PrimitiveType::Torus: {
      const double rho = std::hypot(q.x, q.y);
      const double dr = rho - s.majorRadius;
      double d;
      f = softFalloff(dr * dr + q.z * q.z, b, w, &d);
      const double radial = rho > 0 ? 2.0 * d * dr / rho : 0.0;
      gq = {radial * q.x, radial * q.y, 2.0 * d * q.z};
      break;
    }
    case PrimitiveType::Cube: {
      const double n = s.exponent;
      const double ax = std::fabs(q.x), ay = std::fabs(q.y), az = std::fabs(q.z);
      const double sum = std::pow(ax, n) + std::pow(ay, n) + std::pow(az, n);
      const double r = std::pow(sum, 1.0 / n);
      double d;
      f = softFalloff(r * r, b, w, &d);
      if (r > 0 && d != 0) {
        // d(r^2)/dq_i = 2 r sign(q_i) |q_i|^(n-1) / r^(n-1)
        const double k = 2.0 * d * std::pow(r, 2.0 - n);
        gq = {k * std::copysign(std::pow(ax, n - 1), q.x),
              k * std::copysign(std::pow(ay, n - 1), q.y),
              k * std::copysign(std::pow(az, n - 1), q.z)};
      }
      break;
    }
    case PrimitiveType::Expression: {
      // weight * e^2 inside (e < 0): zero with zero slope on the expression's own surface, as
      // every falloff here ends, so cuts and blends have no crease for the polygonisers to miss.
      const double e = expressions_->evaluate(prim.expressionIndex, q.x, q.y, q.z);
      if (e >= 0) break;
      f = w * e * e;
      if (gradient) {
        const double h = 1e-6 * std::max(1.0, length(q));
        auto at = [&](double x, double y, double z) {
          return expressions_->evaluate(prim.expressionIndex, x, y, z);
        };
        gq = Vec3{at(q.x + h, q.y, q.z) - at(q.x - h, q.y, q.z),
                  at(q.x, q.y + h, q.z) - at(q.x, q.y - h, q.z),
                  at(q.x, q.y, q.z + h) - at(q.x, q.y, q.z - h)} *
             (2.0 * w * e / (2 * h));
      }
      break;
    }
  }
  if (gradient) *gradient = multiplyTransposed(prim.toLocal, gq) * prim.sign;
  return prim.sign * f;
}

double FieldEvaluator::value(const Vec3& p) {
  double sum = 0;
  for (const PreparedPrimitive& prim : field_.primitives()) {
    if (inside(prim.support, p)) sum += contribution(prim, p, nullptr);
  }
  return sum - field_.iso();
}

double FieldEvaluator::valueAndGradient(const Vec3& p, Vec3& gradient) {
  double sum = 0;
  gradient = {0, 0, 0};
  for (const PreparedPrimitive& prim : field_.primitives()) {
    if (!inside(prim.support, p)) continue;
    Vec3 g;
    sum += contribution(prim, p, &g);
    gradient += g;
  }
  return sum - field_.iso();
}

double FieldEvaluator::lipschitzNear(const Vec3& p, double reach) const {
  double bound = 0;
  for (const PreparedPrimitive& prim : field_.primitives()) {
    if (boxDistance(prim.support, p) > reach) continue;
    bound += prim.slopes.empty() ? prim.lipschitz : slopeNear(prim, p, reach);
  }
  return bound;
}

// The slope bound of an expression's lattice cell holding p, which covers the ball (p, reach)
// when reach is within slopeReach; the global bound otherwise, and outside the lattice.
double FieldEvaluator::slopeNear(const PreparedPrimitive& prim, const Vec3& p, double reach) {
  constexpr int n = PreparedPrimitive::kSlopeCells;
  if (reach > prim.slopeReach) return prim.lipschitz;
  const Bounds& box = prim.slopeBox;
  int index[3];
  for (int a = 0; a < 3; ++a) {
    const double at = (p[a] - box.lo[a]) / (box.hi[a] - box.lo[a]) * n;
    if (!(at >= 0 && at < n)) return prim.lipschitz;
    index[a] = static_cast<int>(at);
  }
  return prim.slopes[(index[2] * n + index[1]) * n + index[0]];
}

double Field::localReach() const {
  double reach = 1e300;
  for (const PreparedPrimitive& prim : primitives_) {
    if (!prim.slopes.empty()) reach = std::min(reach, prim.slopeReach);
  }
  return reach;
}

Vec3 FieldEvaluator::normal(const Vec3& p) {
  Vec3 g;
  valueAndGradient(p, g);
  const double n = length(g);
  return n > 0 ? g * (-1.0 / n) : Vec3{0, 0, 0};
}

double rootOnSegment(FieldEvaluator& field, const Vec3& origin, const Vec3& direction, double t0,
                     double f0, double t1, double f1, double tolerance) {
  if (f0 == 0) return t0;
  if (f1 == 0) return t1;
  int side = 0;
  double t = t0;
  for (int i = 0; i < 60 && (t1 - t0) > tolerance; ++i) {
    t = (t0 * f1 - t1 * f0) / (f1 - f0);
    if (!(t > t0 && t < t1)) t = 0.5 * (t0 + t1);
    const double ft = field.value(origin + direction * t);
    if (ft == 0) return t;
    // Illinois: halve the value of the end that stays, so that it does not stay forever.
    if ((ft > 0) == (f0 > 0)) {
      t0 = t;
      f0 = ft;
      if (side == -1) f1 *= 0.5;
      side = -1;
    } else {
      t1 = t;
      f1 = ft;
      if (side == 1) f0 *= 0.5;
      side = 1;
    }
  }
  return t;
}

bool projectToSurface(FieldEvaluator& field, Vec3& p, double tolerance, double maxStep,
                      int maxSteps) {
  for (int i = 0; i < maxSteps; ++i) {
    Vec3 g;
    const double f = field.valueAndGradient(p, g);
    const double g2 = dot(g, g);
    if (g2 == 0) return false;
    const double distance = std::fabs(f) / std::sqrt(g2);
    if (distance < tolerance) return true;
    Vec3 step = g * (-f / g2);
    const double len = std::sqrt(dot(step, step));
    if (len > maxStep) step *= maxStep / len;
    p += step;
  }
  Vec3 g;
  const double f = field.valueAndGradient(p, g);
  return dot(g, g) > 0 && std::fabs(f) / length(g) < tolerance;
}

}  // namespace limn::render::implicit
