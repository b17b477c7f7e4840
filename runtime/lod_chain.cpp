// LodChain facts: Yu, Liang and Chen's level l = round(log2(triangles)) and the structural checks every
// chain passes before the runtime trusts it (asset decode, bake output).
#include "runtime/lod_chain.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "runtime/model_table.h"

namespace lod {

int32_t level_of_triangles(uint64_t triangles) {
  if (triangles == 0) return 0;
  // log2 of an integer is never exactly k + 0.5, so rounding has no ties to break.
  return static_cast<int32_t>(std::lround(std::log2(static_cast<double>(triangles))));
}

namespace {

bool fail(std::string* message, std::string text) {
  if (message) *message = std::move(text);
  return false;
}

// Finite and far from float's limits (bounds are scaled, summed and squared downstream).
bool finite_sane(float x) { return std::isfinite(x) && std::abs(x) <= kMaxTreeMagnitude; }

bool all_finite(const std::vector<float>& values, size_t* bad) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!finite_sane(values[i])) {
      *bad = i;
      return false;
    }
  }
  return true;
}

// Names and URIs: bounded, no control bytes (they end up in files, JSON and terminals).
bool printable_string(const std::string& s) {
  if (s.size() > kMaxMaterialString) return false;
  for (unsigned char c : s)
    if (c < 0x20 || c == 0x7f) return false;
  return true;
}

bool unit_factor(float x) { return std::isfinite(x) && x >= 0 && x <= 1; }

bool validate_images(const LodChain& chain, std::string* message) {
  if (chain.images.size() > kMaxEmbeddedImages)
    return fail(message, std::to_string(chain.images.size()) + " embedded images, at most " + std::to_string(kMaxEmbeddedImages));
  uint64_t total = 0;
  for (size_t k = 0; k < chain.images.size(); ++k) {
    const EmbeddedImage& img = chain.images[k];
    const std::string at = "embedded image " + std::to_string(k);
    if (img.bytes.size() > kMaxEmbeddedImageBytes)
      return fail(message, at + " is " + std::to_string(img.bytes.size()) + " bytes, at most " +
                               std::to_string(kMaxEmbeddedImageBytes));
    total += img.bytes.size();
    if (img.type == ImageType::unknown || image_type_of(img.bytes) != img.type)
      return fail(message, at + " is not the PNG or JPEG its type says (signature checked)");
  }
  if (total > kMaxEmbeddedBytes)
    return fail(message, "embedded images take " + std::to_string(total) + " bytes, at most " + std::to_string(kMaxEmbeddedBytes));
  return true;
}

