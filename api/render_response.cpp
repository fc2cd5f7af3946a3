// writeRenderResponse: RenderResult -> the 200 answer's JSON, in DESIGN.md's shape. Images are
// encoded (PNG or EXR) and carried as base64; numbers that are not finite are written as null.
#include <chrono>
#include <string_view>
#include <utility>

#include "api/base64.h"
#include "api/json_util.h"
#include "api/render_api.h"
#include "api/request_parts.h"
#include "api/response_parts.h"
#include "render/core/parallel.h"

namespace limn::api {

namespace {

using json::writeNumber;
using json::Writer;
using render::pipeline::Outputs;

void numberField(Writer& w, const char* key, double value) {
  w.Key(key);
  writeNumber(w, value);
}

void countField(Writer& w, const char* key, size_t value) {
  w.Key(key);
  w.Uint64(value);
}

// The order images appear in the answer.
std::vector<const char*> requestedPasses(const Outputs& outputs) {
  std::vector<const char*> names;
  if (outputs.color) names.push_back(render::pass::kColor);
  if (outputs.mask) names.push_back(render::pass::kMask);
  if (outputs.depth) names.push_back(render::pass::kDepth);
  if (outputs.normal) names.push_back(render::pass::kNormal);
  if (outputs.wireframe) names.push_back(render::pass::kWireframe);
  if (outputs.contours) names.push_back(render::pass::kContours);
  if (outputs.cage) names.push_back(render::pass::kCage);
  if (outputs.diff) names.push_back(render::pass::kDiff);
  if (outputs.patches) names.push_back(render::pass::kPatches);
  return names;
}

// The passes of `images` an answer carries for `outputs`, in order, each with its image (null
// when `owner` did not produce it). The contour and cage overlays are drawn over the method's
// image, the diff compares it with the reference and the patch image shows its patches; the
// reference has none.
std::vector<std::pair<const char*, const render::Image*>> passesToWrite(
    const render::ImageSet& images, const Outputs& outputs, std::string_view owner) {
  std::vector<std::pair<const char*, const render::Image*>> passes;
  for (const char* name : requestedPasses(outputs)) {
    const std::string_view pass = name;
    if (owner == "reference" && (pass == render::pass::kContours || pass == render::pass::kCage ||
                                 pass == render::pass::kDiff || pass == render::pass::kPatches)) {
      continue;
    }
    const render::Image* image = images.find(name);
    passes.emplace_back(name, image && !image->empty() ? image : nullptr);
  }
  return passes;
}

void writeImages(Writer& w, const render::ImageSet& images, const AnswerShape& shape,
                 const char* owner, std::vector<std::string>& warnings,
                 const response::EncodedImages* encodedAhead = nullptr) {
  w.StartObject();
  for (const auto& [name, image] : passesToWrite(images, shape.outputs, owner)) {
    if (!image) {
      warnings.push_back(std::string("output \"") + name + "\" was requested but the " + owner +
                         " did not produce it");
      continue;
    }
    const response::EncodedPass* ahead = encodedAhead ? encodedAhead->find(image) : nullptr;
    const response::EncodedPass encoded =
        ahead ? response::EncodedPass{} : response::encodePass(*image, name, shape.encoding);
    const response::EncodedPass& pass = ahead ? *ahead : encoded;
    w.Key(name);
    w.StartObject();
    w.Key("mime");
    json::writeString(w, pass.mime);
    w.Key("width");
    w.Int(pass.width);
    w.Key("height");
    w.Int(pass.height);
    w.Key("data");
    // Base64 needs no escaping: skip the writer's per-character scan of a large string.
    w.RawValue(pass.quotedBase64.c_str(), pass.quotedBase64.size(), rapidjson::kStringType);
    w.EndObject();
  }
  w.EndObject();
}

void writeMetrics(Writer& w, const render::metrics::Metrics& m) {
  w.StartObject();
  if (m.silhouette) {
    w.Key("silhouette");
    w.StartObject();
    numberField(w, "hausdorffPx", m.silhouette->hausdorffPx);
    numberField(w, "meanPx", m.silhouette->meanPx);
    numberField(w, "iou", m.silhouette->iou);
    w.Key("mismatchPx");
    w.Int64(m.silhouette->mismatchPx);
    if (m.silhouette->outlineHausdorffPx) {
      numberField(w, "outlineHausdorffPx", *m.silhouette->outlineHausdorffPx);
      numberField(w, "outlineMeanPx", m.silhouette->outlineMeanPx.value_or(0.0));
      w.Key("outlineUnresolvedLoops");
      w.Int64(m.silhouette->outlineUnresolvedLoops);
    }
    w.EndObject();
  }
  if (m.image) {
    w.Key("image");
    w.StartObject();
    numberField(w, "rmse", m.image->rmse);
    numberField(w, "psnr", m.image->psnr);
    if (m.image->diffScale) numberField(w, "diffScale", *m.image->diffScale);
    w.EndObject();
  }
  if (m.depth) {
    w.Key("depth");
    w.StartObject();
    numberField(w, "maxRel", m.depth->maxRel);
    numberField(w, "meanRel", m.depth->meanRel);
    w.EndObject();
  }
  if (m.normal) {
    w.Key("normal");
    w.StartObject();
    numberField(w, "meanDeg", m.normal->meanDeg);
    numberField(w, "maxDeg", m.normal->maxDeg);
    w.EndObject();
  }
  if (m.geometry) {
    w.Key("geometry");
    w.StartObject();
    numberField(w, "maxDist", m.geometry->maxDist);
    numberField(w, "meanDist", m.geometry->meanDist);
    numberField(w, "relMaxDist", m.geometry->relMaxDist);
    numberField(w, "relMeanDist", m.geometry->relMeanDist);
    w.EndObject();
  }
  w.EndObject();
}

void writeSilhouetteStats(Writer& w, const render::silhouette::SilhouetteStats& s,
                          bool presubdivided) {
  w.Key("silhouette");
  w.StartObject();
  w.Key("presubdivided");
  w.Bool(presubdivided);
  auto count = [&](const char* key, size_t value) { countField(w, key, value); };
  count("presubdivisionLevels", static_cast<size_t>(s.presubdivisionLevels));
  count("edgesTested", s.search.edgesTested);
  count("edgesWithSignChange", s.search.edgesWithSignChange);
  count("edgesSampled", s.search.edgesSampled);
  count("doubleCrossingEdges", s.search.doubleCrossings);
  count("interiorLoopFaces", s.search.interiorLoopFaces);
  count("outlineEdges", s.search.outlineEdges);
  count("contourPoints", s.search.contourPoints);
  count("contourFaces", s.contourFaces);
  count("correctedFaces", s.correctedFaces);
  count("trianglesCulled", s.trianglesCulled);
  count("curveSamples", s.curveSamples);
  count("unresolvedSamples", s.unresolvedSamples);
  count("refinedEdges", s.refinedEdges);
  count("refinedFaces", s.refinedFaces);
  count("interiorSplits", s.interiorSplits);
  count("trianglesAdded", s.trianglesAdded);
  count("trianglesDrawn", s.trianglesDrawn);
  w.EndObject();
}

void writeImplicitStats(Writer& w, const render::pipeline::Stats::Implicit& s) {
  const render::implicit::PolygonizerStats& p = s.polygonizer;
  w.Key("implicit");
  w.StartObject();
  auto count = [&](const char* key, size_t value) { countField(w, key, value); };
  count("primitives", s.primitives);
  w.Key("polygonizer");
  w.String(render::implicit::polygonizerName(s.method));
  count("boundaryEdges", s.closure.boundaryEdges);
  count("nonManifoldEdges", s.closure.nonManifoldEdges);
  count("misorientedEdges", s.closure.misorientedEdges);
  count("cellsVisited", p.cellsVisited);
  count("fieldSamples", p.fieldSamples);
  count("octreeLeaves", p.octreeLeaves);
  count("edgesSplit", p.edgesSplit);
  w.Key("gridCells");
  w.StartArray();
  for (int n : p.gridCells) w.Int(n);
  w.EndArray();
  numberField(w, "cellSize", p.cellSize);
  numberField(w, "sampleMs", p.sampleMs);
  numberField(w, "polygonizeMs", p.polygonizeMs);
  numberField(w, "vertexMs", p.vertexMs);
  numberField(w, "sampleMvoxelsPerS", p.sampleMvoxelsPerS);
  w.EndObject();
}

void writePatchStats(Writer& w, const render::pipeline::Stats::Patches& s) {
  namespace patches = render::patches;
  w.Key("patchTable");
  w.StartObject();
  auto count = [&](const char* key, size_t value) { countField(w, key, value); };
  w.Key("isolation");
  w.Int(s.table.isolation);
  count("patches", s.table.patches);
  w.Key("byLevel");
  w.StartArray();
  for (size_t level = 0; level < s.table.byLevel.size(); ++level) {
    w.StartObject();
    count("level", level);
    for (int k = 0; k < patches::kPatchKinds; ++k) {
      count(patches::patchKindName(static_cast<patches::PatchKind>(k)), s.table.byLevel[level][k]);
    }
    w.EndObject();
  }
  w.EndArray();
  count("refinedPoints", s.table.refinedPoints);
  count("endCapPoints", s.table.endCapPoints);
  count("patchesDrawn", s.tessellation.patchesDrawn);
  count("patchesCulled", s.tessellation.patchesCulled);
  count("patchesOffScreen", s.tessellation.patchesOffScreen);
  count("patchesSplit", s.tessellation.patchesSplit);
  count("domains", s.tessellation.domains);
  count("transitionEdges", s.tessellation.transitionEdges);
  count("clampedEdges", s.tessellation.clampedEdges);
  count("crowdedDomains", s.tessellation.crowdedDomains);
  numberField(w, "dicingRate", s.tessellation.dicingRate);
  numberField(w, "tableMs", s.tableMs);
  numberField(w, "tessellateMs", s.tessellateMs);
  w.Key("tessellator");
  w.String(s.tessellator == render::pipeline::PatchTessellator::Gpu ? "gpu" : "cpu");
  count("gpuDraws", s.gpuDraws);
  w.EndObject();
}

void writeFrames(Writer& w, const std::vector<render::pipeline::RenderResult::Frame>& frames,
                 const AnswerShape& shape, std::vector<std::string>& warnings,
                 const response::EncodedImages* encodedAhead) {
  w.Key("frames");
  w.StartArray();
  for (const auto& frame : frames) {
    w.StartObject();
    w.Key("images");
    writeImages(w, frame.images, shape, "method", warnings, encodedAhead);
    w.Key("triangles");
    w.Uint64(frame.triangles);
    numberField(w, "approxMs", frame.approxMs);
    numberField(w, "rasterMs", frame.rasterMs);
    w.EndObject();
  }
  w.EndArray();
}

void writeStats(Writer& w, const render::pipeline::Stats& s) {
  w.StartObject();
  w.Key("controlVertices");
  w.Int(s.controlVertices);
  w.Key("controlFaces");
  w.Int(s.controlFaces);
  w.Key("triangles");
  w.Uint64(s.triangles);
  w.Key("vertices");
  w.Uint64(s.vertices);
  w.Key("patches");
  w.Uint64(s.patches);
  w.Key("referenceTriangles");
  w.Uint64(s.referenceTriangles);
  if (s.referenceCrossCheckPx) {
    numberField(w, "referenceCrossCheckPx", *s.referenceCrossCheckPx);
    numberField(w, "referenceCrossCheckMeanPx", s.referenceCrossCheckMeanPx.value_or(0.0));
    if (s.referenceCrossCheckOutlinePx) {
      numberField(w, "referenceCrossCheckOutlinePx", *s.referenceCrossCheckOutlinePx);
      numberField(w, "referenceCrossCheckOutlineMeanPx",
                  s.referenceCrossCheckOutlineMeanPx.value_or(0.0));
    }
  }
  if (s.silhouette) writeSilhouetteStats(w, *s.silhouette, s.presubdivided);
  if (s.patchTable) writePatchStats(w, *s.patchTable);
  if (s.implicit) {
    w.Key("closed");
    w.Bool(s.implicit->closure.closed());
    writeImplicitStats(w, *s.implicit);
  }
  w.EndObject();
}

// referenceMs split by stage, with what the reference cast and whether its scene was cached.
void writeReferenceStages(Writer& w, const render::oracle::ReferenceStats& s, double crossCheckMs) {
  w.Key("referenceStages");
  w.StartObject();
  numberField(w, "tessellateMs", s.tessellateMs);
  numberField(w, "bvhMs", s.bvhMs);
  numberField(w, "primaryRaysMs", s.traceMs);
  numberField(w, "newtonMs", s.newtonMs);
  numberField(w, "maskMs", s.maskMs);
  numberField(w, "outlineMs", s.outlineMs);
  numberField(w, "crossCheckMs", crossCheckMs);
  w.Key("sceneCached");
  w.Bool(s.sceneCached);
  w.Key("raysCast");
  w.Uint64(s.raysCast);
  w.Key("refinedPixels");
  w.Uint64(s.refinedPixels);
  w.EndObject();
}

// metricsMs split by stage: the silhouette masks, the located outlines, colour/depth/normal, and
// the distances to the limit surface.
void writeMetricsStages(Writer& w, const render::metrics::MetricsTimings& s) {
  w.Key("metricsStages");
  w.StartObject();
  numberField(w, "silhouetteMs", s.silhouetteMs);
  numberField(w, "outlineMs", s.outlineMs);
  numberField(w, "imageMs", s.imageMs);
  numberField(w, "geometryMs", s.geometryMs);
  w.EndObject();
}

void writeVec3(Writer& w, const render::Vec3& v) {
  w.StartArray();
  writeNumber(w, v.x);
  writeNumber(w, v.y);
  writeNumber(w, v.z);
  w.EndArray();
}

void writeCamera(Writer& w, const render::Camera& c) {
  w.StartObject();
  w.Key("eye");
  writeVec3(w, c.eye());
  w.Key("target");
  writeVec3(w, c.target());
  w.Key("up");
  writeVec3(w, c.up());
  numberField(w, "fovYDeg", c.fovYDeg());
  w.Key("projection");
  w.String(c.projection() == render::Projection::Perspective ? "perspective" : "orthographic");
  numberField(w, "orthoHeight", c.orthoHeight());
  w.Key("width");
  w.Int(c.width());
  w.Key("height");
  w.Int(c.height());
  w.EndObject();
}

}  // namespace

namespace response {

void writeCamera(Writer& w, const render::Camera& camera) { api::writeCamera(w, camera); }

EncodedPass encodePass(const render::Image& image, const char* passName,
                       render::image::Encoding encoding) {
  render::image::EncodedImage encoded =
      render::image::encode(image, passName, encoding.format, encoding.quality);
  return {.mime = std::move(encoded.mime),
          .width = encoded.width,
          .height = encoded.height,
          .quotedBase64 = "\"" + encodeBase64(encoded.bytes) + "\""};
}

EncodedImages::EncodedImages(const std::vector<Owned>& sets, const Outputs& outputs,
                             render::image::Encoding encoding) {
  std::vector<std::pair<const char*, const render::Image*>> all;
  for (const Owned& set : sets) {
    for (const auto& pass : passesToWrite(*set.images, outputs, set.owner)) {
      if (pass.second) all.push_back(pass);
    }
  }
  std::vector<EncodedPass> encoded(all.size());
  render::parallelFor(all.size(), 1, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      encoded[i] = encodePass(*all[i].second, all[i].first, encoding);
    }
  });
  for (size_t i = 0; i < all.size(); ++i) passes_.emplace(all[i].second, std::move(encoded[i]));
}

