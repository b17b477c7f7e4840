// MaterialTextures: every chain's materials as the shader needs them, scene-wide in
// MeshLayout::first_material order; each image is decoded once per colour space (stb_image,
// from its file, or from memory for the images the asset carries: LodChain::images),
// however many materials name it, into one mipmapped GL texture: base colour and emissive
// images as sRGB (the GL decodes them to linear), metallic-roughness, normal and occlusion
// images as linear data, as glTF defines them.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "runtime/lod_chain.h"

namespace lod::viewer {

// Images wider or taller than this are refused (drawn without texture), so a hostile or huge
// file cannot ask for gigabytes of decoded pixels.
inline constexpr int kMaxTextureSide = 8192;

// Texture names are 0 when the material has none (or it could not be read): the factor alone.
struct GpuMaterial {
  float base_color[4] = {1, 1, 1, 1};
  GLuint texture = 0;  // base colour (sRGB)
  GLuint normal_texture = 0;  // 0 = none: the interpolated normal is used as is
  float normal_scale = 1;
  float metallic = 1, roughness = 1;
  GLuint metallic_roughness_texture = 0;  // G = roughness, B = metallic (linear)
  GLuint occlusion_texture = 0;           // R = ambient occlusion (linear)
  float occlusion_strength = 1;
  GLuint emissive_texture = 0;            // sRGB
  float emissive[3] = {0, 0, 0};
  AlphaMode alpha_mode = AlphaMode::opaque;
  float alpha_cutoff = 0.5f;
  bool double_sided = false;
};

class MaterialTextures {
 public:
  MaterialTextures() = default;
  ~MaterialTextures();
  MaterialTextures(const MaterialTextures&) = delete;
  MaterialTextures& operator=(const MaterialTextures&) = delete;

  // Reads every chain's images; an unreadable one is logged once on stderr
  // (naming the file and why) and its materials draw with their factor only.
  void upload(std::span<const LodChain> chains);

  const std::vector<GpuMaterial>& materials() const { return materials_; }
  size_t texture_count() const { return textures_.size(); }
  size_t bytes() const { return bytes_; }

 private:
  std::vector<GpuMaterial> materials_;
  std::vector<GLuint> textures_;
  size_t bytes_ = 0;
};

}  // namespace lod::viewer
