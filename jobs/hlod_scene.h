// HLOD models of a scene config: the models with hlod = true baked (cached by content hash) to
// .hlod files and placed by their one instance, and the config without them for the discrete
// path (objects of an hlod model never become discrete objects).
#pragma once
#include <filesystem>
#include <functional>
#include <string>

#include "jobs/hlod_models.h"
#include "jobs/scene_config.h"
#include "runtime/status.h"

namespace lod {

// `config` without its hlod models and their [[instances]] blocks (instance model indices
// renumbered to the models left).
SceneConfig discrete_part(const SceneConfig& config);

// Loads `cache_dir/<name>-<key>.hlod` when its tree is valid and its source_hash is the key
// (hlod_source_hash of the mesh and min_verts), otherwise bakes it with bake_hlod_file. Every
// hlod model must have exactly one instance. An entry marked bad (a node of it failed to read
// while streaming: jobs/hlod_read_failures.h) is rebaked, and the mark removed. `log` gets
// progress lines; `baked` / `cached` count the models each way.
Status bake_hlod_models(const SceneConfig& config, const std::filesystem::path& cache_dir,
                        const std::function<void(const std::string&)>& log, HlodModels& out, size_t* baked = nullptr,
                        size_t* cached = nullptr);

}  // namespace lod
