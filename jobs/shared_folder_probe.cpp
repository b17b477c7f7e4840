#include "jobs/shared_folder_probe.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>

#include "runtime/file_write.h"

namespace lod {

Status place_probes(const std::vector<SharedFolder>& folders, std::string& name) {
  name = ".lod-shared-probe" + unique_temporary_suffix();
  for (const SharedFolder& f : folders) {
    std::error_code ec;
    std::filesystem::create_directories(f.path, ec);
    if (ec) return Status::error(f.path.string() + ": cannot create the " + f.what + ": " + ec.message());
    const std::filesystem::path file = f.path / name;
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) return Status::error(f.path.string() + ": cannot create a file in the " + f.what + ": " + describe_write_errno(errno));
    ::close(fd);
  }
  return Status::success();
}

std::vector<uint8_t> sees_probes(const std::vector<SharedFolder>& folders, const std::string& name) {
  std::vector<uint8_t> seen;
  const bool plain = !name.empty() && name.find('/') == std::string::npos && name != "." && name != "..";
  for (const SharedFolder& f : folders) {
    std::error_code ec;
    seen.push_back(plain && std::filesystem::is_regular_file(f.path / name, ec) ? 1 : 0);
  }
  return seen;
}

std::string unseen_message(const std::vector<SharedFolder>& folders, const std::vector<std::vector<uint8_t>>& answers) {
  std::string message;
  for (size_t k = 0; k < folders.size(); ++k) {
    std::vector<size_t> ranks;
    for (size_t r = 0; r < answers.size(); ++r)
      if (answers[r].size() == folders.size() && answers[r][k] == 0) ranks.push_back(r);
    if (ranks.empty()) continue;
    std::string list;
    for (size_t r : ranks) list += (list.empty() ? "" : ", ") + std::to_string(r);
    if (!message.empty()) message += "; ";
    message += (ranks.size() == 1 ? "rank " + list + " does" : "ranks " + list + " do") + " not see, in its " +
               folders[k].what + ", the file rank 0 made in " + folders[k].path.string();
  }
  if (!message.empty())
    message += " (the cache and output folders must be shared storage, the same folder on every rank's node)";
  return message;
}

void remove_probes(const std::vector<SharedFolder>& folders, const std::string& name) {
  for (const SharedFolder& f : folders) {
    std::error_code ec;
    std::filesystem::remove(f.path / name, ec);
  }
}

}  // namespace lod
