// The engine on generated meshes (issue 23). The input steers tests/support's hostile-mesh
// generator (FuzzChoices: non-manifold edges and vertices, valences 2-512, n-gons, holes, every
// boundary rule, creases and corners of every sharpness, degenerate and coincident faces,
// Catmull-Clark, Loop and bilinear), and its first 8 bytes seed the requests: the mesh goes, as
// OBJ text inside the JSON body so that validation runs as for users, through the api handlers
// in-process with a real Rasterizer, once per method — coarse; uniform by opensubdiv, masks and
// factored at one level 0-3; adaptive; silhouette; patches diced by the CPU and the GPU; limit;
// some with "reference": true — at 32 x 32, and through /v1/tessellate, /v1/silhouette and
// /v1/compare now and then (requestVariants, the list the server sweep sends too).
//
// The property: every answer is 200 or a 4xx (a mesh made invalid on purpose: a 4xx), and no
// /v1/compare row fails with a 5xx; 504 only once the input's deadline has passed (see below).
// A 500 aborts with the request and answer printed; a crash, a sanitizer report or an input
// slower than libFuzzer's -timeout is a finding as usual. This target loads Mesa (llvmpipe)
// through EGL: run it with detect_leaks=0 (scripts/fuzz.sh does), for the reason
// scripts/sanitize.sh gives. LIMN_ENGINE_FUZZ_VERBOSE=1 prints each request's time and status;
// LIMN_ENGINE_FUZZ_DUMP=DIR writes the requests of the inputs run, to replay with `limn render`.
#include <rapidjson/document.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "api/compare_api.h"
#include "api/render_api.h"
#include "api/silhouette_api.h"
#include "fuzz/fuzz_common.h"
#include "render/raster/rasterizer.h"
#include "tests/support/mesh_generator.h"

