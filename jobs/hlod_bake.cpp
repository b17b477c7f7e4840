// HLOD bake job: load -> clean -> build (subtrees as tbb tasks in an arena of the requested
// size) -> write. Progress lines every 10 %.
#include "jobs/hlod_bake.h"

#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <vector>

#include "jobs/annotated_parallel_for.h"
#include "preprocess/gltf_io.h"  // gltf_external_files
#include "preprocess/material_runs.h"
#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "preprocess/mesh_readers.h"  // open_mesh_file
#include "runtime/regular_file.h"
#include "runtime/embedded_image.h"
#include "runtime/file_write.h"
#include "runtime/hlod_asset.h"
#include "runtime/lod_asset.h"  // hash_bytes

namespace lod {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The images a slot of `materials` still names, renumbered in order of first use (a texture that
// prepare_hlod_input left out may have been an image's only user; the .hlod keeps no unnamed image).
std::vector<EmbeddedImage> kept_embedded_images(std::vector<ChainMaterial>& materials, std::vector<EmbeddedImage> images) {
  std::vector<int64_t> renumbered(images.size(), -1);
  std::vector<EmbeddedImage> kept;
  for (ChainMaterial& c : materials)
    for (std::string* uri : texture_slots(c))
      if (uint32_t k = 0; is_embedded_image_uri(*uri, &k) && k < images.size()) {
        if (renumbered[k] < 0) renumbered[k] = int64_t(kept.size()), kept.push_back(std::move(images[k]));
        *uri = embedded_image_uri(uint32_t(renumbered[k]));
      }
  return kept;
}

}  // namespace

// Content hash of the mesh file's bytes, mixed with what else decides the output.
Status hlod_source_hash(const std::filesystem::path& file, uint32_t min_verts, uint64_t& out) {
  // The mesh readers' own checks first: a directory, FIFO or device is refused by name, and a
  // file whose head cannot be its format unread.
  {
    RegularFile f;
    uint64_t read_bytes = 0;
    if (Status s = detail::open_mesh_file(file, f, read_bytes); !s) return s;
  }
  uint64_t content = 0;
  if (Status s = hash_regular_file(file, content); !s) return s;
  out = hlod_source_hash_of(file, content, min_verts);
  return Status::success();
}

uint64_t hlod_source_hash_of(const std::filesystem::path& file, uint64_t content, uint32_t min_verts) {
  // The materials and uvs are in the tree since build version 2: what an OBJ's .mtl or a glTF's
  // buffers and images hold is part of the source. Version 3 keeps embedded images, so a tree
  // cached before (its embedded textures left out) is not taken for current; version 4 keeps
  // colours and TEXCOORD_1 (and the textures that read it).
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".gltf" || ext == ".glb" || ext == ".obj")
    for (const auto& named : ext == ".obj" ? obj_external_files(file) : gltf_external_files(file)) {
      // In 1 MB pieces (a glTF's .bin is the geometry, hundreds of MB on a scan); a missing,
      // empty or unreadable one adds nothing (the load says what is wrong with it).
      if (uint64_t more = 0; hash_regular_file(named, more, content)) content = more;
      else content = hash_bytes(nullptr, 0, content);
    }
  const uint64_t settings[2] = {kHlodBuildVersion, min_verts};
  return hash_bytes(settings, sizeof settings, content);
}

Status load_hlod_input(const std::filesystem::path& mesh_file, MeshData& mesh, HlodSurfaces& surfaces,
                       std::vector<std::string>& notes, size_t* input_triangles, uint64_t* content_hash) {
  MeshData m;
  uint64_t hash = 0;
  if (Status s = load_mesh_hashed(mesh_file, m, hash); !s) return s;
  if (content_hash) *content_hash = hash;
  if (input_triangles) *input_triangles = m.triangle_count();
  prepare_hlod_input(mesh_file, m, surfaces, notes);
  mesh = std::move(m);
  return Status::success();
}

