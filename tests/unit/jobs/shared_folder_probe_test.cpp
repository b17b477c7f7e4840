// The probe behind the distributed bakes' first step: rank 0's file in each folder, every
// rank's look in its own, and what rank 0 says about the ranks that did not see it.
#include "jobs/shared_folder_probe.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "test_support.h"

namespace lod {
namespace {

TEST(SharedFolderProbe, SeenWhereItWasPlacedNotElsewhereAndRemovedAfter) {
  const auto dir = test::temp_dir("shared_probe");
  const std::vector<SharedFolder> mine{{"cache folder", dir / "cache"}, {"output folder", dir / "out" / "deep"}};
  std::string name;
  ASSERT_TRUE(place_probes(mine, name));
  EXPECT_EQ(name.find('/'), std::string::npos);
  EXPECT_EQ(sees_probes(mine, name), (std::vector<uint8_t>{1, 1})) << "the folders are made when missing";
  const std::vector<SharedFolder> node_local{{"cache folder", dir / "cache"}, {"output folder", dir / "elsewhere"}};
  EXPECT_EQ(sees_probes(node_local, name), (std::vector<uint8_t>{1, 0}));
  std::string second;
  ASSERT_TRUE(place_probes(mine, second));
  EXPECT_NE(second, name) << "two jobs sharing a folder probe with two names";
  remove_probes(mine, name);
  remove_probes(mine, second);
  EXPECT_EQ(sees_probes(mine, name), (std::vector<uint8_t>{0, 0}));
  EXPECT_TRUE(std::filesystem::is_empty(dir / "cache"));
}

TEST(SharedFolderProbe, ANameFromAnotherRankIsNeverAPath) {
  const auto dir = test::temp_dir("shared_probe_names");
  std::filesystem::create_directories(dir / "a");
  test::write_text(dir / "a" / "x", "");
  const std::vector<SharedFolder> f{{"cache folder", dir / "b"}};
  std::filesystem::create_directories(dir / "b");
  for (const std::string bad : {"../a/x", "", ".", "..", "/etc/hostname"})
    EXPECT_EQ(sees_probes(f, bad), std::vector<uint8_t>{0}) << bad;
}

TEST(SharedFolderProbe, UnseenMessageNamesEachFoldersRanks) {
  const std::vector<SharedFolder> f{{"cache folder", "/shared/cache"}, {"output folder", "/shared/out"}};
  EXPECT_EQ(unseen_message(f, {{1, 1}, {1, 1}, {1, 1}}), "");
  EXPECT_EQ(unseen_message(f, {{1, 1}, {}, {1, 1}}), "") << "a rank that could not look says why itself";
  const std::string one = unseen_message(f, {{1, 1}, {0, 1}});
  EXPECT_NE(one.find("rank 1 does not see, in its cache folder, the file rank 0 made in /shared/cache"), std::string::npos) << one;
  EXPECT_EQ(one.find("output folder,"), std::string::npos) << one;
  const std::string two = unseen_message(f, {{1, 1}, {1, 0}, {0, 0}, {1, 0}});
  EXPECT_NE(two.find("rank 2 does not see, in its cache folder"), std::string::npos) << two;
  EXPECT_NE(two.find("ranks 1, 2, 3 do not see, in its output folder"), std::string::npos) << two;
  EXPECT_NE(two.find("shared storage"), std::string::npos) << two;
}

TEST(SharedFolderProbe, AFolderThatCannotBeMadeIsNamed) {
  const auto dir = test::temp_dir("shared_probe_file");
  test::write_text(dir / "taken", "a file where the folder should be");
  std::string name;
  const Status s = place_probes({{"cache folder", dir / "ok"}, {"output folder", dir / "taken" / "out"}}, name);
  ASSERT_FALSE(s);
  EXPECT_NE(s.message.find((dir / "taken" / "out").string()), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("output folder"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace lod
