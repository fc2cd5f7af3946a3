#include "tests/integration/openapi_check.h"

#include <sys/stat.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "tests/integration/server_process.h"

namespace limn::testing {

OpenApiCheck checkAgainstOpenApi(int port, const std::vector<ApiExchange>& exchanges) {
  const std::string folder = writeTempFile("", "");
  std::remove(folder.c_str());
  if (::mkdir(folder.c_str(), 0700) != 0) throw std::runtime_error("cannot make " + folder);
  OpenApiCheck check;
  for (size_t i = 0; i < exchanges.size(); ++i) {
    const ApiExchange& e = exchanges[i];
    HttpResponse r = HttpClient(port).request(e.method, e.path, e.body, e.headers);
    check.statuses.insert(r.status);
    const std::string name = folder + "/" + std::to_string(100 + i);
    std::ofstream(name + ".meta") << e.method << " "
                                  << (e.documented.empty() ? e.path : e.documented) << " "
                                  << r.status << " " << r.header("Content-Type");
    std::ofstream(name + ".body", std::ios::binary) << r.body;
  }
  CommandResult result =
      runCommand("/usr/bin/python3 '" LIMN_SOURCE_DIR
                 "/tests/integration/check_openapi.py' '" LIMN_SOURCE_DIR "/api/openapi.json' '" +
                 folder + "'");
  runCommand("rm -rf '" + folder + "'");
  check.status = result.status;
  check.output = result.output;
  return check;
}

}  // namespace limn::testing
