// The files of a distributed bake's cache as its tests see them: the entries of one kind, in
// name order, and the two kinds of damage the bake must survive (a flipped bit, a lost tail).
#pragma once
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "test_support.h"

namespace lod::test {

// The regular files in `cache` whose extension is `ext` (".hsub", ".hlod"), sorted; none when
// the folder does not exist.
inline std::vector<std::filesystem::path> cache_entries(const std::filesystem::path& cache, const std::string& ext) {
  std::vector<std::filesystem::path> files;
  if (std::filesystem::exists(cache))
    for (const auto& e : std::filesystem::directory_iterator(cache))
      if (e.is_regular_file() && e.path().extension() == ext) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

// One bit flipped in the middle of the entry: its checksum no longer holds.
inline void corrupt_entry(const std::filesystem::path& entry) {
  std::vector<uint8_t> bytes = read_bytes(entry);
  bytes[bytes.size() / 2] ^= 0x10;
  write_bytes(entry, bytes);
}

// The entry's last byte cut off, as a write stopped short leaves it.
inline void truncate_entry(const std::filesystem::path& entry) {
  std::vector<uint8_t> bytes = read_bytes(entry);
  bytes.resize(bytes.size() - 1);
  write_bytes(entry, bytes);
}

}  // namespace lod::test
