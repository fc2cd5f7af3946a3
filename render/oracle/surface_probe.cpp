#include "render/oracle/surface_probe.h"

#include <opensubdiv/bfr/tessellation.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace limn::render::oracle {

namespace Bfr = OpenSubdiv::Bfr;

namespace {

// Samples per face edge (a uniform Bfr tessellation at this rate).
constexpr int kProbeRate = 4;
// On a displaced surface: bumps of the highest frequency allowed are a few per face of a coarse
// mesh, and the facing must be sampled within each.
constexpr int kDisplacedProbeRate = 16;
// Sampled curvature underestimates peaks between samples: segments use this multiple.
constexpr double kCurvatureSafety = 2.0;

FaceProbe probeFace(const subdiv::LimitSurface& surface, int face, const Camera& camera) {
  FaceProbe probe;
  probe.probed = true;
  Bfr::Parameterization param = surface.parameterization(face);
  const int n = param.GetFaceSize();
  const int rate = surface.displaced() ? kDisplacedProbeRate : kProbeRate;
  Bfr::Tessellation tess(param, rate);
  std::vector<double> uv(2 * tess.GetNumCoords());
  tess.GetCoords(uv.data());
  std::vector<int> facets(3 * tess.GetNumFacets());
  tess.GetFacets(facets.data());

  std::vector<subdiv::LimitSample> samples(tess.GetNumCoords());
  for (size_t i = 0; i < samples.size(); ++i) {
    samples[i] = surface.evaluate(face, uv[2 * i], uv[2 * i + 1]);
    double g = dot(samples[i].normal, normalize(camera.viewVector(samples[i].position)));
    probe.gMin = std::min(probe.gMin, g);
    probe.gMax = std::max(probe.gMax, g);
  }

  // Curvature of the surface across the samples: normal turn per unit length.
  double kappa = 0;
  for (size_t f = 0; f < facets.size(); f += 3) {
    for (int k = 0; k < 3; ++k) {
      const auto& a = samples[facets[f + k]];
      const auto& b = samples[facets[f + (k + 1) % 3]];
      double turn = length(a.normal - b.normal);
      double dist = length(a.position - b.position);
      probe.normalSpread = std::max(probe.normalSpread, turn);
      if (dist > 0) kappa = std::max(kappa, turn / dist);
    }
  }
  // The contour may pass between samples when facing comes closer to zero than it varies.
  double tau = 0.05 + probe.normalSpread;
  probe.silhouette = probe.gMin < tau && probe.gMax > -tau;

  // Boundary coords run corner 0, the rate - 1 points of edge 0, corner 1, ...
  probe.segmentsAtOnePixel.resize(n);
  probe.lengthPx.resize(n);
  const int boundary = n * rate;
  for (int k = 0; k < n; ++k) {
    std::vector<Vec3> p(rate + 1);
    double minDepth = 1e300;
    for (int i = 0; i <= rate; ++i) {
      p[i] = samples[(k * rate + i) % boundary].position;
      minDepth = std::min(minDepth, camera.depthOf(p[i]));
    }
    double length3 = 0, edgeKappa = 0;
    for (int i = 0; i < rate; ++i) length3 += length(p[i + 1] - p[i]);
    for (int i = 1; i < rate; ++i) {
      double h = 0.5 * (length(p[i] - p[i - 1]) + length(p[i + 1] - p[i]));
      if (h > 0) {
        edgeKappa = std::max(edgeKappa, length(p[i - 1] - p[i] * 2.0 + p[i + 1]) / (h * h));
      }
    }
    double ppu = camera.pixelsPerUnit(std::max(minDepth, camera.nearPlane()));
    double curvature = kCurvatureSafety * std::max(kappa, edgeKappa);
    probe.lengthPx[k] = length3 * ppu;
    probe.segmentsAtOnePixel[k] = length3 * std::sqrt(ppu * curvature / 8.0);
  }
  return probe;
}

}  // namespace

std::vector<FaceProbe> probeFaces(const subdiv::LimitSurface& surface, const Camera& camera) {
  std::vector<FaceProbe> probes(surface.faceCount());
  tbb::parallel_for(tbb::blocked_range<int>(0, surface.faceCount(), 16),
                    [&](const tbb::blocked_range<int>& r) {
                      for (int f = r.begin(); f < r.end(); ++f) {
                        if (surface.hasLimit(f)) probes[f] = probeFace(surface, f, camera);
                      }
                    });
  return probes;
}

}  // namespace limn::render::oracle
