// The service configuration file: every key, its type and range; ConfigError is the answer.
#include "api/config.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    limn::api::parseConfig(limn::fuzz::asText(data, size));
  } catch (const limn::api::ConfigError&) {
  }
  return 0;
}
