// Failed HLOD node reads: the message, the mark on a cache entry.
#include "jobs/hlod_read_failures.h"

#include <mutex>
#include <vector>

#include "runtime/file_write.h"
#include "runtime/hlod_asset.h"
#include "runtime/regular_file.h"

namespace lod {

std::filesystem::path bad_mark_path(const std::filesystem::path& entry) {
  std::filesystem::path mark = entry;
  mark += ".bad";
  return mark;
}

Status mark_entry_bad(const std::filesystem::path& entry, const std::string& why) {
  return write_file_atomic(bad_mark_path(entry), why + "\n");
}

bool entry_marked_bad(const std::filesystem::path& entry, std::string* why) {
  const std::filesystem::path mark = bad_mark_path(entry);
  std::error_code ec;
  if (!std::filesystem::exists(std::filesystem::symlink_status(mark, ec))) return false;
  if (why) {
    // The reason is for messages only: its first few hundred bytes, from a regular file.
    why->clear();
    RegularFile f;
    std::vector<uint8_t> head;
    if (open_regular_file(mark, kConfigFileLimit, f) && f.read_head(512, head)) why->assign(head.begin(), head.end());
    while (!why->empty() && (why->back() == '\n' || why->back() == '\r')) why->pop_back();
    if (why->empty()) *why = "no reason recorded";
  }
  return true;
}

void clear_bad_mark(const std::filesystem::path& entry) {
  std::error_code ec;
  std::filesystem::remove(bad_mark_path(entry), ec);
}

namespace {

// Per model: marked once (the first failure), then every failure of it says how that went.
struct EntryMarks {
  explicit EntryMarks(size_t n) : once(n), note(n) {}
  std::vector<std::once_flag> once;
  std::vector<std::string> note;  // written inside its call_once, read after it
};

}  // namespace

ModelNodeLoader marking_bad_entries(std::shared_ptr<const HlodModels> models, ModelNodeLoader read) {
  if (!read)
    read = [models](uint32_t model, uint32_t node, HlodPayload& out) {
      return read_hlod_node(models->files[model], node, models->trees[model].nodes[node], out);
    };
  auto marks = std::make_shared<EntryMarks>(models->trees.size());
  return [models, read = std::move(read), marks](uint32_t model, uint32_t node, HlodPayload& out) {
    Status st = read(model, node, out);
    if (st || model >= models->cache_entry.size() || !models->cache_entry[model]) return st;
    const std::filesystem::path& file = models->files[model];
    std::call_once(marks->once[model], [&] {
      const Status marked = mark_entry_bad(file, hlod_failure_message(*models, model, node, st.message));
      marks->note[model] = marked ? "; the cache entry is marked bad, the next run rebakes it"
                                  : "; cannot mark the cache entry bad: " + marked.message;
    });
    st.message += marks->note[model];
    return st;
  };
}

std::string hlod_failure_message(const HlodModels& models, uint32_t model, uint32_t node, const std::string& why) {
  const std::string file = model < models.files.size() && !models.files[model].empty()
                               ? models.files[model].string()
                               : model < models.names.size() ? "hlod model " + models.names[model]
                                                             : "hlod model " + std::to_string(model);
  if (why.size() > file.size() && why.compare(0, file.size(), file) == 0 && why[file.size()] == ':') return why;
  return file + ": node " + std::to_string(node) + ": " + why;
}

}  // namespace lod
