// Bake jobs: parallel baking of a scene's models with a content-hash cache.
#include "jobs/bake_jobs.h"

#include <gtest/gtest.h>

#include <mutex>

#include "runtime/lod_asset.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

struct BakeDir {
  fs::path meshes = test::temp_dir("bake-meshes");
  fs::path cache = test::temp_dir("bake-cache");
  std::vector<ModelConfig> models;
  std::vector<std::string> lines;
  std::mutex mutex;
  ProgressLog log = [this](const std::string& line) {
    std::lock_guard lock(mutex);
    lines.push_back(line);
  };

  BakeDir() {
    test::write_text(meshes / "a.off", test::sphere_off(12, 16));
    test::write_text(meshes / "b.off", test::sphere_off(16, 24));
    test::write_text(meshes / "c.off", test::sphere_off(8, 10));
    for (const char* n : {"a", "b", "c"}) {
      ModelConfig m{n, meshes / (std::string(n) + ".off"), {}};
      m.bake.ratios = {1.0f, 0.5f, 0.25f};
      models.push_back(m);
    }
  }
  size_t lines_with(const std::string& part) {
    std::lock_guard lock(mutex);
    size_t n = 0;
    for (const auto& l : lines) n += l.find(part) != std::string::npos;
    return n;
  }
  std::vector<fs::path> cache_files() const {
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(cache)) out.push_back(e.path());
    return out;
  }
};

TEST(BakeJobs, BakesEveryModelThenServesThemFromTheCache) {
  BakeDir d;
  std::vector<LodChain> chains;
  BakeSummary first;
  const Status s = bake_scene_models(d.models, d.cache, 2, chains, first, d.log);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(chains.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(chains[i].name, d.models[i].name) << "chains come in model order";
    EXPECT_EQ(chains[i].levels.size(), 3u);
  }
  EXPECT_EQ(first.baked, 3u);
  EXPECT_EQ(first.cached, 0u);
  ASSERT_EQ(first.jobs.size(), 3u);
  EXPECT_GT(first.jobs[1].input_triangles, 0u);
  EXPECT_EQ(d.cache_files().size(), 3u);
  EXPECT_GT(d.lines_with("bake a"), 0u);

  std::vector<LodChain> again;
  BakeSummary second;
  ASSERT_TRUE(bake_scene_models(d.models, d.cache, 2, again, second, d.log).ok);
  EXPECT_EQ(second.baked, 0u);
  EXPECT_EQ(second.cached, 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(second.jobs[i].from_cache);
    EXPECT_EQ(again[i].indices, chains[i].indices);
    EXPECT_EQ(again[i].source_hash, chains[i].source_hash);
  }
}

// A scene's `file` may name a baked asset: it is read as is, never rebaked or
// written to the cache, and a broken one is refused naming the model and the file.
TEST(BakeJobs, ReadsAModelWhoseFileIsALodAssetAsIs) {
  BakeDir d;
  std::vector<LodChain> chains;
  BakeSummary first;
  ASSERT_TRUE(bake_scene_models(d.models, d.cache, 2, chains, first, d.log).ok);
  const fs::path asset = d.meshes / "b-prebaked.LOD";
  ASSERT_TRUE(write_lod_asset(asset, chains[1]).ok);
  const fs::path fresh_cache = test::temp_dir("bake-cache-lod");
  std::vector<ModelConfig> models = {ModelConfig{"tree", asset, {}}};
  models[0].bake.ratios = {1.0f, 0.1f};  // ignored: the asset's own levels are kept
  std::vector<LodChain> loaded;
  BakeSummary summary;
  const Status s = bake_scene_models(models, fresh_cache, 1, loaded, summary, d.log);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(loaded.size(), 1u);
  EXPECT_EQ(loaded[0].name, "tree");
  EXPECT_EQ(loaded[0].levels.size(), chains[1].levels.size());
  EXPECT_EQ(loaded[0].indices, chains[1].indices);
  EXPECT_EQ(loaded[0].positions, chains[1].positions);
  EXPECT_EQ(summary.baked, 0u);
  EXPECT_EQ(summary.cached, 1u);
  EXPECT_TRUE(fs::is_empty(fresh_cache));
  EXPECT_EQ(d.lines_with("loaded as is"), 1u);

  test::write_bytes(asset, {'n', 'o', 't', ' ', 'a', 's', 's', 'e', 't'});
  const Status bad = bake_scene_models(models, fresh_cache, 1, loaded, summary, d.log);
  EXPECT_FALSE(bad.ok);
  EXPECT_NE(bad.message.find("model tree"), std::string::npos) << bad.message;
  EXPECT_NE(bad.message.find(asset.string()), std::string::npos) << bad.message;
}

