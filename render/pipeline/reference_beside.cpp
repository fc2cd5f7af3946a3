#include "render/pipeline/reference_beside.h"

#include <utility>

#include "render/pipeline/job_checks.h"

namespace limn::render::pipeline {

ReferenceBeside::ReferenceBeside(const subdiv::LimitSurface& surface, const Camera& camera,
                                 const PassSelection& passes, const CancelToken& cancel,
                                 oracle::ReferenceOptions options)
    : camera_(camera), passes_(passes), cancel_(&cancel) {
  begun_ = std::async(std::launch::async, [this, &surface, options = std::move(options)] {
    Stopwatch own;
    oracle::BegunReference half =
        oracle::beginReference(surface, camera_, passes_, cancel_, options);
    begunMs_ = own.lapMs();
    return half;
  });
}

ReferenceBeside::~ReferenceBeside() {
  if (!begun_.valid()) return;
  cancel_.cancel();
  begun_.wait();
}

oracle::ReferenceResult ReferenceBeside::finish(const oracle::ReferenceOptions& hinted) {
  oracle::BegunReference half = begun_.get();
  Stopwatch own;
  oracle::ReferenceResult reference =
      oracle::finishReference(std::move(half), camera_, passes_, cancel_, hinted);
  finishMs_ = own.lapMs();
  return reference;
}

}  // namespace limn::render::pipeline
