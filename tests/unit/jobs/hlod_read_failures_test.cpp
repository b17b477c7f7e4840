// Failed HLOD node reads: a cache entry is marked bad once, every failure of it says so, and the
// next bake rebakes a marked entry instead of taking it up as cached.
#include "jobs/hlod_read_failures.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "jobs/hlod_scene.h"
#include "jobs/scene_config.h"
#include "test_support.h"

namespace lod {
namespace {

// A scene of one hlod model (a small sphere) and its cache folder.
struct HlodScene {
  std::filesystem::path dir = test::temp_dir("hlod-read-failures");
  SceneConfig config;
  HlodScene() {
    test::write_text(dir / "ball.off", test::sphere_off(20, 40));
    test::write_text(dir / "scene.toml",
                     "[[model]]\nname = \"ball\"\nfile = \"ball.off\"\nhlod = true\nmin_verts = 200\n"
                     "[[instances]]\nmodel = \"ball\"\ncount = 1\n");
    const Status st = load_scene_config(dir / "scene.toml", dir, config);
    EXPECT_TRUE(st) << st.message;
  }
  // One bake: the log's lines, how many were baked and cached.
  Status bake(HlodModels& out, size_t& baked, size_t& cached, std::string& log) {
    log.clear();
    return bake_hlod_models(config, dir / "cache", [&](const std::string& line) { log += line + "\n"; }, out, &baked,
                            &cached);
  }
};

TEST(HlodReadFailures, AnEntryMarkedBadIsRebakedAndItsMarkRemoved) {
  HlodScene s;
  HlodModels h;
  size_t baked = 0, cached = 0;
  std::string log;
  ASSERT_TRUE(s.bake(h, baked, cached, log));
  ASSERT_EQ(baked, 1u);
  ASSERT_EQ(h.cache_entry, std::vector<uint8_t>{1});
  const std::filesystem::path entry = h.files[0];
  ASSERT_TRUE(s.bake(h, baked, cached, log));
  EXPECT_EQ(cached, 1u) << log;

  ASSERT_TRUE(mark_entry_bad(entry, entry.string() + ": node 3: payload checksum mismatch"));
  std::string why;
  ASSERT_TRUE(entry_marked_bad(entry, &why));
  EXPECT_EQ(why, entry.string() + ": node 3: payload checksum mismatch");
  ASSERT_TRUE(s.bake(h, baked, cached, log));
  EXPECT_EQ(baked, 1u) << log;
  EXPECT_EQ(cached, 0u) << log;
  EXPECT_NE(log.find("was marked bad (" + entry.string() + ": node 3: payload checksum mismatch), rebaking"),
            std::string::npos)
      << log;
  EXPECT_FALSE(entry_marked_bad(entry)) << "the fresh entry replaced the bad one";
  EXPECT_EQ(h.files[0], entry);
  ASSERT_TRUE(s.bake(h, baked, cached, log));
  EXPECT_EQ(cached, 1u) << log;
}

// Loaders failing on several threads at once: the entry is marked once, with the first
// failure's reason, and every failure says it was marked. A .hlod the config names is not.
TEST(HlodReadFailures, AFailingCacheEntryIsMarkedOnceAndEveryFailureSaysSo) {
  const auto dir = test::temp_dir("hlod-read-failures-mark");
  auto h = std::make_shared<HlodModels>();
  h->names = {"cached", "named"};
  h->files = {dir / "cached.hlod", dir / "named.hlod"};
  h->trees.resize(2);
  h->cache_entry = {1, 0};
  std::atomic<int> reads{0};
  const ModelNodeLoader load = marking_bad_entries(h, [&](uint32_t, uint32_t, HlodPayload&) {
    ++reads;
    return Status::error("the storage erred");
  });
  std::vector<std::thread> threads;
  std::vector<Status> results(8);
  for (uint32_t t = 0; t < 8; ++t)
    threads.emplace_back([&, t] {
      HlodPayload p;
      results[t] = load(t % 2, t, p);
    });
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(reads.load(), 8);
  for (uint32_t t = 0; t < 8; ++t) {
    ASSERT_FALSE(results[t]);
    const bool marked = results[t].message.find("marked bad") != std::string::npos;
    EXPECT_EQ(marked, t % 2 == 0) << results[t].message;
  }
  std::string why;
  ASSERT_TRUE(entry_marked_bad(dir / "cached.hlod", &why));
  EXPECT_EQ(why.rfind((dir / "cached.hlod").string() + ": node ", 0), 0u) << why;
  EXPECT_NE(why.find(": the storage erred"), std::string::npos) << why;
  EXPECT_FALSE(entry_marked_bad(dir / "named.hlod"));
}

TEST(HlodReadFailures, MessagesNameTheFileAndTheNodeOnce) {
  HlodModels h;
  h.names = {"ball", "bare"};
  h.files = {"/cache/ball-1f.hlod", ""};
  EXPECT_EQ(hlod_failure_message(h, 0, 17, "truncated at byte 812"), "/cache/ball-1f.hlod: node 17: truncated at byte 812");
  EXPECT_EQ(hlod_failure_message(h, 0, 17, "/cache/ball-1f.hlod: node 17: payload checksum mismatch"),
            "/cache/ball-1f.hlod: node 17: payload checksum mismatch")
      << "the reader named them already";
  EXPECT_EQ(hlod_failure_message(h, 1, 2, "the storage erred"), "hlod model bare: node 2: the storage erred");
}

}  // namespace
}  // namespace lod