const EncodedPass* EncodedImages::find(const render::Image* image) const {
  auto it = passes_.find(image);
  return it == passes_.end() ? nullptr : &it->second;
}

void writeImages(Writer& w, const render::ImageSet& images, const Outputs& outputs,
                 render::image::Encoding encoding, const char* owner,
                 std::vector<std::string>& warnings, const EncodedImages* encodedAhead) {
  const std::vector<std::string> none;
  api::writeImages(
      w, images,
      AnswerShape{.outputs = outputs, .reference = false, .encoding = encoding, .warnings = none},
      owner, warnings, encodedAhead);
}

void writeMetrics(Writer& w, const render::metrics::Metrics& metrics) {
  api::writeMetrics(w, metrics);
}

void writeStats(Writer& w, const render::pipeline::Stats& stats) { api::writeStats(w, stats); }

void writeReferenceStages(Writer& w, const render::oracle::ReferenceStats& stats,
                          double crossCheckMs) {
  api::writeReferenceStages(w, stats, crossCheckMs);
}

void writeSilhouetteStats(Writer& w, const render::silhouette::SilhouetteStats& stats,
                          bool presubdivided) {
  api::writeSilhouetteStats(w, stats, presubdivided);
}

}  // namespace response

std::string writeRenderResponse(const render::pipeline::RenderResult& result,
                                const RenderRequest& request) {
  return writeRenderResponse(result, AnswerShape{.outputs = request.job.outputs,
                                                 .reference = request.job.reference,
                                                 .encoding = request.encoding,
                                                 .warnings = request.warnings});
}

