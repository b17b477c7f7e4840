// StreamedFile: appended in pieces, whole under its name only once closed, errors name the file.
#include "cli/streamed_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "test_support.h"

namespace {

using lod::cli::StreamedFile;

std::string read_all(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

size_t entries(const std::filesystem::path& dir) {
  size_t n = 0;
  for (auto it = std::filesystem::directory_iterator(dir); it != std::filesystem::directory_iterator(); ++it) ++n;
  return n;
}

TEST(StreamedFile, AppearsWholeOnlyWhenClosed) {
  const auto dir = lod::test::temp_dir("streamed");
  const auto file = dir / "sub" / "rows.csv";
  StreamedFile f;
  ASSERT_TRUE(f.open(file)) << f.status().message;
  std::string want;
  for (int i = 0; i < 200000; ++i) {  // several buffers' worth
    const std::string row = "row " + std::to_string(i) + "\n";
    f.write(row);
    want += row;
  }
  const std::string big(StreamedFile::kBufferBytes + 10, 'x');  // one piece larger than the buffer
  f.write(big);
  want += big;
  EXPECT_FALSE(std::filesystem::exists(file)) << "not under its name before close";
  EXPECT_EQ(f.bytes(), want.size());
  ASSERT_TRUE(f.close());
  EXPECT_EQ(read_all(file), want);
  EXPECT_EQ(entries(dir / "sub"), 1u) << "no temporary left";
}

TEST(StreamedFile, AFileNotClosedLeavesNothing) {
  const auto dir = lod::test::temp_dir("streamed-drop");
  {
    StreamedFile f;
    ASSERT_TRUE(f.open(dir / "a.json"));
    f.write("{\n");
  }
  EXPECT_EQ(entries(dir), 0u);
}

TEST(StreamedFile, RefusesAFolderItCannotCreateNamingTheFile) {
  const auto dir = lod::test::temp_dir("streamed-bad");
  lod::test::write_text(dir / "plain", "a file, not a folder");
  StreamedFile f;
  const auto st = f.open(dir / "plain" / "frames.csv");
  EXPECT_FALSE(st);
  EXPECT_NE(st.message.find("frames.csv"), std::string::npos) << st.message;
  f.write("ignored");
  EXPECT_FALSE(f.ok());
}

}  // namespace
