// `limn batch`: a batch of comparisons from a spec file or from --meshes/--methods/--views,
// computed by a local pool of render workers (each with its own EGL context, as `limn serve`
// runs them) or by a running server (--server URL, through POST /v1/compare), resumable, with a
// report at the end; `limn batch --report DIR` only writes the report. docs/batch.md.
#pragma once

namespace limn::server {

// argv[1] is "batch". Exit status: 0 every row computed, 1 usage or configuration, 2 a spec or
// mesh limn refuses, 3 the run could not finish (no GL context, server unavailable or gone),
// 4 done, but some rows carry errors (summary.md lists them).
int batchCommand(int argc, char** argv);

}  // namespace limn::server
