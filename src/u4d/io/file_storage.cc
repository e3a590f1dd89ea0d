#include "u4d/io/file_storage.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "u4d/util/check.h"

namespace u4d {
namespace {

// Appends the numbers of a number or (nested) sequence node; false when the
// node holds anything else.
bool AppendSequence(const cv::FileNode& node, std::vector<double>* out) {
  if (node.isInt() || node.isReal()) {
    out->push_back(static_cast<double>(node));
    return true;
  }
  if (!node.isSeq()) return false;
  for (const cv::FileNode& x : node)
    if (!AppendSequence(x, out)) return false;
  return true;
}

bool IsMatrix(const cv::FileNode& node) {
  return node.isMap() && HasKey(node, "rows") && HasKey(node, "cols") && HasKey(node, "data");
}

std::string CountsText(const std::vector<int>& counts) {
  std::string s;
  for (size_t i = 0; i < counts.size(); ++i)
    s += (i == 0 ? "" : (i + 1 == counts.size() ? " or " : ", ")) + std::to_string(counts[i]);
  return s;
}

// Whether the rest of a line holds only spaces or a comment.
bool BlankOrComment(std::string_view rest) {
  const size_t i = rest.find_first_not_of(" \t\r");
  return i == std::string_view::npos || rest[i] == '#';
}

// OpenCV's YAML parser (4.6) loops forever on some multi-document input: after
// a document that ends early (content on its '---' line, or a '...' line) it
// reads the next from a stale line buffer, and a line starting with '-' then
// stops it advancing. The files read here hold one document, so anything
// after a '...' line, a second '---', or content on the '---' line is refused
// before OpenCV sees the file. XML ('<') and JSON ('{') files are not YAML.
void CheckSingleYamlDocument(const fs::path& path, const std::string& what) {
  const std::string text = ReadTextFile(path);
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos || text[first] == '<' || text[first] == '{') return;
  bool content = false, ended = false;
  int line_number = 0;
  for (size_t start = 0; start < text.size(); ++line_number) {
    const size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view line(text.data() + start, end - start);
    start = end + 1;
    const auto refuse = [&](const char* why) {
      ThrowError(fmt::format("{}:{}: {} ({}): only one YAML document is read", path.string(),
                             line_number + 1, why, what));
    };
    if (BlankOrComment(line)) continue;
    if (ended) refuse("content after the document's end '...'");
    if (line.substr(0, 3) == "...") {
      ended = true;
    } else if (line.substr(0, 3) == "---") {
      if (content) refuse("a second document '---'");
      if (!BlankOrComment(line.substr(3))) refuse("content on the '---' line");
      content = true;
    } else if (line[0] != '%') {
      content = true;
    }
  }
}

// A byte no text file of these holds: a control character (but tab and
// carriage return), DEL, or a byte never found in UTF-8.
bool ForeignByte(unsigned char c) {
  return (c < 0x20 && c != '\t' && c != '\r') || c == 0x7f || c == 0xc0 || c == 0xc1 || c >= 0xf5;
}

// Whether `content` (a line without its indentation, outside a flow
// sequence) is "- item" or "key: value" with a plain key.
bool ItemOrKeyLine(std::string_view content) {
  if (content == "-" || content.substr(0, 2) == "- ") return true;
  const size_t colon = content.find(':');
  if (colon == 0 || colon == std::string_view::npos) return false;
  for (size_t i = 0; i < colon; ++i) {
    const char c = content[i];
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.')
      return false;
  }
  return colon + 1 == content.size() || content[colon + 1] == ' ';
}

// OpenCV's YAML parser (4.6) loops forever on more malformed input than the
// multi-document kind: a line indented less than the block it closes but
// more than the block around it ("  dt: d" then " abc-x"), a bare word on a
// line of its own, stray bytes, a document whose first line is indented and
// a later one is not (" a: 1" then "- x"). The files read here are what
// cv::FileStorage and the tools like it write, so only that subset of YAML
// reaches the parser: text without foreign bytes; each line "key: value"
// with a plain key, "- item", or the continuation of a [ ] sequence opened
// above; the first of them not indented; each line indented deeper than
// the open block or exactly as one of the enclosing blocks.
void CheckYamlLines(const fs::path& path, const std::string& what) {
  const std::string text = ReadTextFile(path);
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos || text[first] == '<' || text[first] == '{') return;
  std::vector<size_t> open = {0};  // indentation of the enclosing blocks
  int depth = 0;                   // open '[' and '{' of a flow sequence
  bool first_block = true;         // no "key: value" or "- item" line yet
  int line_number = 0;
  for (size_t start = 0; start < text.size(); ++line_number) {
    const size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view line(text.data() + start, end - start);
    start = end + 1;
    const auto refuse = [&](const std::string& why) {
      ThrowError(fmt::format("{}:{}: {} ({}): only the YAML that cv::FileStorage writes is read",
                             path.string(), line_number + 1, why, what));
    };
    for (const char c : line)
      if (ForeignByte(static_cast<unsigned char>(c))) refuse("a control or non-text byte");
    if (BlankOrComment(line) || line[0] == '%' || line.substr(0, 3) == "---" ||
        line.substr(0, 3) == "...")
      continue;
    const size_t indent = line.find_first_not_of(' ');
    if (depth == 0) {
      if (!ItemOrKeyLine(line.substr(indent)))
        refuse("neither 'key: value' nor '- item' nor inside a [ ] sequence");
      if (first_block && indent > 0) refuse("the document's first line is indented");
      first_block = false;
      bool closed = false;
      while (open.size() > 1 && indent < open.back()) {
        open.pop_back();
        closed = true;
      }
      if (indent > open.back()) {
        if (closed)
          refuse(
              "indented as no enclosing block: a line that ends a block must line up "
              "with an outer one");
        open.push_back(indent);
      }
    }
    bool quoted = false;
    for (const char c : line) {
      if (c == '"') quoted = !quoted;
      if (quoted) continue;
      if (c == '#') break;
      if (c == '[' || c == '{') ++depth;
      if ((c == ']' || c == '}') && --depth < 0) refuse("a ']' or '}' that closes nothing");
    }
  }
  if (depth != 0)
    ThrowError(fmt::format(
        "{}: a [ ] sequence is not closed ({}): only the YAML that cv::FileStorage writes is read",
        path.string(), what));
}

}  // namespace

