// Texture URIs: percent-encoding both ways and resolution against the source's folder.
#include "runtime/texture_uri.h"

#include <cctype>

#include "runtime/embedded_image.h"

namespace lod {

std::string decode_uri(const std::string& uri) {
  auto hex = [](char c) { return std::isdigit(uint8_t(c)) ? c - '0' : std::tolower(uint8_t(c)) - 'a' + 10; };
  std::string s;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(uint8_t(uri[i + 1])) && std::isxdigit(uint8_t(uri[i + 2]))) {
      s += char(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
      i += 2;
    } else {
      s += uri[i];
    }
  }
  return s;
}

std::string path_to_uri(const std::string& path) {
  static const char* hex = "0123456789ABCDEF";
  std::string s;
  for (unsigned char c : path) {
    if (c == '\\') c = '/';  // OBJ files written on Windows
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/') {
      s += char(c);
    } else {
      s += '%';
      s += hex[c >> 4];
      s += hex[c & 15];
    }
  }
  return s;
}

std::filesystem::path texture_file(const std::string& base, const std::string& uri) {
  if (uri.empty() || uri.rfind("data:", 0) == 0 || uri.find("://") != std::string::npos || is_embedded_image_uri(uri))
    return {};
  return std::filesystem::path(base) / decode_uri(uri);
}

}  // namespace lod