bool validate_materials(const LodChain& chain, std::string* message) {
  if (chain.materials.empty() && chain.submeshes.empty()) return true;
  if (chain.materials.size() > kMaxMaterials)
    return fail(message, std::to_string(chain.materials.size()) + " materials, at most " +
                             std::to_string(kMaxMaterials) + " are supported");
  if (!printable_string(chain.texture_base)) return fail(message, "texture base folder is too long or has control bytes");
  for (size_t i = 0; i < chain.materials.size(); ++i) {
    const ChainMaterial& m = chain.materials[i];
    const std::string at = "material " + std::to_string(i);
    if (!printable_string(m.name)) return fail(message, at + " name is too long or has control bytes");
    const auto uris = texture_slots(m);
    for (size_t k = 0; k < kTextureSlots; ++k)
      if (!printable_string(*uris[k]))
        return fail(message, at + " " + kTextureSlotNames[k] + " texture URI is too long or has control bytes");
    for (size_t k = 0; k < kTextureSlots; ++k)
      if (uint32_t image = 0; is_embedded_image_uri(*uris[k], &image) && image >= chain.images.size())
        return fail(message, at + " " + kTextureSlotNames[k] + " texture names embedded image '" + *uris[k] + "' of " +
                                 std::to_string(chain.images.size()));
    for (size_t k = 0; k < kTextureSlots; ++k)
      if (m.tex_coords[k] > kMaxTexCoord)
        return fail(message, at + " " + kTextureSlotNames[k] + " texture reads TEXCOORD_" +
                                 std::to_string(m.tex_coords[k]) + " (only 0 and 1 are kept)");
    if (!(std::isfinite(m.normal_scale) && m.normal_scale >= 0 && m.normal_scale <= 1e6f))
      return fail(message, at + " has a normal texture scale outside [0, 1e6]");
    if (!unit_factor(m.occlusion_strength)) return fail(message, at + " has an occlusion strength outside [0, 1]");
    for (float c : m.emissive)
      if (!unit_factor(c)) return fail(message, at + " has an emissive factor outside [0, 1]");
    for (float c : m.base_color)
      if (!unit_factor(c)) return fail(message, at + " has a base colour factor outside [0, 1]");
    if (!unit_factor(m.metallic) || !unit_factor(m.roughness))
      return fail(message, at + " has a metallic or roughness factor outside [0, 1]");
    if (uint8_t(m.alpha_mode) > uint8_t(AlphaMode::blend))
      return fail(message, at + " has unknown alpha mode " + std::to_string(unsigned(m.alpha_mode)));
    if (!(std::isfinite(m.alpha_cutoff) && m.alpha_cutoff >= 0 && m.alpha_cutoff <= 1e6f))
      return fail(message, at + " has an invalid alpha cutoff");
  }
  // Runs in level order, each level's covering its indices back to back.
  const size_t drawn = drawn_levels(chain);
  size_t r = 0;
  for (size_t k = 0; k < chain.levels.size(); ++k) {
    const LodLevel& lv = chain.levels[k];
    uint64_t covered = 0;
    for (; r < chain.submeshes.size() && chain.submeshes[r].level == k; ++r) {
      const LevelSubmesh& s = chain.submeshes[r];
      const std::string at = "submesh " + std::to_string(r) + " (level " + std::to_string(k) + ")";
      if (k >= drawn) return fail(message, at + " belongs to the culled level");
      if (s.first_index != covered)
        return fail(message, at + " starts at index " + std::to_string(s.first_index) + ", the runs before end at " +
                                 std::to_string(covered));
      if (s.index_count == 0 || s.index_count % 3 != 0)
        return fail(message, at + " has " + std::to_string(s.index_count) + " indices, not a positive multiple of 3");
      covered += s.index_count;
      if (covered > lv.index_count)
        return fail(message, at + " ends at index " + std::to_string(covered) + " past the level's " +
                                 std::to_string(lv.index_count));
      if (s.material < -1 || (s.material >= 0 && size_t(s.material) >= chain.materials.size()))
        return fail(message, at + " names material " + std::to_string(s.material) + " of " +
                                 std::to_string(chain.materials.size()));
    }
    if (k < drawn && covered != lv.index_count)
      return fail(message, "level " + std::to_string(k) + "'s material runs cover " + std::to_string(covered) +
                               " of its " + std::to_string(lv.index_count) + " indices");
  }
  if (r != chain.submeshes.size())
    return fail(message, "submesh " + std::to_string(r) + " names level " + std::to_string(chain.submeshes[r].level) +
                             " out of order or of " + std::to_string(chain.levels.size()));
  return true;
}

}  // namespace