namespace {

using limn::api::Answer;
using limn::testing::GeneratedMesh;
using limn::testing::RequestVariant;

// One rasterizer (and its GL context, and the GPU tessellator it compiles on first use) for the
// whole run, as a render worker has; never destroyed (Mesa's teardown at exit is not ours).
limn::render::pipeline::RenderContext& context() {
  static auto* ctx = [] {
    auto* c = new limn::render::pipeline::RenderContext;
    c->rasterizer = new limn::render::raster::Rasterizer();
    return c;
  }();
  return *ctx;
}

[[noreturn]] void finding(const std::string& what, const RequestVariant& v,
                          const GeneratedMesh& mesh, const Answer& answer) {
  std::fprintf(stderr,
               "\n=== engine_fuzz finding: %s\nmesh: %s\nrequest: %s %s (Accept: %s)\n"
               "status %d, answer: %.4000s\nbody: %s\n",
               what.c_str(), mesh.description.c_str(), v.path.c_str(), v.label.c_str(),
               v.accept.c_str(), answer.status, answer.body.c_str(), v.body.c_str());
  std::abort();
}

// A compare answer's rows fail one by one inside a 200; a 5xx among them is a finding too.
bool compareRowFailed(const std::string& body, const limn::render::CancelToken& deadline) {
  rapidjson::Document doc;
  doc.Parse(body.c_str(), body.size());
  if (doc.HasParseError() || !doc.IsObject() || !doc.HasMember("rows") || !doc["rows"].IsArray()) {
    return true;
  }
  for (const auto& row : doc["rows"].GetArray()) {
    if (!row.HasMember("error")) continue;
    const int status = row["error"]["status"].GetInt();
    if (status >= 500 && !(status == 504 && deadline.expired())) return true;
  }
  return false;
}

void check(const Answer& answer, const RequestVariant& v, const GeneratedMesh& mesh,
           const limn::render::CancelToken& deadline) {
  const int s = answer.status;
  // The input's deadline passed: 504 timeout is the service's answer (limn serve's
  // requestTimeoutMs); before it, a 504 is a finding like any other 5xx.
  if (s == 504 && deadline.expired()) return;
  if (s == 200) {
    if (!mesh.refusal.empty())
      finding("200 for a mesh made invalid (" + mesh.refusal + ")", v, mesh, answer);
    if (v.path == "/v1/compare" && compareRowFailed(answer.body, deadline)) {
      finding("a /v1/compare row failed with a 5xx (or no rows)", v, mesh, answer);
    }
    return;
  }
  if (s == 400 || s == 404 || s == 406 || s == 413 || s == 422) return;
  finding("status " + std::to_string(s), v, mesh, answer);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace limn;
  // The first 8 bytes seed the requests' choices (cameras, params, outputs, which endpoints);
  // the rest is the mesh.
  uint64_t requestSeed = 0;
  const size_t head = size < 8 ? size : 8;
  std::memcpy(&requestSeed, data, head);
  testing::FuzzChoices meshChoices(data + head, size - head);
  testing::GeneratorOptions options;
  options.maxFaces = 200;
  // Valences up to 128: past that a boundary vertex makes the limit surface take gigabytes
  // (a known finding, docs/operations.md "Fuzzing"; tests/integration's sweep says more), which
  // would stop every run at -rss_limit_mb.
  options.maxValence = 128;
  const GeneratedMesh mesh = testing::generateMesh(meshChoices, options);
  testing::SeededChoices requestChoices(requestSeed);
  const auto& limits = fuzz::defaultLimits();
  // One deadline for all of an input's requests, as the server gives each request one: a few
  // degenerate meshes make the reference tessellate up to its 12M-triangle budget (seconds
  // each, minutes under the sanitizers), and past the deadline the remaining requests answer
  // 504 at once. A stage that does not check its CancelToken overruns it and shows up as a
  // libFuzzer timeout. LIMN_ENGINE_FUZZ_DEADLINE_MS changes it (default 20000).
  static const long deadlineMs = [] {
    const char* text = std::getenv("LIMN_ENGINE_FUZZ_DEADLINE_MS");
    return text ? std::atol(text) : 20000L;
  }();
  const render::CancelToken cancel(render::CancelToken::Clock::now() +
                                   std::chrono::milliseconds(deadlineMs));
  // LIMN_ENGINE_FUZZ_VERBOSE=1: each request's label, status and time (which is slow).
  // LIMN_ENGINE_FUZZ_DUMP=DIR: each request's body written to DIR/<k>.json (path, Accept and
  // label in DIR/<k>.txt), for `limn render` or curl.
  static const bool verbose = std::getenv("LIMN_ENGINE_FUZZ_VERBOSE") != nullptr;
  static const char* dump = std::getenv("LIMN_ENGINE_FUZZ_DUMP");
  if (verbose) std::fprintf(stderr, "mesh: %s\n", mesh.description.c_str());
  int k = 0;
  for (const RequestVariant& v : testing::requestVariants(mesh, requestChoices)) {
    if (dump) {
      const std::string base = std::string(dump) + "/" + std::to_string(k++);
      std::ofstream(base + ".json") << v.body;
      std::ofstream(base + ".txt") << v.path << "\n" << v.accept << "\n" << v.label << "\n";
    }
    const auto start = std::chrono::steady_clock::now();
    Answer answer;
    if (v.path == "/v1/render") {
      answer = api::handleRender(v.body, limits, context(), cancel);
    } else if (v.path == "/v1/tessellate") {
      answer = api::handleTessellate(v.body, v.accept, limits, cancel);
    } else if (v.path == "/v1/silhouette") {
      answer = api::handleSilhouette(v.body, v.accept, limits, cancel);
    } else {
      answer = api::handleCompare(v.body, limits, context(), cancel);
    }
    if (verbose) {
      std::fprintf(
          stderr, "  %-40s %d %8.1f ms\n", (v.path + " " + v.label).c_str(), answer.status,
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count());
    }
    check(answer, v, mesh, cancel);
  }
  return 0;
}
