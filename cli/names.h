// Names from assets and the command line are data: never printed raw to a terminal, never
// used as paths as they are.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>

namespace lod::cli {

// `text` safe for a terminal: valid UTF-8 is kept but for control characters (C0, DEL, C1),
// which become \n, \t, \r, \e or \xNN escapes, as does every byte of an invalid sequence; a
// backslash is doubled so escapes cannot be faked.
inline std::string printable(std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  auto hex = [&](uint8_t b) {
    out += "\\x";
    out += kHex[b >> 4];
    out += kHex[b & 15];
  };
  const auto* p = reinterpret_cast<const uint8_t*>(text.data());
  const size_t n = text.size();
  for (size_t i = 0; i < n;) {
    const uint8_t b = p[i];
    if (b < 0x80) {
      if (b == '\\') out += "\\\\";
      else if (b == '\n') out += "\\n";
      else if (b == '\t') out += "\\t";
      else if (b == '\r') out += "\\r";
      else if (b == 0x1b) out += "\\e";
      else if (b < 0x20 || b == 0x7f) hex(b);
      else out += static_cast<char>(b);
      ++i;
      continue;
    }
    // A well-formed UTF-8 sequence (no overlongs, surrogates or values past U+10FFFF).
    size_t len = 0;
    uint32_t cp = 0, min = 0;
    if (b >= 0xc2 && b <= 0xdf) len = 2, cp = b & 0x1f, min = 0x80;
    else if (b >= 0xe0 && b <= 0xef) len = 3, cp = b & 0x0f, min = 0x800;
    else if (b >= 0xf0 && b <= 0xf4) len = 4, cp = b & 0x07, min = 0x10000;
    bool ok = len > 0 && i + len <= n;
    for (size_t k = 1; ok && k < len; ++k) {
      if ((p[i + k] & 0xc0) != 0x80) ok = false;
      else cp = cp << 6 | (p[i + k] & 0x3f);
    }
    ok = ok && cp >= min && cp <= 0x10ffff && !(cp >= 0xd800 && cp <= 0xdfff);
    if (!ok) {
      hex(b);
      ++i;
      continue;
    }
    if (cp >= 0x80 && cp <= 0x9f) {  // C1 controls (CSI and friends)
      for (size_t k = 0; k < len; ++k) hex(p[i + k]);
    } else {
      out.append(text.substr(i, len));
    }
    i += len;
  }
  return out;
}

// A file name stem made from a model name: A-Z a-z 0-9 _ - . kept, every other byte (path
// separators, NUL, controls, non-ASCII) becomes '_', no leading dot (so never "." or "..",
// nor hidden), at most 64 characters; "model" when nothing is left. Never a path.
inline std::string export_stem(std::string_view name) {
  std::string out;
  for (char c : name) {
    if (out.size() == 64) break;
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                      c == '-' || c == '.';
    out += keep ? c : '_';
  }
  while (!out.empty() && out.front() == '.') out.erase(out.begin());
  bool meaningful = false;
  for (char c : out) meaningful = meaningful || (c != '_' && c != '.' && c != '-');
  return meaningful ? out : "model";
}

}  // namespace lod::cli
