// Texture references as stored by the bake: RFC 3986 relative URIs against the source's folder.
#pragma once
#include <filesystem>
#include <string>

namespace lod {

// Percent-decoding (RFC 3986 2.1): "%20" -> ' '; malformed escapes are kept as written.
std::string decode_uri(const std::string& uri);

// A relative file path as a URI: '/' separated, everything but unreserved characters and '/'
// percent-encoded (OBJ's map_Kd names files, glTF's uri is a URI).
std::string path_to_uri(const std::string& path);

// The file a texture URI names against `base` (a folder), or empty for data URIs, URLs
// ("scheme://"), images embedded in the chain ("embedded:<k>") or an empty URI. Nothing is checked on disk.
std::filesystem::path texture_file(const std::string& base, const std::string& uri);

}  // namespace lod