std::string writeRenderResponse(const render::pipeline::RenderResult& result,
                                const AnswerShape& shape) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  std::vector<std::string> warnings = shape.warnings;
  warnings.insert(warnings.end(), result.warnings.begin(), result.warnings.end());

  std::vector<response::EncodedImages::Owned> sets;
  if (result.frames.empty()) sets.push_back({&result.images, "method"});
  for (const auto& frame : result.frames) sets.push_back({&frame.images, "method"});
  if (shape.reference && result.referenceImages) {
    sets.push_back({&*result.referenceImages, "reference"});
  }
  const response::EncodedImages encoded(sets, shape.outputs, shape.encoding);

  rapidjson::StringBuffer buffer;
  Writer w(buffer);
  w.StartObject();
  w.Key("images");
  if (result.frames.empty()) {
    writeImages(w, result.images, shape, "method", warnings, &encoded);
  } else {  // each frame has its own
    w.StartObject();
    w.EndObject();
    writeFrames(w, result.frames, shape, warnings, &encoded);
  }
  if (shape.reference) {
    w.Key("reference");
    w.StartObject();
    w.Key("images");
    if (result.referenceImages) {
      writeImages(w, *result.referenceImages, shape, "reference", warnings, &encoded);
    } else {
      w.StartObject();
      w.EndObject();
      warnings.push_back("the reference was requested but not produced");
    }
    if (result.timings.reference && result.timings.reference->accuracyPx > 0) {
      numberField(w, "accuracyPx", result.timings.reference->accuracyPx);  // mesh references
    }
    w.EndObject();
  }
  const double encodeMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();

  w.Key("metrics");
  writeMetrics(w, result.metrics);
  w.Key("stats");
  writeStats(w, result.stats);

  const render::pipeline::Timings& t = result.timings;
  w.Key("timings");
  w.StartObject();
  numberField(w, "parseMs", t.parseMs);
  numberField(w, "surfaceMs", t.surfaceMs);
  numberField(w, "approxMs", t.approxMs);
  numberField(w, "rasterMs", t.rasterMs);
  numberField(w, "referenceMs", t.referenceMs);
  numberField(w, "metricsMs", t.metricsMs);
  numberField(w, "encodeMs", encodeMs);
  numberField(w, "totalMs", t.parseMs + t.totalMs + encodeMs);
  if (t.reference) writeReferenceStages(w, *t.reference, t.crossCheckMs);
  if (t.metricsStages) writeMetricsStages(w, *t.metricsStages);
  w.EndObject();

  w.Key("warnings");
  json::writeStrings(w, warnings);

  w.Key("camera");
  writeCamera(w, result.camera);
  w.EndObject();
  return {buffer.GetString(), buffer.GetSize()};
}

