// The scene HLOD of a config's scene ([scene_hlod] enabled): built from its static instances
// (blocks without motion) on the TBB pool; make_service binds it to the handles it gives them.
#pragma once
#include <span>

#include "jobs/bake_jobs.h"  // ProgressLog
#include "jobs/scene.h"
#include "jobs/scene_config.h"
#include "runtime/scene_hlod_tree.h"
#include "runtime/status.h"

namespace lod {

// `config` is the one `scene` was made from (its instance blocks say which objects move).
// An empty tree when [scene_hlod] is off or fewer than min_objects objects are static.
Status bake_scene_hlod(const SceneConfig& config, const Scene& scene, const ProgressLog& log, SceneHlodTree& out);

}  // namespace lod