bool validate_chain(const LodChain& chain, std::string* message, const char** section) {
  // Which asset section the failing element lives in (for the asset reader's message).
  auto in = [&](const char* tag) {
    if (section) *section = tag;
  };
  in("LEVL");
  if (chain.levels.empty()) return fail(message, "chain has no levels");
  if (chain.levels.size() > kMaxLevels)
    return fail(message, "chain has " + std::to_string(chain.levels.size()) + " levels, at most " +
                             std::to_string(kMaxLevels) + " are supported");
  in("POSN");
  if (chain.positions.size() % 3 != 0)
    return fail(message, "positions hold " + std::to_string(chain.positions.size()) +
                             " floats, not a multiple of 3");
  in("NRML");
  if (!chain.normals.empty() && chain.normals.size() != chain.positions.size())
    return fail(message, "normals hold " + std::to_string(chain.normals.size()) + " floats but positions " +
                             std::to_string(chain.positions.size()));
  size_t bad = 0;
  in("POSN");
  if (!all_finite(chain.positions, &bad))
    return fail(message, "vertex " + std::to_string(bad / 3) + " has a " +
                             (std::isfinite(chain.positions[bad]) ? "huge (beyond 1e18)" : "non-finite") + " position");
  in("NRML");
  if (!all_finite(chain.normals, &bad))
    return fail(message, "vertex " + std::to_string(bad / 3) + " has a " +
                             (std::isfinite(chain.normals[bad]) ? "huge (beyond 1e18)" : "non-finite") + " normal");
  // Per-vertex attribute columns: `per` floats a vertex, one error per level.
  auto check_column = [&](const char* tag, const char* name, const std::vector<float>& values,
                          const std::vector<float>& errors, size_t per) {
    in(tag);
    if (values.empty() && errors.empty()) return true;
    if (values.size() != chain.positions.size() / 3 * per)
      return fail(message, std::string(name) + "s hold " + std::to_string(values.size()) + " floats for " +
                               std::to_string(chain.positions.size() / 3) + " vertices (" + std::to_string(per) + " each)");
    if (errors.size() != chain.levels.size())
      return fail(message, std::to_string(errors.size()) + " " + name + " errors for " +
                               std::to_string(chain.levels.size()) + " levels");
    if (!all_finite(values, &bad))
      return fail(message, "vertex " + std::to_string(bad / per) + " has a huge or non-finite " + name);
    for (size_t k = 0; k < errors.size(); ++k)
      if (!(errors[k] >= 0 && errors[k] < 1e18f))
        return fail(message, "level " + std::to_string(k) + " has an invalid " + name + " error");
    return true;
  };
  if (!check_column("TEX0", "uv", chain.uvs, chain.uv_errors, 2)) return false;
  if (!check_column("TEX1", "uv1", chain.uvs1, chain.uv1_errors, 2)) return false;
  if (!check_column("COL0", "colour", chain.colors, chain.color_errors, 4)) return false;
  in("LEVL");

  const uint64_t vertex_total = chain.positions.size() / 3;
  const uint64_t index_total = chain.indices.size();
  for (size_t k = 0; k < chain.levels.size(); ++k) {
    const LodLevel& lv = chain.levels[k];
    const std::string at = "level " + std::to_string(k);
    if (lv.index_count % 3 != 0)
      return fail(message, at + " has " + std::to_string(lv.index_count) + " indices, not a multiple of 3");
    if (uint64_t{lv.first_index} + lv.index_count > index_total)
      return fail(message, at + " indices [" + std::to_string(lv.first_index) + ", " +
                               std::to_string(uint64_t{lv.first_index} + lv.index_count) +
                               ") exceed the " + std::to_string(index_total) + " stored");
    if (uint64_t{lv.first_vertex} + lv.vertex_count > vertex_total)
      return fail(message, at + " vertices [" + std::to_string(lv.first_vertex) + ", " +
                               std::to_string(uint64_t{lv.first_vertex} + lv.vertex_count) +
                               ") exceed the " + std::to_string(vertex_total) + " stored");
    const uint32_t* idx = chain.indices.data() + lv.first_index;
    for (uint32_t i = 0; i < lv.index_count; ++i) {
      if (idx[i] >= lv.vertex_count) {
        in("INDX");
        return fail(message, at + " index " + std::to_string(i) + " references vertex " +
                                 std::to_string(idx[i]) + " of " + std::to_string(lv.vertex_count));
      }
    }
    if (lv.level != level_of_triangles(lv.triangles()))
      return fail(message, at + " says l = " + std::to_string(lv.level) + " but its " +
                               std::to_string(lv.triangles()) + " triangles give l = " +
                               std::to_string(level_of_triangles(lv.triangles())));
    if (!finite_sane(lv.error) || lv.error < 0 || !finite_sane(lv.error_rms) || lv.error_rms < 0)
      return fail(message, at + " has an invalid error (" + std::to_string(lv.error) + ", rms " +
                               std::to_string(lv.error_rms) + ")");
    const Sphere& s = lv.bounds;
    if (!finite_sane(s.center[0]) || !finite_sane(s.center[1]) || !finite_sane(s.center[2]) ||
        !finite_sane(s.radius) || s.radius < 0)
      return fail(message, at + " has an invalid bounding sphere");
    // The culled level (a last ratio of 0): empty, and only as the last of two or more.
    if (lv.index_count == 0 && (k == 0 || k + 1 != chain.levels.size()))
      return fail(message, at + " has no triangles; only a last level after level 0 may be empty (the culled level)");
    if (lv.index_count == 0 && lv.vertex_count != 0)
      return fail(message, at + " is the culled level (no triangles) but has " + std::to_string(lv.vertex_count) +
                               " vertices");
    if (k > 0) {
      const LodLevel& finer = chain.levels[k - 1];
      if (lv.triangles() > finer.triangles())
        return fail(message, at + " has " + std::to_string(lv.triangles()) + " triangles, more than level " +
                                 std::to_string(k - 1) + "'s " + std::to_string(finer.triangles()));
      if (lv.error < finer.error)
        return fail(message, at + " error " + std::to_string(lv.error) + " is below level " +
                                 std::to_string(k - 1) + "'s " + std::to_string(finer.error));
    }
  }
  in("MRPH");
  if (!chain.morph_targets.empty()) {
    const uint64_t want = morph_target_count(chain);
    if (chain.morph_targets.size() != want)
      return fail(message, "morph targets hold " + std::to_string(chain.morph_targets.size()) +
                               " entries, the levels but the last have " + std::to_string(want) + " vertices");
    for (size_t k = 0; k + 1 < drawn_levels(chain); ++k) {
      const LodLevel& lv = chain.levels[k];
      const uint32_t next = chain.levels[k + 1].vertex_count;
      // Ranges were checked above; targets of level k start where its vertices do.
      const uint32_t* t = chain.morph_targets.data() + lv.first_vertex;
      for (uint32_t v = 0; v < lv.vertex_count; ++v)
        if (t[v] >= next)
          return fail(message, "level " + std::to_string(k) + " vertex " + std::to_string(v) +
                                   " morphs into vertex " + std::to_string(t[v]) + " of level " +
                                   std::to_string(k + 1) + "'s " + std::to_string(next));
    }
  }
  in("IMGS");
  if (!validate_images(chain, message)) return false;
  in("MATL");
  if (!validate_materials(chain, message)) return false;
  return true;
}

