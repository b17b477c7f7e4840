// runtime/regular_file.h: only regular files are opened (FIFOs, devices, sockets and folders
// are refused by stat, naming the file and what it is), every read is bounded before it
// starts, and no other code opens user paths for reading (a scan of the sources).
#include "runtime/regular_file.h"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include "fifo_guard.h"
#include "runtime/lod_asset.h"
#include "runtime/lod_chain.h"
#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

bool has(const Status& s, const std::string& part) { return s.message.find(part) != std::string::npos; }

// A file of `size` bytes holding `head` first and no data blocks after it (ftruncate).
void sparse_file(const fs::path& path, const std::vector<uint8_t>& head, uint64_t size) {
  test::write_bytes(path, head);
  ASSERT_EQ(::truncate(path.c_str(), off_t(size)), 0) << path;
}

TEST(RegularFile, RefusesWhatIsNotARegularFileByNameAndKind) {
  const fs::path dir = test::temp_dir("regular-kinds");
  test::FifoGuard fifo(dir / "f.off");
  ASSERT_TRUE(fifo.made());
  fs::create_directories(dir / "folder.off");
  std::vector<uint8_t> bytes;
  Status s = read_regular_file(fifo.path(), kInputFileLimit, bytes);
  EXPECT_FALSE(fifo.fired()) << "the FIFO was opened";
  ASSERT_FALSE(s);
  EXPECT_TRUE(has(s, "f.off: is a FIFO, not a regular file")) << s.message;
  s = read_regular_file(dir / "folder.off", kInputFileLimit, bytes);
  EXPECT_TRUE(has(s, "folder.off: is a directory, not a regular file")) << s.message;
  s = read_regular_file("/dev/zero", kInputFileLimit, bytes);
  EXPECT_TRUE(has(s, "/dev/zero: is a character device, not a regular file")) << s.message;
  s = read_regular_file(dir / "none.off", kInputFileLimit, bytes);
  EXPECT_TRUE(has(s, "none.off: no such file")) << s.message;
  uint64_t hash = 0;
  s = hash_regular_file("/dev/zero", hash);
  EXPECT_TRUE(has(s, "/dev/zero: is a character device")) << s.message;
  s = hash_regular_file(fifo.path(), hash);
  EXPECT_TRUE(has(s, "f.off: is a FIFO")) << s.message;
  EXPECT_FALSE(fifo.fired()) << "the FIFO was opened";
  EXPECT_TRUE(bytes.empty());
}

TEST(RegularFile, RefusesASocket) {
  const fs::path dir = test::temp_dir("regular-socket");
  const fs::path path = dir / "s.lod";
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.string().size() >= sizeof addr.sun_path) GTEST_SKIP() << "temp path too long for a socket";
  std::strcpy(addr.sun_path, path.c_str());
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const Status s = check_regular_file(path, kInputFileLimit);
  ::close(fd);
  EXPECT_TRUE(has(s, "s.lod: is a socket, not a regular file")) << s.message;
}

TEST(RegularFile, RefusesAFileOverItsKindsLimitUnread) {
  const fs::path dir = test::temp_dir("regular-limit");
  sparse_file(dir / "big.mtl", {'n', 'e', 'w'}, kMaterialFileLimit.max_bytes + 1);
  std::vector<uint8_t> bytes;
  const Status s = read_regular_file(dir / "big.mtl", kMaterialFileLimit, bytes);
  ASSERT_FALSE(s);
  EXPECT_TRUE(has(s, "big.mtl: is " + std::to_string(kMaterialFileLimit.max_bytes + 1) + " bytes; a material file is at most"))
      << s.message;
  EXPECT_TRUE(bytes.empty());
}

TEST(RegularFile, ReadsAndHashesARegularFile) {
  const fs::path dir = test::temp_dir("regular-read");
  std::vector<uint8_t> data(3 * (1 << 20) + 17);
  for (size_t i = 0; i < data.size(); ++i) data[i] = uint8_t(i * 31 + 7);
  test::write_bytes(dir / "a.bin", data);
  std::vector<uint8_t> back;
  ASSERT_TRUE(read_regular_file(dir / "a.bin", kInputFileLimit, back));
  EXPECT_EQ(back, data);
  uint64_t hash = 0;
  ASSERT_TRUE(hash_regular_file(dir / "a.bin", hash, 5));
  EXPECT_EQ(hash, hash_bytes(data.data(), data.size(), 5)) << "hashed in pieces, the same as whole";
  RegularFile f;
  ASSERT_TRUE(open_regular_file(dir / "a.bin", kInputFileLimit, f));
  std::vector<uint8_t> part;
  const Status past = f.read_exactly(data.size() - 4, 8, part);
  EXPECT_TRUE(has(past, "truncated")) << past.message;
  ASSERT_TRUE(f.read_exactly(10, 4, part));
  EXPECT_EQ(part, std::vector<uint8_t>(data.begin() + 10, data.begin() + 14));
}

TEST(RegularFile, TextHeadWithANulByteIsRefused) {
  const fs::path dir = test::temp_dir("regular-text");
  sparse_file(dir / "zeros.txt", {}, 1 << 20);
  RegularFile f;
  ASSERT_TRUE(open_regular_file(dir / "zeros.txt", kInputFileLimit, f));
  const Status s = check_text_head(f, "OFF");
  EXPECT_TRUE(has(s, "zeros.txt: holds binary data (a NUL byte at offset 0), not OFF text")) << s.message;
}

