// writeSilhouetteSvg: ContourResult -> an SVG drawing of the contour in the camera's pixel
// coordinates (x right, y down: SVG's own convention, so no transform is needed).
//
// One <path> per piece. Where visibility changes between two points, the segment joining them
// belongs to neither piece (splitPieces()); each piece is drawn on to that segment's midpoint,
// so the line stays continuous and the change shows half-way. Hidden pieces are drawn first,
// dashed and light, so the visible outline lies on top where the two meet.
#include <cstdio>
#include <string>

#include "api/silhouette_api.h"

namespace limn::api {

namespace {

using render::Vec3;
using render::pipeline::ContourLine;
using render::silhouette::PolylinePiece;

constexpr const char* kVisibleStyle = R"(stroke="#1a1a1a" stroke-width="1.5")";
constexpr const char* kHiddenStyle = R"(stroke="#b0b0b0" stroke-width="1" stroke-dasharray="4 3")";

void appendPoint(std::string& d, char command, double x, double y) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%c%.2f %.2f", command, x, y);
  if (!d.empty()) d += ' ';
  d += buf;
}

// The path data of one piece of `line` (see the file comment for the half segments).
std::string pieceData(const ContourLine& line, const PolylinePiece& piece) {
  const int n = static_cast<int>(line.points.size());
  const bool whole = line.pieces.size() == 1;
  std::string d;
  auto pixel = [&](int i) -> const Vec3& { return line.points[(i + n) % n].pixel; };
  auto midpoint = [&](int a, int b) {
    return Vec3{(pixel(a).x + pixel(b).x) / 2, (pixel(a).y + pixel(b).y) / 2, 0};
  };
  bool hasPrevious = !whole && (piece.start > 0 || line.closed);
  bool hasNext = !whole && (piece.end + 1 < n || line.closed);
  if (hasPrevious) {
    Vec3 m = midpoint(piece.start - 1, piece.start);
    appendPoint(d, 'M', m.x, m.y);
  }
  for (int i = piece.start; i <= piece.end; ++i) {
    appendPoint(d, d.empty() ? 'M' : 'L', pixel(i).x, pixel(i).y);
  }
  if (hasNext) {
    Vec3 m = midpoint(piece.end, piece.end + 1);
    appendPoint(d, 'L', m.x, m.y);
  }
  if (whole && line.closed) d += " Z";
  return d;
}

// XML comments may not hold "--"; warnings are echoed there with it broken up.
std::string commentText(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '-' && !out.empty() && out.back() == '-') out += ' ';
    out += static_cast<unsigned char>(c) < 0x20 ? ' ' : c;
  }
  if (!out.empty() && out.back() == '-') out += ' ';
  return out;
}

}  // namespace

std::string writeSilhouetteSvg(const render::pipeline::ContourResult& result,
                               const SilhouetteRequest& request) {
  const int width = result.camera.width(), height = result.camera.height();
  const render::pipeline::ContourStats& s = result.stats;
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(width) +
         "\" height=\"" + std::to_string(height) + "\" viewBox=\"0 0 " + std::to_string(width) +
         " " + std::to_string(height) + "\">\n";
  out += "<!-- limn contours of the limit surface: " + std::to_string(s.polylines) +
         " polylines, " + std::to_string(s.visiblePieces) + " visible and " +
         std::to_string(s.hiddenPieces) + " hidden pieces -->\n";
  for (const std::string& w : request.warnings) out += "<!-- warning: " + commentText(w) + " -->\n";
  for (const std::string& w : result.warnings) out += "<!-- warning: " + commentText(w) + " -->\n";
  out += "<rect width=\"" + std::to_string(width) + "\" height=\"" + std::to_string(height) +
         "\" fill=\"#ffffff\"/>\n";
  out += "<g fill=\"none\" stroke-linecap=\"round\" stroke-linejoin=\"round\">\n";
  for (bool visible : {false, true}) {
    for (size_t i = 0; i < result.polylines.size(); ++i) {
      const ContourLine& line = result.polylines[i];
      for (const PolylinePiece& piece : line.pieces) {
        if (piece.visible != visible) continue;
        out += std::string("<path class=\"") + (visible ? "visible" : "hidden") +
               "\" data-polyline=\"" + std::to_string(i) + "\" " +
               (visible ? kVisibleStyle : kHiddenStyle) + " d=\"" + pieceData(line, piece) +
               "\"/>\n";
      }
    }
  }
  out += "</g>\n</svg>\n";
  return out;
}

}  // namespace limn::api