namespace {

void appendImages(const json::Value* images, const std::string& prefix,
                  std::vector<DecodedImage>& out) {
  if (!images || !images->IsObject()) return;
  for (const auto& member : images->GetObject()) {
    const json::Value* mime = json::find(member.value, "mime");
    const json::Value* data = json::find(member.value, "data");
    if (!mime || !data || !mime->IsString() || !data->IsString()) continue;
    const std::string_view type = mime->GetString();
    const char* extension = type == "image/png"     ? ".png"
                            : type == "image/x-exr" ? ".exr"
                            : type == "image/jpeg"  ? ".jpg"
                            : type == "image/webp"  ? ".webp"
                                                    : ".bin";
    if (auto bytes = decodeBase64(data->GetString())) {
      out.push_back({prefix + member.name.GetString() + extension, std::move(*bytes)});
    }
  }
}

}  // namespace

std::vector<DecodedImage> imagesOf(std::string_view answerJson) {
  rapidjson::Document root;
  request::parseJson(answerJson, root);
  std::vector<DecodedImage> out;
  if (!root.IsObject()) return out;
  appendImages(json::find(root, "images"), "", out);
  if (const json::Value* reference = json::find(root, "reference");
      reference && reference->IsObject()) {
    appendImages(json::find(*reference, "images"), "reference_", out);
  }
  return out;
}

}  // namespace limn::api
