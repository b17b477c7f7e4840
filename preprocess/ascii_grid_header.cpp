#include "preprocess/ascii_grid_header.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <string_view>
#include <vector>

namespace lod {
namespace detail {

std::vector<std::string_view> grid_tokens(std::string_view s) {
  std::vector<std::string_view> out;
  constexpr std::string_view kSpace = " \t\r\n:";
  for (size_t at = s.find_first_not_of(kSpace); at != std::string_view::npos; at = s.find_first_not_of(kSpace, at)) {
    const size_t end = std::min(s.find_first_of(kSpace, at), s.size());
    out.push_back(s.substr(at, end - at));
    at = end;
  }
  return out;
}

bool same_word(std::string_view a, std::string_view b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return std::tolower(uint8_t(x)) == y; });
}

bool is_grid_keyword(std::string_view t) {
  static constexpr std::array<std::string_view, 15> kWords = {
      "ncols", "nrows", "xllcorner", "yllcorner", "xllcenter", "yllcenter", "cellsize", "dx",
      "dy",    "north", "south",     "east",      "west",      "rows",      "cols"};
  return std::any_of(kWords.begin(), kWords.end(), [&](std::string_view w) { return same_word(t, w); });
}

// The integer after the first token naming `a` or `b`, read as GDAL does (atoi: leading digits),
// saturating instead of overflowing; 0 when absent.
uint64_t declared_count(const std::vector<std::string_view>& tokens, std::string_view a, std::string_view b) {
  for (size_t i = 0; i + 1 < tokens.size(); ++i) {
    if (!same_word(tokens[i], a) && !same_word(tokens[i], b)) continue;
    std::string_view v = tokens[i + 1];
    if (!v.empty() && (v[0] == '+' || v[0] == '-')) {
      if (v[0] == '-') return 0;
      v.remove_prefix(1);
    }
    uint64_t n = 0;
    for (char c : v) {
      if (c < '0' || c > '9') break;
      n = std::min<uint64_t>(n * 10 + uint64_t(c - '0'), uint64_t(1) << 31);  // GDAL reads an int
    }
    return n;
  }
  return 0;
}

}  // namespace detail

Status check_ascii_grid_header(std::span<const uint8_t> head, uint64_t file_bytes, const std::string& name,
                               const HeightFieldOptions& o, uint64_t bytes_per_sample) {
  const std::string_view text(reinterpret_cast<const char*>(head.data()), std::min(head.size(), kAsciiGridHeadBytes));
  const std::vector<std::string_view> tokens = detail::grid_tokens(text);
  if (tokens.empty() || !detail::is_grid_keyword(tokens[0])) return Status::success();
  const uint64_t cols = detail::declared_count(tokens, "ncols", "cols");
  const uint64_t rows = detail::declared_count(tokens, "nrows", "rows");
  if (cols == 0 || rows == 0) return Status::success();  // GDAL refuses these itself
  if (Status st = check_height_field_size(name, cols, rows, o, bytes_per_sample); !st) return st;
  if (cols * rows > (file_bytes + 1) / 2)
    return Status::error(name + ": text grid declares " + std::to_string(cols) + " x " + std::to_string(rows) +
                         " samples, but the file has only " + std::to_string(file_bytes) +
                         " bytes (a sample takes at least 2)");
  return Status::success();
}

}  // namespace lod
