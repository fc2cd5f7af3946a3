#include "formats/obj_scan.h"

#include <charconv>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <set>
#include <system_error>

#include "render/core/error.h"
#include "render/core/quoted.h"

namespace limn::formats {

namespace {

using render::InputError;

// tinyobjloader's own limit on face size: it stores vertex counts in an unsigned char.
constexpr int kMaxObjFaceSize = 255;

[[noreturn]] void syntax(int line, const std::string& message) {
  std::string subject = "line " + std::to_string(line);
  throw InputError(InputError::Kind::InvalidMesh, subject, subject + ": " + message);
}

[[noreturn]] void overLimit(const std::string& limit, int line, const std::string& message) {
  throw InputError(InputError::Kind::LimitExceeded, limit,
                   "line " + std::to_string(line) + ": " + message + ": exceeds limit " + limit);
}

// Splits on spaces and tabs into `tokens` (reused across lines: no allocation per line).
void tokenize(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
}

bool isDigit(char c) { return c >= '0' && c <= '9'; }

// [+-]? (digits ('.' digits*)? | '.' digits) ([eE] [+-]? digits)?: the decimal numbers that
// tinyobjloader reads the same way strtod does.
bool isDecimal(std::string_view t) {
  size_t i = 0;
  if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
  size_t intDigits = 0, fracDigits = 0;
  while (i < t.size() && isDigit(t[i])) ++i, ++intDigits;
  if (i < t.size() && t[i] == '.') {
    ++i;
    while (i < t.size() && isDigit(t[i])) ++i, ++fracDigits;
  }
  if (intDigits + fracDigits == 0) return false;
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    size_t expDigits = 0;
    while (i < t.size() && isDigit(t[i])) ++i, ++expDigits;
    if (expDigits == 0) return false;
  }
  return i == t.size();
}

// A finite decimal number, or a syntax error that says what is wrong with `token`.
double parseNumber(std::string_view token, int line, const char* what) {
  if (isDecimal(token)) {
    // from_chars takes no '+'; it reports overflow and underflow alike as out of range, so
    // that rare case goes through strtod, which returns 0 on underflow and HUGE_VAL on overflow.
    std::string_view digits = token[0] == '+' ? token.substr(1) : token;
    double value = 0;
    auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (error == std::errc() && end == digits.data() + digits.size()) return value;
    value = std::strtod(std::string(token).c_str(), nullptr);
    if (!std::isfinite(value)) {
      syntax(line, std::string(what) + " " + render::quoted(token) +
                       " is not finite (overflows a double)");
    }
    return value;
  }
  std::string text(token);
  char* end = nullptr;
  double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() + text.size() && !std::isfinite(value)) {
    syntax(line, std::string(what) + " " + render::quoted(token) + " is not finite");
  }
  syntax(line, std::string(what) + " " + render::quoted(token) + " is not a decimal number");
}

// [+-]? digits within int range.
bool parseInt(std::string_view t, int* out) {
  size_t i = (!t.empty() && (t[0] == '+' || t[0] == '-')) ? 1 : 0;
  if (i == t.size() || t.size() - i > 10) return false;
  long long value = 0;
  for (size_t k = i; k < t.size(); ++k) {
    if (!isDigit(t[k])) return false;
    value = value * 10 + (t[k] - '0');
  }
  if (t[0] == '-') value = -value;
  if (value < INT_MIN || value > INT_MAX) return false;
  *out = static_cast<int>(value);
  return true;
}

// Statements that carry nothing limn uses and are skipped silently.
const std::set<std::string_view> kSkipped = {"vt", "vn", "vp", "g", "o", "s", "usemtl", "mtllib"};
// Statements skipped with a warning: elements that are not faces, and free-form geometry.
const std::set<std::string_view> kIgnoredWithWarning = {
    "l",      "p",      "cstype",     "deg",       "bmat",     "step",     "curv",
    "curv2",  "surf",   "parm",       "trim",      "hole",     "scrv",     "sp",
    "end",    "con",    "mg",         "bevel",     "c_interp", "d_interp", "lod",
    "maplib", "usemap", "shadow_obj", "trace_obj", "ctech",    "stech"};

class Scanner {
 public:
  explicit Scanner(const render::mesh::MeshLimits& limits) : limits_(limits) {}

  void line(std::string_view text, int number) {
    tokenize(text, tokens_);
    const std::vector<std::string_view>& tokens = tokens_;
    if (tokens.empty() || tokens[0][0] == '#') return;
    std::string_view keyword = tokens[0];
    if (keyword == "v") return vertex(tokens, number);
    if (keyword == "f") return face(tokens, number);
    if (keyword == "t") return tag(tokens, number);
    if (kSkipped.count(keyword)) return;
    if (kIgnoredWithWarning.count(keyword)) {
      if (warned_.insert(std::string(keyword)).second) {
        scan_.warnings.push_back("line " + std::to_string(number) + ": OBJ statement " +
                                 render::quoted(keyword) +
                                 " is not used by limn and was ignored (here and later)");
      }
      return;
    }
    syntax(number, "unknown OBJ statement " + render::quoted(keyword));
  }

  ObjScan take() { return std::move(scan_); }

 private:
  void vertex(const std::vector<std::string_view>& tokens, int line) {
    size_t values = tokens.size() - 1;
    if (values != 3 && values != 4 && values != 6) {
      syntax(line, "a vertex needs x y z (optionally w, or r g b), got " + std::to_string(values) +
                       " values");
    }
    for (size_t i = 1; i < tokens.size(); ++i) parseNumber(tokens[i], line, "vertex coordinate");
    if (static_cast<int>(scan_.vertexLines.size()) >= limits_.maxVertices) {
      overLimit("maxVertices", line,
                "mesh has more than " + std::to_string(limits_.maxVertices) + " vertices");
    }
    scan_.vertexLines.push_back(line);
  }

