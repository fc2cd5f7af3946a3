// worstOf: the worst of several views' metrics, member by member.
#include <algorithm>

#include "render/metrics/metrics.h"

namespace limn::render::metrics {

namespace {

void worse(double& worst, double value) { worst = std::max(worst, value); }
void lower(double& worst, double value) { worst = std::min(worst, value); }
void worse(std::optional<double>& worst, const std::optional<double>& value) {
  if (value) worst = worst ? std::max(*worst, *value) : *value;
}

// The group `member` of every view that has it, folded by `fold` into the first one's copy.
template <class Group, class Fold>
std::optional<Group> worstGroup(const std::vector<Metrics>& views,
                                std::optional<Group> Metrics::*member, Fold fold) {
  std::optional<Group> worst;
  for (const Metrics& view : views) {
    const std::optional<Group>& group = view.*member;
    if (!group) continue;
    if (!worst) {
      worst = group;
    } else {
      fold(*worst, *group);
    }
  }
  return worst;
}

}  // namespace

Metrics worstOf(const std::vector<Metrics>& views) {
  Metrics out;
  out.silhouette =
      worstGroup(views, &Metrics::silhouette, [](SilhouetteMetrics& w, const SilhouetteMetrics& v) {
        worse(w.hausdorffPx, v.hausdorffPx);
        worse(w.meanPx, v.meanPx);
        lower(w.iou, v.iou);
        w.mismatchPx = std::max(w.mismatchPx, v.mismatchPx);
        worse(w.outlineHausdorffPx, v.outlineHausdorffPx);
        worse(w.outlineMeanPx, v.outlineMeanPx);
        w.outlineUnresolvedLoops = std::max(w.outlineUnresolvedLoops, v.outlineUnresolvedLoops);
      });
  out.image = worstGroup(views, &Metrics::image, [](ColorMetrics& w, const ColorMetrics& v) {
    worse(w.rmse, v.rmse);
    lower(w.psnr, v.psnr);
    worse(w.diffScale, v.diffScale);
  });
  out.depth = worstGroup(views, &Metrics::depth, [](DepthMetrics& w, const DepthMetrics& v) {
    worse(w.maxRel, v.maxRel);
    worse(w.meanRel, v.meanRel);
  });
  out.normal = worstGroup(views, &Metrics::normal, [](NormalMetrics& w, const NormalMetrics& v) {
    worse(w.meanDeg, v.meanDeg);
    worse(w.maxDeg, v.maxDeg);
  });
  out.geometry =
      worstGroup(views, &Metrics::geometry, [](GeometryMetrics& w, const GeometryMetrics& v) {
        worse(w.maxDist, v.maxDist);
        worse(w.meanDist, v.meanDist);
        worse(w.relMaxDist, v.relMaxDist);
        worse(w.relMeanDist, v.relMeanDist);
      });
  return out;
}

}  // namespace limn::render::metrics
