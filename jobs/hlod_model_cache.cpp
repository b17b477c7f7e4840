// The model cache: key, path, check, store (the bake's file read back -> checked -> renamed), load.
#include "jobs/hlod_model_cache.h"

#include <algorithm>
#include <cstdio>

#include "jobs/hlod_read_failures.h"
#include "runtime/hlod_asset.h"
#include "runtime/lod_asset.h"  // hash_bytes
#include "runtime/regular_file.h"

namespace lod {
namespace {

// The whole file; `opened` false when nothing is there. Anything else unreadable (a folder in
// its place, an I/O error) is a refusal with its reason. The tree is read first (its head
// bounded by the file): the payloads it places must end where the file does before the file
// is read whole.
Status read_file(const std::filesystem::path& path, std::vector<uint8_t>& out, bool& opened) {
  std::error_code ec;
  opened = std::filesystem::exists(std::filesystem::symlink_status(path, ec));
  if (!opened) return Status::error(path.string() + ": does not exist");
  RegularFile f;
  if (Status s = open_regular_file(path, kInputFileLimit, f); !s) return s;
  HlodFile hlod;
  HlodTree tree;
  if (Status s = hlod.open(path, tree); !s) return s;
  uint64_t end = 0;
  for (const HlodNode& n : tree.nodes) end = std::max(end, n.payload_offset + n.payload_size);
  if (end != f.size)
    return Status::error(path.string() + ": its payloads end at " + std::to_string(end) + " of " +
                         std::to_string(f.size) + " bytes");
  return f.read_all(out);
}

}  // namespace

uint64_t hlod_model_key(uint64_t source_hash, const std::string& name) {
  const uint64_t words[4] = {source_hash, kHlodAssetVersion, kHlodModelEntryVersion, hash_bytes(name.data(), name.size())};
  return hash_bytes(words, sizeof words, 0x686d6f64656cull);
}

std::filesystem::path hlod_model_entry_path(const std::filesystem::path& dir, uint64_t key) {
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.hlod", static_cast<unsigned long long>(key));
  return dir / name;
}

Status check_hlod_model(std::span<const uint8_t> bytes, const std::string& name, uint64_t source_hash,
                        const std::string& what, HlodTree* tree) {
  HlodTree t;
  std::vector<HlodPayload> payloads;
  if (Status s = decode_hlod_asset(bytes, what, t, payloads); !s) return s;
  if (t.name != name) return Status::error(what + ": holds model '" + t.name + "', not '" + name + "'");
  if (t.source_hash != source_hash) return Status::error(what + ": was baked from another source (its hash differs)");
  uint64_t end = 0;
  for (const HlodNode& n : t.nodes) end = std::max(end, n.payload_offset + n.payload_size);
  if (end != bytes.size())
    return Status::error(what + ": " + std::to_string(bytes.size() - end) + " bytes after the last payload");
  if (tree) *tree = std::move(t);
  return Status::success();
}

Status store_hlod_model(const std::filesystem::path& dir, uint64_t key, const std::filesystem::path& baked,
                        const std::string& name, uint64_t source_hash, std::vector<uint8_t>& bytes, HlodTree* tree) {
  const std::filesystem::path path = hlod_model_entry_path(dir, key);
  bool opened = false;
  Status st = read_file(baked, bytes, opened);
  if (st) st = check_hlod_model(bytes, name, source_hash, baked.string(), tree);
  std::error_code ec;
  if (!st) {
    std::filesystem::remove(baked, ec);
    return Status::error(path.string() + ": the baked file does not verify: " + st.message);
  }
  std::filesystem::rename(baked, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(baked, ignored);
    return Status::error(path.string() + ": cannot rename the verified entry into place: " + ec.message());
  }
  clear_bad_mark(path);
  return Status::success();
}

CacheLookup load_hlod_model(const std::filesystem::path& dir, uint64_t key, const std::string& name,
                            uint64_t source_hash, std::vector<uint8_t>& bytes, HlodTree* tree, std::string* why) {
  const std::filesystem::path path = hlod_model_entry_path(dir, key);
  bool opened = false;
  std::vector<uint8_t> read;
  Status st = read_file(path, read, opened);
  if (!opened) return CacheLookup::missing;
  // A reader that streamed it found a node damaged since (the check below would too).
  if (std::string bad; st && entry_marked_bad(path, &bad)) st = Status::error(path.string() + ": marked bad: " + bad);
  if (st) st = check_hlod_model(read, name, source_hash, path.string(), tree);
  if (!st) {
    if (why) *why = st.message;
    return CacheLookup::refused;
  }
  bytes = std::move(read);
  return CacheLookup::found;
}

}  // namespace lod
