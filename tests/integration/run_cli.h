// Runs the `lod` binary of this build with arguments; its exit code and combined output.
#pragma once
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace lod::test {

struct CliResult {
  int code = -1;
  std::string out;  // stdout + stderr
};

inline CliResult run_lod(const std::string& args) {
  const std::string cmd = std::string(LOD_CLI_PATH) + " " + args + " 2>&1";
  CliResult r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace lod::test