  void face(const std::vector<std::string_view>& tokens, int line) {
    const std::string face = "face " + std::to_string(scan_.faceLines.size());
    int n = static_cast<int>(tokens.size()) - 1;
    if (n < 3) syntax(line, face + " has " + std::to_string(n) + " vertices: at least 3 needed");
    if (n > limits_.maxFaceSize) {
      overLimit("maxFaceSize", line, face + " has " + std::to_string(n) + " vertices");
    }
    if (n > kMaxObjFaceSize) {
      syntax(line, face + " has " + std::to_string(n) + " vertices: OBJ faces may have at most " +
                       std::to_string(kMaxObjFaceSize));
    }
    int verticesSoFar = static_cast<int>(scan_.vertexLines.size());
    for (int k = 1; k <= n; ++k) {
      std::string_view token = tokens[k];
      // v, v/vt, v//vn or v/vt/vn: every index a non-zero integer, vt may be empty with vn.
      std::string_view parts[3];
      size_t count = 0, start = 0;
      bool ok = true;
      for (;;) {
        size_t slash = token.find('/', start);
        if (count == 3) {
          ok = false;
          break;
        }
        parts[count++] = token.substr(
            start, slash == std::string_view::npos ? std::string_view::npos : slash - start);
        if (slash == std::string_view::npos) break;
        start = slash + 1;
      }
      int index = 0;
      for (size_t p = 0; ok && p < count; ++p) {
        if (p == 1 && count == 3 && parts[1].empty()) continue;  // v//vn
        int value = 0;
        ok = parseInt(parts[p], &value) && value != 0;
        if (p == 0) index = value;
      }
      if (!ok) {
        syntax(line, face + ": " + render::quoted(token) +
                         " is not a vertex reference (v, v/vt, v//vn or v/vt/vn with non-zero "
                         "integer indices; OBJ indices start at 1)");
      }
      if (index < 0 && verticesSoFar + index < 0) {
        syntax(line, face + ": relative index " + std::to_string(index) + " reaches before the " +
                         "first vertex (only " + std::to_string(verticesSoFar) +
                         " vertices precede it)");
      }
    }
    if (static_cast<int>(scan_.faceLines.size()) >= limits_.maxFaces) {
      overLimit("maxFaces", line,
                "mesh has more than " + std::to_string(limits_.maxFaces) + " faces");
    }
    scan_.faceLines.push_back(line);
  }

  void tag(const std::vector<std::string_view>& tokens, int line) {
    if (tokens.size() < 3) {
      syntax(line, "a tag line needs a name and a size triple, e.g. \"t crease 2/1/0 0 1 2.0\"");
    }
    ObjTag tag;
    tag.line = line;
    tag.name = std::string(tokens[1]);
    // nInts[/nFloats[/nStrings]], as tinyobjloader reads it.
    int counts[3] = {0, 0, 0};
    std::string_view header = tokens[2];
    size_t start = 0;
    for (int c = 0; c < 3; ++c) {
      size_t slash = header.find('/', start);
      std::string_view part = header.substr(
          start, slash == std::string_view::npos ? std::string_view::npos : slash - start);
      if (!parseInt(part, &counts[c]) || counts[c] < 0 || part[0] == '+' || part[0] == '-') {
        syntax(line, "tag " + render::quoted(tag.name) + " has the size triple " +
                         render::quoted(header) + ": expected nInts/nFloats/nStrings, e.g. 2/1/0");
      }
      if (slash == std::string_view::npos) break;
      start = slash + 1;
      if (c == 2) syntax(line, "tag size triple " + render::quoted(header) + " has too many parts");
    }
    size_t expected = static_cast<size_t>(counts[0]) + counts[1] + counts[2];
    if (tokens.size() - 3 != expected) {
      syntax(line, "tag " + render::quoted(tag.name) + " declares " + std::string(header) + " = " +
                       std::to_string(expected) + " values but the line has " +
                       std::to_string(tokens.size() - 3));
    }
    size_t at = 3;
    for (int i = 0; i < counts[0]; ++i, ++at) {
      int value = 0;
      if (!parseInt(tokens[at], &value)) {
        syntax(line, "tag " + render::quoted(tag.name) + ": " + render::quoted(tokens[at]) +
                         " is not an integer");
      }
      tag.ints.push_back(value);
    }
    for (int i = 0; i < counts[1]; ++i, ++at) {
      tag.floats.push_back(parseNumber(tokens[at], line, ("tag " + tag.name + ": value").c_str()));
    }
    for (int i = 0; i < counts[2]; ++i, ++at) tag.strings.emplace_back(tokens[at]);
    scan_.tags.push_back(std::move(tag));
  }

  const render::mesh::MeshLimits& limits_;
  std::vector<std::string_view> tokens_;
  ObjScan scan_;
  std::set<std::string> warned_;
};

}  // namespace

ObjScan scanObj(std::string_view text, const render::mesh::MeshLimits& limits) {
  Scanner scanner(limits);
  // Lines end at \n, \r\n or a lone \r, exactly as tinyobjloader counts them.
  int number = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = pos;
    while (end < text.size() && text[end] != '\n' && text[end] != '\r') ++end;
    ++number;
    std::string_view line = text.substr(pos, end - pos);
    if (line.find('\0') != std::string_view::npos) syntax(number, "contains a NUL byte");
    scanner.line(line, number);
    pos = end;
    if (pos < text.size()) {
      bool crlf = text[pos] == '\r' && pos + 1 < text.size() && text[pos + 1] == '\n';
      pos += crlf ? 2 : 1;
    }
  }
  return scanner.take();
}

}  // namespace limn::formats
