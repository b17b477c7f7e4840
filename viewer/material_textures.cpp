#include "viewer/material_textures.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <utility>

#include <stb_image.h>  // Debian's libstb.so holds the implementation

#include "preprocess/texture_uri.h"

namespace lod::viewer {

namespace {

// Checks the size stb_image read from a header before anything is decoded.
bool fits(int width, int height, std::string& why) {
  if (width > 0 && height > 0 && width <= kMaxTextureSide && height <= kMaxTextureSide) return true;
  why = std::to_string(width) + " x " + std::to_string(height) + " pixels, more than " + std::to_string(kMaxTextureSide) +
        " on a side";
  return false;
}

std::vector<unsigned char> take_pixels(unsigned char* pixels, int width, int height, std::string& why) {
  if (!pixels) {
    why = stbi_failure_reason() ? stbi_failure_reason() : "decoding failed";
    return {};
  }
  std::vector<unsigned char> out(pixels, pixels + size_t(width) * size_t(height) * 4);
  stbi_image_free(pixels);
  return out;
}

// RGBA8 pixels of `file`, or empty with the reason in `why`; the size is checked from the
// header before anything is decoded.
std::vector<unsigned char> decode_image(const std::string& file, int& width, int& height, std::string& why) {
  int channels = 0;
  if (!stbi_info(file.c_str(), &width, &height, &channels)) {
    why = stbi_failure_reason() ? stbi_failure_reason() : "not an image stb_image reads";
    return {};
  }
  if (!fits(width, height, why)) return {};
  return take_pixels(stbi_load(file.c_str(), &width, &height, &channels, 4), width, height, why);
}

// The same for an image the chain carries (PNG or JPEG bytes, at most kMaxEmbeddedImageBytes,
// so the length fits stb_image's int).
std::vector<unsigned char> decode_image(const EmbeddedImage& image, int& width, int& height, std::string& why) {
  int channels = 0;
  const int size = int(image.bytes.size());
  if (!stbi_info_from_memory(image.bytes.data(), size, &width, &height, &channels)) {
    why = stbi_failure_reason() ? stbi_failure_reason() : "not an image stb_image reads";
    return {};
  }
  if (!fits(width, height, why)) return {};
  return take_pixels(stbi_load_from_memory(image.bytes.data(), size, &width, &height, &channels, 4), width, height, why);
}

// A mipmapped, repeating RGBA8 texture. The image's rows go up as stored: glTF's uv origin is
// the image's top left, which is where GL's t = 0 row (the first uploaded) sits.
// `srgb`: colour images, decoded to linear by the GL when sampled (and when mipmapped).
GLuint make_texture(const std::vector<unsigned char>& rgba, int width, int height, bool srgb) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  glBindTexture(GL_TEXTURE_2D, 0);
  return t;
}

}  // namespace

MaterialTextures::~MaterialTextures() {
  if (!textures_.empty()) glDeleteTextures(GLsizei(textures_.size()), textures_.data());
}

void MaterialTextures::upload(std::span<const LodChain> chains) {
  // Decoded once per (file, colour space); 0 = could not be read. A file that cannot be read is
  // said once, whatever the slots naming it.
  std::map<std::pair<std::string, bool>, GLuint> by_file;
  std::map<std::string, bool> unreadable;
  std::map<std::pair<const EmbeddedImage*, bool>, GLuint> by_image;
  for (const LodChain& chain : chains) {
    // An image the chain carries, decoded from memory at its first use; 0 when it cannot be.
    auto embedded_texture = [&](const ChainMaterial& m, const std::string& uri, const EmbeddedImage& image,
                                bool srgb) -> GLuint {
      if (auto it = by_image.find({&image, srgb}); it != by_image.end()) return it->second;
      int w = 0, h = 0;
      std::string why;
      const std::vector<unsigned char> rgba = decode_image(image, w, h, why);
      GLuint t = 0;
      if (rgba.empty()) {
        std::fprintf(stderr, "lod-viewer: %s: material '%s' texture %s (%zu bytes in the asset): %s; drawn without it\n",
                     chain.name.c_str(), m.name.c_str(), uri.c_str(), image.bytes.size(), why.c_str());
      } else {
        t = make_texture(rgba, w, h, srgb);
        textures_.push_back(t);
        bytes_ += rgba.size() * 4 / 3;  // with its mipmaps
      }
      by_image[{&image, srgb}] = t;
      if (!t) by_image[{&image, !srgb}] = 0;  // an image that cannot be decoded is said once
      return t;
    };
    // The texture a URI names, decoded at its first use; 0 when it cannot be read (said once).
    auto texture_of = [&](const ChainMaterial& m, const std::string& uri, bool srgb) -> GLuint {
      if (uri.empty()) return 0;
      if (uint32_t k = 0; is_embedded_image_uri(uri, &k))
        return k < chain.images.size() ? embedded_texture(m, uri, chain.images[k], srgb) : 0;  // validate_chain checked k
      const std::string file = texture_file(chain.texture_base, uri).string();
      if (file.empty()) {
        std::fprintf(stderr, "lod-viewer: %s: material '%s' texture '%s' is not a file (data URI or URL); drawn without it\n",
                     chain.name.c_str(), m.name.c_str(), uri.c_str());
        return 0;
      }
      if (auto it = by_file.find({file, srgb}); it != by_file.end()) return it->second;
      if (unreadable.count(file)) return 0;
      int w = 0, h = 0;
      std::string why;
      const std::vector<unsigned char> rgba = decode_image(file, w, h, why);
      GLuint t = 0;
      if (rgba.empty()) {
        std::fprintf(stderr, "lod-viewer: texture %s: %s; drawn without it\n", file.c_str(), why.c_str());
        unreadable[file] = true;
      } else {
        t = make_texture(rgba, w, h, srgb);
        textures_.push_back(t);
        bytes_ += rgba.size() * 4 / 3;  // with its mipmaps
      }
      by_file[{file, srgb}] = t;
      return t;
    };
    for (const ChainMaterial& m : chain.materials) {
      GpuMaterial g;
      std::copy(m.base_color, m.base_color + 4, g.base_color);
      g.alpha_mode = m.alpha_mode;
      g.alpha_cutoff = m.alpha_cutoff;
      g.double_sided = m.double_sided;
      g.texture = texture_of(m, m.base_color_texture, true);
      g.normal_texture = texture_of(m, m.normal_texture, false);
      g.normal_scale = m.normal_scale;
      g.metallic = m.metallic;
      g.roughness = m.roughness;
      g.metallic_roughness_texture = texture_of(m, m.metallic_roughness_texture, false);
      g.occlusion_texture = texture_of(m, m.occlusion_texture, false);
      g.occlusion_strength = m.occlusion_strength;
      g.emissive_texture = texture_of(m, m.emissive_texture, true);
      std::copy(m.emissive, m.emissive + 3, g.emissive);
      materials_.push_back(g);
    }
  }
}

}  // namespace lod::viewer