TEST(BakeJobs, CacheFileIsNamedByModelAndKey) {
  BakeDir d;
  d.models.resize(1);
  std::vector<LodChain> chains;
  BakeSummary summary;
  ASSERT_TRUE(bake_scene_models(d.models, d.cache, 1, chains, summary, d.log).ok);
  Status key_status;
  const uint64_t key = bake_key(d.models[0].file, d.models[0].bake, &key_status);
  ASSERT_TRUE(key_status.ok);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(key));
  EXPECT_TRUE(fs::exists(d.cache / ("a-" + std::string(hex) + ".lod")));
}

TEST(BakeJobs, ChangedSettingsMissTheCache) {
  BakeDir d;
  d.models.resize(1);
  std::vector<LodChain> chains;
  BakeSummary summary;
  ASSERT_TRUE(bake_scene_models(d.models, d.cache, 1, chains, summary, d.log).ok);
  d.models[0].bake.ratios = {1.0f, 0.3f};
  ASSERT_TRUE(bake_scene_models(d.models, d.cache, 1, chains, summary, d.log).ok);
  EXPECT_EQ(summary.baked, 1u);
  EXPECT_EQ(chains[0].levels.size(), 2u);
  EXPECT_EQ(d.cache_files().size(), 2u);
}

TEST(BakeJobs, CorruptCacheFileIsRebakedWithALogLine) {
  BakeDir d;
  std::vector<LodChain> chains;
  BakeSummary summary;
  ASSERT_TRUE(bake_scene_models(d.models, d.cache, 2, chains, summary, d.log).ok);
  fs::path victim;
  for (const fs::path& p : d.cache_files())
    if (p.filename().string().rfind("b-", 0) == 0) victim = p;
  ASSERT_FALSE(victim.empty());
  std::vector<uint8_t> bytes = test::read_bytes(victim);
  bytes.resize(bytes.size() / 2);  // truncated
  test::write_bytes(victim, bytes);

  std::vector<LodChain> again;
  ASSERT_TRUE(bake_scene_models(d.models, d.cache, 2, again, summary, d.log).ok);
  EXPECT_EQ(summary.baked, 1u);
  EXPECT_EQ(summary.cached, 2u);
  EXPECT_FALSE(summary.jobs[1].from_cache);
  EXPECT_EQ(d.lines_with("rebaking"), 1u);
  EXPECT_EQ(again[1].indices, chains[1].indices);
  LodChain reread;
  EXPECT_TRUE(read_lod_asset(victim, reread).ok) << "the rebake rewrote the cache file";
}

TEST(BakeJobs, MissingMeshNamesModelAndFile) {
  BakeDir d;
  d.models[1].file = d.meshes / "gone.off";
  std::vector<LodChain> chains;
  BakeSummary summary;
  const Status s = bake_scene_models(d.models, d.cache, 2, chains, summary, d.log);
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.message.find("model b"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("gone.off"), std::string::npos) << s.message;
  EXPECT_TRUE(chains.empty()) << "no chains handed out on failure";
}

