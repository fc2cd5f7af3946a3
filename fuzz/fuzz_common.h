// What every fuzz target shares: the limits a server with the built-in configuration applies,
// and the rule that only the errors the API documents may leave a parser. Anything else (an
// uncaught std::out_of_range, a crash, a sanitizer report) is a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "api/answer.h"
#include "api/config.h"
#include "render/core/error.h"

namespace limn::fuzz {

inline const render::pipeline::JobLimits& defaultLimits() {
  static const render::pipeline::JobLimits limits = api::ServiceConfig{}.limits;
  return limits;
}

inline std::string_view asText(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Runs `parse`; the documented refusals (ApiError, InputError) are expected answers.
template <class Parse>
void expectOnlyDocumentedErrors(Parse&& parse) {
  try {
    parse();
  } catch (const api::ApiError&) {
  } catch (const render::InputError&) {
  }
}

}  // namespace limn::fuzz
