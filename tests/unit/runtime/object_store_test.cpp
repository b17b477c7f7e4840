// ObjectStore, HandleTable and object commands: handles stay valid exactly as long as their
// object lives, and every column follows its object when others are erased.
#include "runtime/object_store.h"

#include <gtest/gtest.h>

#include <random>
#include <set>

#include "runtime/handle_table.h"
#include "runtime/object_commands.h"

namespace lod {
namespace {

Transform at(float x) {
  Transform t;
  t.position[0] = x;
  return t;
}

TEST(HandleTable, DestroyedHandlesAreRefusedAndSlotsReused) {
  HandleTable t;
  const ObjectHandle a = t.allocate(), b = t.allocate();
  EXPECT_NE(a, 0u);
  EXPECT_NE(a, b);
  EXPECT_TRUE(t.live(a));
  EXPECT_TRUE(t.release(a));
  EXPECT_FALSE(t.live(a));
  EXPECT_FALSE(t.release(a)) << "a second destroy is refused";
  const ObjectHandle c = t.allocate();
  EXPECT_EQ(handle_slot(c), handle_slot(a)) << "the freed slot is reused";
  EXPECT_NE(c, a) << "with a new generation";
  EXPECT_FALSE(t.live(a));
  EXPECT_TRUE(t.live(c));
  EXPECT_FALSE(t.live(0));
  EXPECT_FALSE(t.live(make_handle(999, 1)));
  EXPECT_EQ(t.live_count(), 2u);
}

TEST(HandleTable, ChurnKeepsTheTableAtItsPeak) {
  HandleTable t;
  std::vector<ObjectHandle> live, dead;
  std::mt19937 rng(3);
  for (int i = 0; i < 200000; ++i) {
    if (live.size() < 64 && (live.empty() || rng() % 2)) {
      live.push_back(t.allocate());
    } else {
      const size_t k = rng() % live.size();
      ASSERT_TRUE(t.release(live[k]));
      if (dead.size() < 1000) dead.push_back(live[k]);
      live[k] = live.back();
      live.pop_back();
    }
  }
  EXPECT_LE(t.slots(), 64u);
  for (ObjectHandle h : dead) EXPECT_FALSE(t.live(h));
  for (ObjectHandle h : live) EXPECT_TRUE(t.live(h));
}

TEST(ObjectStore, EraseMovesEveryColumnWithItsObject) {
  ObjectStore s;
  for (uint32_t i = 0; i < 5; ++i) s.insert(make_handle(i, 1), i % 2, at(float(i)), ObjectOptions{});
  for (uint32_t i = 0; i < 5; ++i) {
    s.prev_level[i] = uint8_t(10 + i);
    s.was_visible[i] = 1;
    s.morph_start[i] = 100.0 + i;
    s.cx[i] = 50.f + i;
  }
  s.erase(1);  // the last object (slot 4) takes index 1
  ASSERT_EQ(s.size(), 4u);
  EXPECT_EQ(s.find(make_handle(1, 1)), kNoIndex);
  const uint32_t i4 = s.find(make_handle(4, 1));
  ASSERT_EQ(i4, 1u);
  EXPECT_EQ(s.transform[i4].position[0], 4.f);
  EXPECT_EQ(s.model[i4], 0u);
  EXPECT_EQ(s.prev_level[i4], 14);
  EXPECT_EQ(s.morph_start[i4], 104.0);
  EXPECT_EQ(s.cx[i4], 54.f);
  for (uint32_t slot : {0u, 2u, 3u}) {
    const uint32_t i = s.find(make_handle(slot, 1));
    ASSERT_NE(i, kNoIndex);
    EXPECT_EQ(s.transform[i].position[0], float(slot));
    EXPECT_EQ(s.prev_level[i], 10 + slot);
  }
  s.erase(s.find(make_handle(3, 1)));  // erasing the last one
  EXPECT_EQ(s.size(), 3u);
  EXPECT_EQ(s.find(make_handle(3, 1)), kNoIndex);
  EXPECT_EQ(s.find(make_handle(0, 2)), kNoIndex) << "a wrong generation is not found";
}

TEST(ObjectCommands, AppliedInStagingOrder) {
  ObjectStore s;
  std::vector<ObjectCommand> cmds(5);
  cmds[0].kind = CommandKind::create, cmds[0].handle = make_handle(0, 1), cmds[0].transform = at(1);
  cmds[1].kind = CommandKind::transform, cmds[1].handle = make_handle(0, 1), cmds[1].transform = at(2);
  cmds[2].kind = CommandKind::create, cmds[2].handle = make_handle(1, 1), cmds[2].model = 1;
  cmds[3].kind = CommandKind::destroy, cmds[3].handle = make_handle(1, 1);
  cmds[4].kind = CommandKind::options, cmds[4].handle = make_handle(0, 1);
  cmds[4].options.never_cull = true;
  std::vector<uint32_t> freed;
  const ApplyCounts n = apply_commands(s, cmds, 2, freed);
  EXPECT_EQ(n.created, 2u);
  EXPECT_EQ(n.destroyed, 1u);
  EXPECT_EQ(n.moved, 1u);
  EXPECT_EQ(n.changed, 1u);
  EXPECT_EQ(n.refused, 0u);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s.transform[0].position[0], 2.f);
  EXPECT_TRUE(s.options[0].never_cull);
  EXPECT_EQ(freed, std::vector<uint32_t>{1});
  EXPECT_TRUE(s.dirty[0]);

  // Unknown handles, unknown models and a slot still in use are refused, nothing changes.
  std::vector<ObjectCommand> bad(3);
  bad[0].kind = CommandKind::transform, bad[0].handle = make_handle(7, 1);
  bad[1].kind = CommandKind::create, bad[1].handle = make_handle(2, 1), bad[1].model = 5;
  bad[2].kind = CommandKind::create, bad[2].handle = make_handle(0, 2);
  EXPECT_EQ(apply_commands(s, bad, 2, freed).refused, 3u);
  EXPECT_EQ(s.size(), 1u);
}

}  // namespace
}  // namespace lod