void prepare_hlod_input(const std::filesystem::path& mesh_file, MeshData& m, HlodSurfaces& surfaces,
                        std::vector<std::string>& notes) {
  // Nothing dropped silently: the tree keeps TEXCOORD_0 and _1, COLOR_0 and the materials; the
  // file's own normals are recomputed (as the .lod bake's), and what a reader skipped it said.
  clean_mesh(m);
  LodChain chain;
  add_chain_materials(m, mesh_file, chain, notes);
  for (size_t i = 0; i < chain.materials.size(); ++i) {
    ChainMaterial& c = chain.materials[i];
    const auto uris = texture_slots(c);
    for (size_t k = 0; k < kTextureSlots; ++k)
      if (const std::vector<float>& set = c.tex_coords[k] == 0 ? m.uvs : m.uvs1;
          !uris[k]->empty() && (c.tex_coords[k] > 1 || set.empty())) {
        notes.push_back(mesh_file.string() + ": material " + std::to_string(i) + " ('" + c.name + "'): its " +
                        kTextureSlotNames[k] + " texture reads TEXCOORD_" + std::to_string(c.tex_coords[k]) +
                        ", which the mesh does not have (left out)");
        uris[k]->clear();
        c.tex_coords[k] = 0;
      }
  }
  surfaces.images = kept_embedded_images(chain.materials, std::move(chain.images));
  surfaces.materials = std::move(chain.materials);
  surfaces.texture_base = surfaces.materials.empty() ? std::string() : std::move(chain.texture_base);
}

ParallelFor tbb_parallel_for() {
  return [](size_t count, const std::function<void(size_t)>& body) { detail::annotated_parallel_for(count, body); };
}

Status bake_hlod_file(const std::filesystem::path& mesh_file, const std::string& name,
                      const std::filesystem::path& out_dir, const HlodBakeSettings& settings, const HlodBakeLog& log,
                      HlodBakeResult* result) {
  HlodBakeResult r;
  auto t0 = std::chrono::steady_clock::now();
  MeshData mesh;
  HlodBuildOptions options;
  std::vector<std::string> notes;
  uint64_t content = 0;  // of the bytes parsed: the file is read once
  if (Status s = load_hlod_input(mesh_file, mesh, options.surfaces, notes, &r.input_triangles, &content); !s) return s;
  if (log)
    for (const std::string& note : notes) log("hlod " + name + ": note: " + note);
  HlodModel model;
  model.tree.source_hash = hlod_source_hash_of(mesh_file, content, settings.min_verts);
  const uint64_t hash = model.tree.source_hash;
  r.load_seconds = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  std::mutex log_mutex;
  std::atomic<int> last_decile{0};
  options.min_verts = settings.min_verts;
  options.parallel_for = tbb_parallel_for();
  options.progress = [&](float fraction) {
    const int decile = int(std::clamp(fraction, 0.f, 1.f) * 10);
    int seen = last_decile.load();
    do {
      if (decile <= seen) return;
    } while (!last_decile.compare_exchange_weak(seen, decile));
    if (!log) return;
    std::lock_guard lock(log_mutex);
    log("hlod " + name + " " + std::to_string(decile * 10) + "%");
  };
  Status built;
  tbb::task_arena arena(settings.threads == 0 ? tbb::task_arena::automatic : int(settings.threads));
  arena.execute([&] {
    try {
      built = build_hlod(model, mesh, options, &r.report);
    } catch (const std::exception& e) {  // bad_alloc on a huge mesh: a status, not a crash
      built = Status::error(mesh_file.string() + ": " + e.what());
    }
  });
  if (!built) return built;
  model.tree.name = name;
  model.tree.source_hash = hash;
  r.build_seconds = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return Status::error(out_dir.string() + ": cannot create the output directory: " + ec.message());
  r.file = out_dir / (name + ".hlod");
  const std::vector<uint8_t> bytes = encode_hlod_asset(model.tree, model.payloads);
  if (Status s = write_file_atomic(r.file, bytes); !s) return s;
  r.bytes = bytes.size();
  r.write_seconds = seconds_since(t0);
  if (result) *result = std::move(r);
  return Status::success();
}

}  // namespace lod
