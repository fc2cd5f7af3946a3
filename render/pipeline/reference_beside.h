// ReferenceBeside: the reference's first half (oracle::beginReference: its scene, primary rays
// and shaded passes, which need nothing of the approximation) run on a thread of its own while
// the calling thread draws the approximation, whose mask the second half then takes as its hint.
// On two cores this fills the one llvmpipe's vertex stage leaves idle (bench/reference_results.md).
#pragma once

#include <future>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/core/passes.h"
#include "render/oracle/reference.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::pipeline {

class ReferenceBeside {
 public:
  // Starts beginReference(surface, camera, passes, .., options); `surface` and `cancel` must
  // outlive this object. Call on the thread that holds the rasteriser: options.colorSamples
  // come from it beforehand.
  ReferenceBeside(const subdiv::LimitSurface& surface, const Camera& camera,
                  const PassSelection& passes, const CancelToken& cancel,
                  oracle::ReferenceOptions options);
  // When the reference was not finished (the drawing beside it threw): stops it and waits, so
  // that nothing it uses is destroyed under it.
  ~ReferenceBeside();
  ReferenceBeside(const ReferenceBeside&) = delete;
  ReferenceBeside& operator=(const ReferenceBeside&) = delete;

  // The whole reference: waits for the first half (rethrowing what it threw) and runs
  // finishReference with `hinted` (options as given, with the hint now set).
  oracle::ReferenceResult finish(const oracle::ReferenceOptions& hinted);
  // The reference's own time: the first half's and finish()'s, not the wait between them.
  double ownMs() const { return begunMs_ + finishMs_; }

 private:
  Camera camera_;
  PassSelection passes_;
  CancelToken cancel_;  // expires with the caller's, or alone when this object is destroyed early
  double begunMs_ = 0, finishMs_ = 0;
  std::future<oracle::BegunReference> begun_;
};

}  // namespace limn::render::pipeline
