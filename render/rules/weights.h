// The scalar weights of the rules that tests and the limit masks share, as functions of the
// valence n.
#pragma once

#include <cmath>
#include <numbers>

namespace limn::render::rules {

// Loop's vertex weight per neighbour: beta(n) = (5/8 - (3/8 + 1/4 cos(2 pi / n))^2) / n
// (Loop 1987), the vertex keeping 1 - n beta. beta(3) = 3/16, beta(6) = 1/16.
inline double loopBeta(int n) {
  if (n == 6) return 1.0 / 16.0;
  const double c = 0.375 + 0.25 * std::cos(2.0 * std::numbers::pi / n);
  return (0.625 - c * c) / n;
}

// Loop's limit weight per neighbour of an interior vertex: 1 / (n + 3 / (8 beta(n)))
// (the dominant left eigenvector of the subdivision matrix; 1/12 at n = 6).
inline double loopLimitWeight(int n) { return 1.0 / (n + 3.0 / (8.0 * loopBeta(n))); }

// Catmull-Clark's limit weights of an interior vertex of valence n on a quad mesh:
// the vertex n/(n+5), each edge neighbour 4/(n(n+5)), each diagonal neighbour 1/(n(n+5))
// (at n = 4 the bicubic B-spline's 16/36, 4/36, 1/36).
inline double catmullClarkLimitVertexWeight(int n) { return n / (n + 5.0); }
inline double catmullClarkLimitEdgeWeight(int n) { return 4.0 / (n * (n + 5.0)); }
inline double catmullClarkLimitFaceWeight(int n) { return 1.0 / (n * (n + 5.0)); }

}  // namespace limn::render::rules
