#include "render/oracle/reference_tessellation.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include <opensubdiv/bfr/tessellation.h>

#include "render/tessellate/tessellate.h"

namespace limn::render::oracle {

namespace Bfr = OpenSubdiv::Bfr;
namespace Far = OpenSubdiv::Far;

namespace {

// Samples per face edge when probing a face (a uniform Bfr tessellation at this rate).
constexpr int kProbeRate = 4;
// Sampled curvature underestimates peaks between samples: required segments use this multiple.
constexpr double kCurvatureSafety = 2.0;
// Density at most (the edge rate is capped by kReferenceMaxEdgeRate anyway).
constexpr double kMaxDensity = 1e4;

// What probing one face found.
struct FaceProbe {
  double gMin = 1, gMax = -1;  // range of cos(normal, view direction) over the samples
  double normalSpread = 0;     // largest |n_i - n_j| between neighbouring samples
  bool silhouette = false;
  // Per face edge: segments that keep the chord error below target, and the projected length
  // (corner - midpoint - corner polyline) the adaptive tessellator measures.
  std::vector<double> segmentsNeeded, projectedPx;
};

FaceProbe probeFace(const subdiv::LimitSurface& surface, int face, const Camera& camera) {
  FaceProbe probe;
  Bfr::Parameterization param = surface.parameterization(face);
  const int n = param.GetFaceSize();
  Bfr::Tessellation tess(param, kProbeRate);
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
  // Facing changes sign, or comes closer to zero than the normal varies between samples (the
  // contour may then pass between them).
  double tau = 0.05 + probe.normalSpread;
  probe.silhouette = probe.gMin < tau && probe.gMax > -tau;

  // Boundary coords run corner 0, the kProbeRate - 1 points of edge 0, corner 1, ...
  probe.segmentsNeeded.resize(n);
  probe.projectedPx.resize(n);
  const int boundary = n * kProbeRate;
  for (int k = 0; k < n; ++k) {
    Vec3 p[kProbeRate + 1], pixel[kProbeRate + 1];
    double minDepth = 1e300;
    for (int i = 0; i <= kProbeRate; ++i) {
      p[i] = samples[(k * kProbeRate + i) % boundary].position;
      pixel[i] = camera.project(p[i]);
      minDepth = std::min(minDepth, camera.depthOf(p[i]));
    }
    double length3 = 0, edgeKappa = 0;
    for (int i = 0; i < kProbeRate; ++i) length3 += length(p[i + 1] - p[i]);
    for (int i = 1; i < kProbeRate; ++i) {
      double h = 0.5 * (length(p[i] - p[i - 1]) + length(p[i + 1] - p[i]));
      if (h > 0) edgeKappa = std::max(edgeKappa, length(p[i - 1] - p[i] * 2.0 + p[i + 1]) / (h * h));
    }
    double ppu = camera.pixelsPerUnit(std::max(minDepth, camera.nearPlane()));
    double curvature = kCurvatureSafety * std::max(kappa, edgeKappa);
    probe.segmentsNeeded[k] = length3 * std::sqrt(ppu * curvature / (8.0 * kOutlineChordErrorPx));
    const Vec3& a = pixel[0];
    const Vec3& m = pixel[kProbeRate / 2];
    const Vec3& b = pixel[kProbeRate];
    probe.projectedPx[k] = std::hypot(m.x - a.x, m.y - a.y) + std::hypot(b.x - m.x, b.y - m.y);
  }
  return probe;
}

}  // namespace

std::vector<double> outlineDensities(const subdiv::LimitSurface& surface, const Camera& camera) {
  const int faceCount = surface.faceCount();
  std::vector<FaceProbe> probes(faceCount);
  tbb::parallel_for(tbb::blocked_range<int>(0, faceCount, 16),
                    [&](const tbb::blocked_range<int>& r) {
                      for (int f = r.begin(); f < r.end(); ++f) {
                        if (surface.hasLimit(f)) probes[f] = probeFace(surface, f, camera);
                      }
                    });

  const Far::TopologyLevel& base = surface.baseLevel();
  std::vector<char> outline(faceCount, 0);
  for (int f = 0; f < faceCount; ++f) outline[f] = surface.hasLimit(f) && probes[f].silhouette;
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    Far::ConstIndexArray faces = base.GetEdgeFaces(e);
    int withLimit = 0;
    double gMin = 1, gMax = -1, tau = 0.05;
    for (int f : faces) {
      if (!surface.hasLimit(f)) continue;
      ++withLimit;
      gMin = std::min(gMin, probes[f].gMin);
      gMax = std::max(gMax, probes[f].gMax);
      tau = std::max(tau, 0.05 + probes[f].normalSpread);
    }
    // A boundary of the limit surface (mesh boundary, hole, faces without limit) is an outline
    // wherever it is seen; a crease is one where facing changes across it.
    bool border = withLimit < static_cast<int>(faces.size()) || faces.size() < 2;
    bool crease = base.GetEdgeSharpness(e) > 0 && gMin < tau && gMax > -tau;
    if (border || crease) {
      for (int f : faces) {
        if (surface.hasLimit(f)) outline[f] = 1;
      }
    }
  }

  std::vector<double> density(faceCount, 1.0);
  for (int f = 0; f < faceCount; ++f) {
    if (!outline[f]) continue;
    const FaceProbe& probe = probes[f];
    double d = 1.0;
    for (size_t k = 0; k < probe.segmentsNeeded.size(); ++k) {
      double wanted = probe.segmentsNeeded[k] * kReferenceDicingRate;
      d = std::max(d, probe.projectedPx[k] > 0 ? wanted / probe.projectedPx[k] : kMaxDensity);
    }
    // Outline faces are at least 4 times finer than the rest even where they are flat.
    density[f] = std::clamp(d, 4.0, kMaxDensity);
  }
  return density;
}

ReferenceTessellation tessellateForReference(const subdiv::LimitSurface& surface,
                                             const Camera& camera, const CancelToken& cancel) {
  std::vector<double> density = outlineDensities(surface, camera);
  cancel.check();
  tessellate::AdaptiveOptions options;
  options.dicingRate = kReferenceDicingRate;
  options.maxEdgeRate = kReferenceMaxEdgeRate;
  options.minEdgeRate = 1;
  options.density = [&density](int face) { return density[face]; };
  ReferenceTessellation result;
  result.mesh = tessellate::tessellateAdaptive(surface, camera, options, cancel);
  for (double d : density) result.outlineFaces += d > 1.0;
  return result;
}

}  // namespace limn::render::oracle
