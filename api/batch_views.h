// The reader of one entry of a batch spec's "cameras" (docs/batch.md): a view name, {"name",
// "camera"}, {"orbitRing": {...}} or {"random": {...}}, expanded into its views. Throws ApiError
// naming `field` ("cameras[2].random.count"). Used by parseBatchSpec (api/batch_spec.h).
#pragma once

#include <rapidjson/document.h>

#include <string>
#include <vector>

#include "api/batch_spec.h"
#include "render/pipeline/render_job.h"

namespace limn::api {

std::vector<ViewSpec> parseViewEntry(const rapidjson::Value& entry, const std::string& field,
                                     const render::pipeline::JobLimits& limits);

}  // namespace limn::api