bool validate_chain_materials(const LodChain& chain, std::string* message) { return validate_materials(chain, message); }

bool validate_chain_images(const LodChain& chain, std::string* message) { return validate_images(chain, message); }

std::span<const LevelSubmesh> level_submeshes(const LodChain& chain, uint32_t level) {
  const auto by_level = [](const LevelSubmesh& s, uint32_t k) { return s.level < k; };
  const auto lo = std::lower_bound(chain.submeshes.begin(), chain.submeshes.end(), level, by_level);
  const auto hi = std::lower_bound(lo, chain.submeshes.end(), level + 1, by_level);
  return {chain.submeshes.data() + (lo - chain.submeshes.begin()), size_t(hi - lo)};
}

bool has_culled_level(const LodChain& chain) {
  return chain.levels.size() > 1 && chain.levels.back().index_count == 0;
}

size_t drawn_levels(const LodChain& chain) { return chain.levels.size() - (has_culled_level(chain) ? 1 : 0); }

uint64_t morph_target_count(const LodChain& chain) {
  uint64_t end = 0;
  for (size_t k = 0; k + 1 < drawn_levels(chain); ++k)
    end = std::max(end, uint64_t{chain.levels[k].first_vertex} + chain.levels[k].vertex_count);
  return end;
}

bool can_morph_levels(const LodChain& chain) {
  return drawn_levels(chain) > 1 && chain.morph_targets.size() == morph_target_count(chain);
}

void compose_morph_targets(std::span<uint32_t> out, const LodChain& chain, uint32_t fine, uint32_t coarse) {
  assert(fine <= coarse && coarse < drawn_levels(chain));
  assert(out.size() == chain.levels[fine].vertex_count);
  assert(fine == coarse || chain.morph_targets.size() == morph_target_count(chain));
  for (uint32_t v = 0; v < out.size(); ++v) {
    uint32_t at = v;
    for (uint32_t k = fine; k < coarse; ++k) at = chain.morph_targets[chain.levels[k].first_vertex + at];
    out[v] = at;
  }
}

}  // namespace lod
