#include "api/accept.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <string>

namespace limn::api {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

// The q of one media range's parameters ("; q=0.5; ..."); 1 when absent or unreadable.
double qualityOf(std::string_view parameters) {
  while (!parameters.empty()) {
    const size_t semicolon = parameters.find(';');
    const std::string_view p = trim(parameters.substr(0, semicolon));
    parameters = semicolon == std::string_view::npos ? "" : parameters.substr(semicolon + 1);
    if (p.size() > 2 && (p[0] == 'q' || p[0] == 'Q') && p[1] == '=') {
      const std::string value(p.substr(2));
      char* end = nullptr;
      const double q = std::strtod(value.c_str(), &end);
      return end == value.c_str() ? 1.0 : q;
    }
  }
  return 1.0;
}

}  // namespace

std::vector<MediaRange> parseAccept(std::string_view accept) {
  std::vector<MediaRange> ranges;
  while (!accept.empty()) {
    const size_t comma = accept.find(',');
    const std::string_view range = accept.substr(0, comma);
    accept = comma == std::string_view::npos ? "" : accept.substr(comma + 1);
    const size_t semicolon = range.find(';');
    const std::string_view type = trim(range.substr(0, semicolon));
    if (type.empty()) continue;
    ranges.push_back(
        {type, semicolon == std::string_view::npos ? 1.0 : qualityOf(range.substr(semicolon + 1))});
  }
  return ranges;
}

bool sameMediaType(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

std::optional<MeshFormat> chooseMeshFormat(std::string_view accept) {
  if (parseAccept(accept).empty()) return MeshFormat::Glb;
  struct Candidate {
    const char* type;
    MeshFormat format;
  };
  static constexpr Candidate kTypes[] = {{"model/gltf-binary", MeshFormat::Glb},
                                         {"application/x-ply", MeshFormat::Ply},
                                         {"model/ply", MeshFormat::Ply},
                                         {"text/plain", MeshFormat::Obj},
                                         {"model/obj", MeshFormat::Obj}};
  std::optional<MeshFormat> best;
  double bestQ = 0, anyQ = 0;
  for (const MediaRange& range : parseAccept(accept)) {
    if (range.type == "*/*" || sameMediaType(range.type, "model/*")) anyQ = std::max(anyQ, range.q);
    for (const Candidate& c : kTypes) {
      if (sameMediaType(range.type, c.type) && range.q > bestQ) {
        best = c.format;
        bestQ = range.q;
      }
    }
  }
  if (best && bestQ >= anyQ) return best;
  if (anyQ > 0) return MeshFormat::Glb;
  return std::nullopt;
}

const char* meshMime(MeshFormat format) {
  switch (format) {
    case MeshFormat::Glb:
      return "model/gltf-binary";
    case MeshFormat::Ply:
      return "application/x-ply";
    case MeshFormat::Obj:
      return "text/plain; charset=utf-8";
  }
  return "application/octet-stream";
}

}  // namespace limn::api
