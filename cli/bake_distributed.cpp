// lod bake --hlod --distributed: the `lod bake` spelling of the MPI bake,
//   mpirun -np N lod bake MESH... -o DIR --hlod --distributed [--cache C] [--subtrees S] ...
// Each rank becomes lod-bake-mpi (the executable beside this one) by exec: same pid, so mpirun's
// rank is the same process and MPI_Init happens there; `lod` itself never links MPI.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/names.h"

namespace lod::cli {
namespace {

namespace fs = std::filesystem;

// What --distributed cannot honour, said before any rank starts.
const char* refused(const BakeArgs& args) {
  if (!args.hlod) return "--distributed bakes .hlod trees: add --hlod";
  if (!args.ratios.empty() || args.method != "auto") return "--ratios and --method do not apply to --hlod";
  if (args.measure) return "--measure does not apply to --hlod (its errors are measured and stored in the file)";
  return nullptr;
}

// lod-bake-mpi next to this executable (build/ and an installed bin/ alike); empty when absent.
fs::path sibling_bake_mpi() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path tool = self.parent_path() / "lod-bake-mpi";
  return fs::is_regular_file(tool, ec) && ::access(tool.c_str(), X_OK) == 0 ? tool : fs::path();
}

std::vector<std::string> bake_mpi_arguments(const fs::path& tool, const BakeArgs& args) {
  std::vector<std::string> v{tool.string()};
  v.insert(v.end(), args.models.begin(), args.models.end());
  v.insert(v.end(), {"-o", args.out_dir, "--cache", distributed_cache_dir(args), "--min-verts",
                     std::to_string(args.min_verts), "--threads", std::to_string(args.threads)});
  if (args.subtrees) v.insert(v.end(), {"--subtrees", std::to_string(args.subtrees)});
  if (args.entry_memory_mb) v.insert(v.end(), {"--entry-memory-mb", std::to_string(args.entry_memory_mb)});
  if (!args.mesh_copies.empty()) v.insert(v.end(), {"--mesh-copies", args.mesh_copies});
  if (args.json) v.push_back("--json");
  if (args.quiet) v.push_back("--quiet");
  return v;
}

}  // namespace

std::string distributed_cache_dir(const BakeArgs& args) {
  return args.cache_dir.empty() ? (fs::path(args.out_dir) / "hlod-cache").string() : args.cache_dir;
}

int bake_distributed_command(const BakeArgs& args) {
  if (const char* why = refused(args)) {
    std::fprintf(stderr, "lod bake: %s\n", why);
    return 1;
  }
  const fs::path tool = sibling_bake_mpi();
  if (tool.empty()) {
    std::fprintf(stderr, "lod bake: --distributed runs lod-bake-mpi, which is not beside this lod (built without "
                         "MPI: run scripts/install-deps.sh, which installs OpenMPI, and build again)\n");
    return 1;
  }
  const std::vector<std::string> words = bake_mpi_arguments(tool, args);
  std::vector<char*> argv;
  for (const std::string& w : words) argv.push_back(const_cast<char*>(w.c_str()));
  argv.push_back(nullptr);
  std::fflush(nullptr);
  ::execv(tool.c_str(), argv.data());
  const int e = errno;
  std::fprintf(stderr, "lod bake: cannot start %s (%s)\n", printable(tool.string()).c_str(), std::strerror(e));
  return 1;
}

}  // namespace lod::cli