// An asset's header and section table are checked against the file's size before the file
// is read: a 4 GiB sparse file with a valid header (and nothing where its checksum should be)
// is refused for the bytes after its sections, not read whole and found corrupt.
TEST(RegularFile, SparseMultiGigabyteLodAssetIsRefusedFromItsHeader) {
  const fs::path dir = test::temp_dir("regular-sparse-lod");
  std::vector<uint8_t> head(16, 0);  // magic, version, no sections
  std::memcpy(head.data(), "LODKIT\x1a\n", 8);
  const uint32_t version = kLodAssetVersion;
  std::memcpy(head.data() + 8, &version, 4);
  sparse_file(dir / "big.lod", head, uint64_t(4) << 30);
  LodChain out;
  out.name = "untouched";
  Status s = read_lod_asset(dir / "big.lod", out);
  ASSERT_FALSE(s);
  EXPECT_TRUE(has(s, "big.lod: file is 4294967296 bytes, its sections and checksum end at 24")) << s.message;
  EXPECT_EQ(out.name, "untouched");
  sparse_file(dir / "zeros.lod", {}, uint64_t(4) << 30);
  s = read_lod_asset(dir / "zeros.lod", out);
  EXPECT_TRUE(has(s, "zeros.lod: not a lodkit asset (bad magic bytes)")) << s.message;
}

TEST(RegularFile, LodReaderRefusesAFifoWithoutOpeningIt) {
  const fs::path dir = test::temp_dir("regular-lod-fifo");
  test::FifoGuard fifo(dir / "pipe.lod");
  LodChain out;
  const Status s = read_lod_asset(fifo.path(), out);
  EXPECT_FALSE(fifo.fired()) << "the FIFO was opened";
  EXPECT_TRUE(has(s, "pipe.lod: is a FIFO, not a regular file")) << s.message;
}

// ---- no other opening of files for reading --------------------------------------------------

// The lines of `text` that open a file for reading other than through regular_file.h: an
// ifstream / fstream / filebuf not constructed on a string literal (a fixed system path such
// as "/proc/meminfo" is not a user path), fopen / freopen, or open(..., O_RDONLY ...).
std::vector<size_t> reading_opens(const std::string& text) {
  static const std::regex stream(R"(\b(basic_ifstream|ifstream|fstream|basic_filebuf|filebuf)\b)");
  static const std::regex literal_stream(R"(\b(ifstream|fstream)\s+\w+\s*[({]\s*")");
  static const std::regex c_open(R"(\b(fopen|freopen|fopen64)\s*\()");
  static const std::regex posix_open(R"(\bopen(at)?(64)?\s*\([^;]*\bO_RDONLY\b)");
  std::vector<size_t> out;
  std::istringstream in(text);
  std::string line;
  for (size_t n = 1; std::getline(in, line); ++n) {
    if (const size_t c = line.find("//"); c != std::string::npos) line.erase(c);
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line.compare(first, 8, "#include") == 0) continue;
    const bool stream_use = std::regex_search(line, stream) && !std::regex_search(line, literal_stream);
    if (stream_use || std::regex_search(line, c_open) || std::regex_search(line, posix_open)) out.push_back(n);
  }
  return out;
}

TEST(RegularFileScan, FindsEveryWayOfOpeningForReading) {
  EXPECT_EQ(reading_opens("std::ifstream f(path, std::ios::binary);\n").size(), 1u);
  EXPECT_EQ(reading_opens("  std::ifstream f;\n  f.open(path);\n").size(), 1u);
  EXPECT_EQ(reading_opens("FILE* f = std::fopen(name.c_str(), \"rb\");\n").size(), 1u);
  EXPECT_EQ(reading_opens("const int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC);\n").size(), 1u);
  EXPECT_EQ(reading_opens("std::fstream f(path);\n").size(), 1u);
  EXPECT_TRUE(reading_opens("std::ifstream in(\"/proc/meminfo\");\n").empty()) << "a fixed system path";
  EXPECT_TRUE(reading_opens("std::ofstream f(path);\n#include <fstream>\n// std::ifstream f(p);\n").empty());
  EXPECT_TRUE(reading_opens("::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);\n").empty());
}

TEST(RegularFileScan, NoOtherCodeOpensUserPathsForReading) {
  // The files allowed to open for reading, and why.
  const std::map<std::string, std::string> allowed = {
      {"runtime/regular_file.cpp", "the one place that opens files for reading"},
      {"runtime/file_write.cpp", "reads back the file it has just created (O_EXCL), not a user path"},
  };
  const fs::path root = LOD_SOURCE_DIR;
  size_t scanned = 0;
  std::vector<std::string> found;
  for (const char* dir : {"runtime", "preprocess", "jobs", "cli"}) {
    ASSERT_TRUE(fs::is_directory(root / dir)) << root / dir;
    for (const auto& e : fs::recursive_directory_iterator(root / dir)) {
      const std::string ext = e.path().extension().string();
      if (!e.is_regular_file() || (ext != ".cpp" && ext != ".h" && ext != ".hpp")) continue;
      const std::string rel = fs::relative(e.path(), root).generic_string();
      ++scanned;
      if (allowed.count(rel)) continue;
      std::ifstream in(e.path());
      std::stringstream text;
      text << in.rdbuf();
      for (size_t line : reading_opens(text.str())) found.push_back(rel + ":" + std::to_string(line));
    }
  }
  EXPECT_GT(scanned, 100u) << "the sources were not found under " << root;
  for (const std::string& f : found)
    ADD_FAILURE() << f << ": opens a file for reading; use runtime/regular_file.h (regular files only, bounded)";
}

}  // namespace
}  // namespace lod