cv::FileStorage OpenFileStorage(const fs::path& path, const std::string& what) {
  CheckFileExists(path, what);
  CheckSingleYamlDocument(path, what);
  CheckYamlLines(path, what);
  cv::FileStorage storage;
  try {
    storage.open(path.string(), cv::FileStorage::READ);
  } catch (const std::exception& e) {
    // cv::Exception, and std::length_error from OpenCV's parser on some input.
    ThrowError(fmt::format("{}: cannot parse as an OpenCV FileStorage {} ({})", path.string(), what,
                           e.what()));
  }
  U4D_CHECK(storage.isOpened(), "{}: cannot open as an OpenCV FileStorage {}", path.string(), what);
  return storage;
}

bool HasKey(const cv::FileNode& map, const std::string& key) {
  if (!map.isMap()) return false;
  const cv::FileNode node = map[key];
  return !node.empty() && !node.isNone();
}

std::string FirstKey(const cv::FileNode& map, const std::vector<std::string>& keys) {
  for (const std::string& key : keys)
    if (HasKey(map, key)) return key;
  return "";
}

std::vector<double> ReadNumbers(const cv::FileNode& map, const std::string& key,
                                const std::vector<int>& counts, const std::string& context) {
  U4D_CHECK(HasKey(map, key), "{}: missing key '{}'", context, key);
  const cv::FileNode node = map[key];
  std::vector<double> out;
  if (IsMatrix(node)) {
    // OpenCV allocates rows x cols before it reads the data: a huge or
    // garbled "rows" must be an error, not a huge allocation.
    const cv::FileNode rows = node["rows"], cols = node["cols"], data = node["data"];
    U4D_CHECK(rows.isInt() && cols.isInt() && data.isSeq() && int(rows) >= 1 && int(cols) >= 1 &&
                  int64_t(int(rows)) * int(cols) <= int64_t(data.size()),
              "{}: '{}' must be a matrix (rows, cols and as many data values)", context, key);
    cv::Mat m;
    try {
      node >> m;
    } catch (const std::exception& e) {
      ThrowError(fmt::format("{}: '{}' is not a readable matrix ({})", context, key, e.what()));
    }
    U4D_CHECK(!m.empty(), "{}: '{}' is an empty matrix", context, key);
    cv::Mat d;
    m.reshape(1, 1).convertTo(d, CV_64F);
    out.assign(d.ptr<double>(), d.ptr<double>() + d.total());
  } else {
    U4D_CHECK(AppendSequence(node, &out) && !out.empty(),
              "{}: '{}' must be a matrix or numbers, found another kind of value", context, key);
  }
  const int n = static_cast<int>(out.size());
  U4D_CHECK(counts.empty() || std::find(counts.begin(), counts.end(), n) != counts.end(),
            "{}: '{}' must have {} values, found {}", context, key, CountsText(counts), n);
  for (const double v : out)
    U4D_CHECK(std::isfinite(v), "{}: '{}' has a non-finite value", context, key);
  return out;
}

int ReadInt(const cv::FileNode& map, const std::string& key, const std::string& context) {
  const double v = ReadNumbers(map, key, {1}, context)[0];
  U4D_CHECK(v == std::floor(v) && std::abs(v) < 1e9, "{}: '{}' must be a whole number, found {}",
            context, key, v);
  return static_cast<int>(v);
}

}  // namespace u4d
