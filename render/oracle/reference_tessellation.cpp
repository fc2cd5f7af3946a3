#include "render/oracle/reference_tessellation.h"

#include <algorithm>
#include <cmath>

#include "render/oracle/surface_probe.h"
#include "render/tessellate/tessellate.h"

namespace limn::render::oracle {

namespace Far = OpenSubdiv::Far;

namespace {

// Faces whose limit surface carries an outline: a silhouette, a boundary of the surface (mesh
// boundary, hole, faces without limit), or a crease across which facing changes. `border`
// gets the faces of the second kind.
std::vector<char> outlineFaces(const subdiv::LimitSurface& surface,
                               const std::vector<FaceProbe>& probes,
                               std::vector<char>& borderFaces) {
  borderFaces.assign(surface.faceCount(), 0);
  const Far::TopologyLevel& base = surface.baseLevel();
  std::vector<char> outline(surface.faceCount(), 0);
  for (int f = 0; f < surface.faceCount(); ++f)
    outline[f] = probes[f].probed && probes[f].silhouette;
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    Far::ConstIndexArray faces = base.GetEdgeFaces(e);
    int withLimit = 0;
    double gMin = 1, gMax = -1, tau = 0.05;
    for (int f : faces) {
      if (!probes[f].probed) continue;
      ++withLimit;
      gMin = std::min(gMin, probes[f].gMin);
      gMax = std::max(gMax, probes[f].gMax);
      tau = std::max(tau, 0.05 + probes[f].normalSpread);
    }
    bool border = withLimit < static_cast<int>(faces.size()) || faces.size() < 2;
    bool crease = base.GetEdgeSharpness(e) > 0 && gMin < tau && gMax > -tau;
    if (border || crease) {
      for (int f : faces) outline[f] = outline[f] || probes[f].probed;
    }
    if (border) {
      for (int f : faces) borderFaces[f] = 1;
    }
  }
  return outline;
}

double clampRate(double segments) {
  return std::clamp(std::ceil(segments), 1.0, static_cast<double>(kReferenceMaxEdgeRate));
}

// Rough triangle count of a face tessellated with these edge rates (Bfr: a quad's inner grid
// follows its edges; other faces split into quad sub-faces at half the rate).
double faceTriangles(const std::vector<double>& rates) {
  double mean = 0;
  for (double r : rates) mean += r / rates.size();
  if (rates.size() == 3) return mean * mean;
  if (rates.size() == 4) return 2 * mean * mean;
  return rates.size() * 2 * (mean / 2) * (mean / 2);
}

// Triangles expected at outline error `errorPx` and dicing rate `dicingPx`. Faces that face away
// everywhere are culled by the tessellator unless they carry an outline.
double estimateTriangles(const std::vector<FaceProbe>& probes, const std::vector<char>& outline,
                         double errorPx, double dicingPx) {
  double total = 0;
  std::vector<double> rates;
  for (size_t f = 0; f < probes.size(); ++f) {
    const FaceProbe& p = probes[f];
    if (!p.probed) continue;
    if (!outline[f] && p.gMin > 0) {
      total += 2;
      continue;
    }
    rates.assign(p.lengthPx.size(), 1.0);
    for (size_t k = 0; k < rates.size(); ++k) {
      double r = p.lengthPx[k] / dicingPx;
      if (outline[f]) r = std::max(r, p.segmentsAtOnePixel[k] / std::sqrt(errorPx));
      rates[k] = clampRate(r);
    }
    total += faceTriangles(rates);
  }
  return total;
}

// Over the budget, the triangles away from outlines go first: they only start Newton and decide
// visibility inside the outline, so their edges may grow to kReferenceMaxDicingRate pixels.
// Only then does the outline's chord error rise (its triangles go as 1 / error), and with it
// the accuracy the answer reports.
void fitToBudget(const std::vector<FaceProbe>& probes, const std::vector<char>& outline,
                 double budget, ReferenceTessellation& result) {
  result.outlineErrorPx = kOutlineChordErrorPx;
  result.dicingRate = kReferenceDicingRate;
  auto estimate = [&] {
    return estimateTriangles(probes, outline, result.outlineErrorPx, result.dicingRate);
  };
  while (result.dicingRate < kReferenceMaxDicingRate && estimate() > budget) {
    result.dicingRate = std::min(result.dicingRate * 1.5, kReferenceMaxDicingRate);
  }
  // One step, by the whole excess: segments go as 1 / sqrt(error) until an edge reaches one
  // segment or the rate cap. Iterating to meet the budget exactly would chase the faces no error
  // can shrink (coincident vertices make a face's sampled curvature unbounded, so its edges stay
  // at the cap) and end with every other outline edge at one segment (a fern's degenerate
  // leaflet tips took its reference to 1.9 px); the tessellator's own fit (ratesScaled) keeps
  // what is left within four times the budget.
  const double over = estimate() / budget;
  if (over > 1.0) result.outlineErrorPx *= over;
}

}  // namespace

ReferenceTessellation tessellateForReference(const subdiv::LimitSurface& surface,
                                             const Camera& camera, const CancelToken& cancel,
                                             double triangleBudget) {
  std::vector<FaceProbe> probes = probeFaces(surface, camera);
  ReferenceTessellation result;
  std::vector<char> outline = outlineFaces(surface, probes, result.borderFaces);
  cancel.check();

  fitToBudget(probes, outline, triangleBudget, result);

  // Segments per edge, and the chord error they leave (where the rate cap cuts them short it
  // grows as 1 / rate^2). No segment stands further from its curve than half its own length,
  // which bounds the edges of degenerate faces, whose sampled curvature is unbounded.
  const Far::TopologyLevel& base = surface.baseLevel();
  std::vector<int> segments(base.GetNumEdges(), 0);
  double achieved = kOutlineChordErrorPx;
  for (int f = 0; f < surface.faceCount(); ++f) {
    if (!outline[f]) continue;
    ++result.outlineFaces;
    Far::ConstIndexArray edges = base.GetFaceEdges(f);
    for (int k = 0; k < edges.size(); ++k) {
      double needed = probes[f].segmentsAtOnePixel[k] / std::sqrt(result.outlineErrorPx);
      double rate = clampRate(needed);
      double perSegment = probes[f].segmentsAtOnePixel[k] / rate;
      achieved =
          std::max(achieved, std::min(perSegment * perSegment, 0.5 * probes[f].lengthPx[k] / rate));
      segments[edges[k]] = std::max(segments[edges[k]], static_cast<int>(rate));
    }
  }
  result.outlineErrorPx = achieved;

  tessellate::AdaptiveOptions options;
  options.dicingRate = result.dicingRate;
  options.maxEdgeRate = kReferenceMaxEdgeRate;
  options.minEdgeRate = 1;
  options.maxTriangles = 4 * static_cast<size_t>(triangleBudget);
  options.fitToBudget = true;
  options.stage = "reference";
  options.remedy = "";
  options.ratesScaled = &result.ratesScaled;
  options.minSegments = [&segments](int edge) { return segments[edge]; };
  result.mesh = tessellate::tessellateAdaptive(surface, camera, options, cancel);
  return result;
}

}  // namespace limn::render::oracle
