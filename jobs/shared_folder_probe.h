// Whether every rank of a distributed bake sees the same folders: the cache and the output
// must be shared storage. A rank on a node-local path would bake into a cache rank 0 never
// reads (rank 0 then bakes its share again) or write its part of the .hlod where nobody
// looks; checked before any work, the job fails at once naming the rank and the folder.
//
//   rank 0        place_probes: one empty file of its own in each of its folders
//   broadcast     the file's name -> every rank: sees_probes in its own folders
//   gather        the answers -> rank 0: unseen_message, remove_probes
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "runtime/status.h"

namespace lod {

struct SharedFolder {
  std::string what;  // "cache folder", for messages
  std::filesystem::path path;
};

// Rank 0: creates each folder (if missing) and an empty file named `name` (unique to this call)
// in it; fails naming the folder it could not write.
Status place_probes(const std::vector<SharedFolder>& folders, std::string& name);

// One byte per folder: 1 when the probe file `name` is there (a name with a '/' is never).
std::vector<uint8_t> sees_probes(const std::vector<SharedFolder>& folders, const std::string& name);

// Rank 0, over every rank's sees_probes answer (by rank; an answer of another size: that rank
// could not look, and says why itself): which ranks miss which folder's probe, or "".
std::string unseen_message(const std::vector<SharedFolder>& folders, const std::vector<std::vector<uint8_t>>& answers);

void remove_probes(const std::vector<SharedFolder>& folders, const std::string& name);

}  // namespace lod