TEST(BakeJobs, BrokenMeshNamesModelAndFileAndWritesNothingForIt) {
  BakeDir d;
  test::write_text(d.meshes / "broken.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  d.models[2].file = d.meshes / "broken.off";
  std::vector<LodChain> chains;
  BakeSummary summary;
  const Status s = bake_scene_models(d.models, d.cache, 2, chains, summary, d.log);
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.message.find("model c"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("broken.off"), std::string::npos) << s.message;
  EXPECT_EQ(s.message.find("broken.off"), s.message.rfind("broken.off")) << "the file is named once: " << s.message;
  EXPECT_NE(s.message.find("references vertex 7 of 3"), std::string::npos) << s.message;
  for (const fs::path& p : d.cache_files()) EXPECT_NE(p.filename().string().rfind("c-", 0), 0u) << p;
}

TEST(BakeJobs, BakeErrorsNameTheModelAndTheFileOnce) {
  // The bake's own message already says "c (file)"; the job must not say it again.
  BakeDir d;
  d.models[2].bake.ratios = {1.0f, 1.5f};
  std::vector<LodChain> chains;
  BakeSummary summary;
  const Status s = bake_scene_models(d.models, d.cache, 2, chains, summary, d.log);
  ASSERT_FALSE(s.ok);
  EXPECT_EQ(s.message.rfind("model c (", 0), 0u) << s.message;
  EXPECT_EQ(s.message.find("c.off"), s.message.rfind("c.off")) << "the file is named once: " << s.message;
  EXPECT_NE(s.message.find("ratio 1.5"), std::string::npos) << s.message;
}

TEST(BakeJobs, NoModelsIsAnEmptySuccess) {
  BakeDir d;
  std::vector<LodChain> chains(2);
  BakeSummary summary;
  ASSERT_TRUE(bake_scene_models({}, d.cache, 0, chains, summary, nullptr).ok);
  EXPECT_TRUE(chains.empty());
  EXPECT_EQ(summary.baked + summary.cached, 0u);
}

TEST(BakeJobs, UnwritableCacheDirectoryIsRefused) {
  BakeDir d;
  test::write_text(d.cache / "file", "x");
  std::vector<LodChain> chains;
  BakeSummary summary;
  const Status s = bake_scene_models(d.models, d.cache / "file" / "sub", 1, chains, summary, d.log);
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.message.find("file/sub"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

// ratios = [1, 0.5, 0.25, 0]: the bake appends the culled level (empty), the chain validates
// and morphs between its drawn levels, and the cached asset gives the same chain back.
TEST(BakeJobsCulledLevel, ARatioOfZeroBakesAnEmptyLastLevel) {
  BakeDir d;
  std::vector<ModelConfig> models = {d.models[0]};
  models[0].bake.ratios = {1.0f, 0.5f, 0.25f, 0.0f};
  std::vector<LodChain> chains;
  BakeSummary first, second;
  Status s = bake_scene_models(models, d.cache, 2, chains, first, d.log);
  ASSERT_TRUE(s.ok) << s.message;
  const LodChain& c = chains.at(0);
  ASSERT_EQ(c.levels.size(), 4u);
  EXPECT_TRUE(has_culled_level(c));
  EXPECT_EQ(c.levels[3].triangles(), 0u);
  EXPECT_EQ(c.levels[3].vertex_count, 0u);
  EXPECT_GT(c.levels[2].triangles(), 0u);
  EXPECT_GE(c.levels[3].error, 2 * c.levels[0].bounds.radius * 0.999f) << "culled: the object's size is the error";
  EXPECT_GE(c.levels[3].error, c.levels[2].error);
  std::string why;
  EXPECT_TRUE(validate_chain(c, &why)) << why;
  EXPECT_TRUE(can_morph_levels(c)) << "the drawn levels keep their morph targets";

  std::vector<LodChain> again;
  s = bake_scene_models(models, d.cache, 2, again, second, d.log);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(second.cached, 1u);
  EXPECT_EQ(encode_lod_asset(again.at(0)), encode_lod_asset(c));
}

// A view-dependent textured model: its hierarchy carries uvs and pins its seams; a cached tree
// from before that rule (no VHAT section) is rebuilt once, with a log line, and the cache
// rewritten.
TEST(BakeJobs, ViewDependentTexturedModelsGetUvsAndOldTreesAreRebuilt) {
  BakeDir d;
  const fs::path file = test::write_two_material_gltf(d.meshes / "globe", "globe", 12, 24);
  ASSERT_FALSE(file.empty());
  ModelConfig m{"globe", file, {}};
  m.bake.ratios = {1.0f, 0.5f};
  m.view_dependent = true;
  std::vector<LodChain> chains;
  BakeSummary summary;
  Status s = bake_scene_models({m}, d.cache, 1, chains, summary, d.log);
  ASSERT_TRUE(s.ok) << s.message;
  const VertexTree& t = chains[0].hierarchy;
  ASSERT_FALSE(t.empty());
  EXPECT_TRUE(t.seams_pinned);
  ASSERT_EQ(t.uvs.size(), 2 * size_t(t.node_count()));
  EXPECT_TRUE(std::equal(t.uvs.begin(), t.uvs.begin() + 2 * t.leaf_count, chains[0].uvs.begin()));
  ASSERT_EQ(d.cache_files().size(), 1u);
  // Make the cached tree look like one from before (no uvs, seams not pinned).
  const fs::path cached = d.cache_files()[0];
  LodChain old;
  ASSERT_TRUE(read_lod_asset(cached, old).ok);
  old.hierarchy.uvs.clear();
  old.hierarchy.seams_pinned = false;
  ASSERT_TRUE(write_lod_asset(cached, old).ok);
  s = bake_scene_models({m}, d.cache, 1, chains, summary, d.log);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(summary.cached, 1u);
  EXPECT_EQ(d.lines_with("before attribute seams were pinned, rebuilding"), 1u);
  EXPECT_EQ(chains[0].hierarchy.uvs.size(), 2 * size_t(chains[0].hierarchy.node_count()));
  LodChain again;
  ASSERT_TRUE(read_lod_asset(cached, again).ok);
  EXPECT_TRUE(again.hierarchy.seams_pinned);  // rewritten: rebuilt once only
  EXPECT_EQ(again.hierarchy.uvs, chains[0].hierarchy.uvs);
}

}  // namespace
}  // namespace lod
