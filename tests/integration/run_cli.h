// What the end-to-end tests share: running the `lod` binary of this build (or any command)
// with its exit code and combined output, reading the JSON it writes, and the TOML blocks their
// generated scenes are made of.
#pragma once
#include <sys/wait.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "test_support.h"

namespace lod::test {

struct CliResult {
  int code = -1;
  std::string out;  // stdout + stderr
};

// A shell command; stderr is folded into the output.
inline CliResult run_shell(const std::string& cmd) {
  CliResult r;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline CliResult run_lod(const std::string& args) { return run_shell(std::string(LOD_CLI_PATH) + " " + args); }

#if defined(LOD_BAKE_MPI_PATH) && defined(LOD_MPIEXEC)
// lod-bake-mpi on `ranks` ranks. Root may run mpirun here (containers, CI); loopback only; more
// ranks than cores is fine. Under AddressSanitizer, OpenMPI's own allocations at exit are not
// reported as leaks.
inline CliResult run_mpi_program(int ranks, const std::string& program, const std::string& args,
                                 const std::string& env = "") {
  return run_shell("env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 "
                   "ASAN_OPTIONS=\"${ASAN_OPTIONS:-}:detect_leaks=0\" " +
                   env + " " LOD_MPIEXEC " --oversubscribe --mca btl self,vader,tcp --mca btl_tcp_if_include lo" +
                   " --mca oob_tcp_if_include lo -np " + std::to_string(ranks) + " " + program + " " + args);
}
inline CliResult run_mpi(int ranks, const std::string& args, const std::string& env = "") {
  return run_mpi_program(ranks, LOD_BAKE_MPI_PATH, args, env);
}
#endif

// The JSON object a command printed after its other output (`--json` to stdout: the first
// line that is "{" to the last "}"); null when there is none or it does not parse.
inline nlohmann::json printed_json(const CliResult& r) {
  const size_t at = r.out.find("{\n");
  if (at == std::string::npos) return {};
  return nlohmann::json::parse(r.out.substr(at, r.out.rfind('}') + 1 - at), nullptr, false);
}

inline nlohmann::json read_json(const std::filesystem::path& p) {
  std::ifstream f(p);
  return nlohmann::json::parse(f);
}

// `lod run --config CFG --quiet --cache DIR/cache --json DIR/run.json FLAGS`.
inline CliResult run_scene(const std::filesystem::path& cfg, const std::filesystem::path& dir,
                           const std::string& flags = "") {
  return run_lod("run --config " + cfg.string() + " --quiet --cache " + (dir / "cache").string() + " --json " +
                 (dir / "run.json").string() + (flags.empty() ? "" : " " + flags));
}

// ---- TOML blocks; each ends with a blank line ----

inline std::string run_block(uint32_t frames, uint32_t threads = 2) {
  return "[run]\nframes = " + std::to_string(frames) + "\nthreads = " + std::to_string(threads) + "\n\n";
}

// [budget] triangles = M, then `more` lines of the table.
inline std::string budget_block(uint64_t triangles, const std::string& more = "") {
  return "[budget]\n" + more + "triangles = " + std::to_string(triangles) + "\n\n";
}

struct Orbit {
  double radius = 120, height_above = 10;
  uint32_t period_frames = 24, width = 640, height = 360;
};

// A camera circling the origin.
inline std::string orbit_camera_block(const Orbit& o) {
  return "[camera]\npath = \"orbit\"\ncenter = [0, 0, 0]\nradius = " + std::to_string(o.radius) +
         "\nheight_above = " + std::to_string(o.height_above) + "\nperiod_frames = " + std::to_string(o.period_frames) +
         "\nwidth = " + std::to_string(o.width) + "\nheight = " + std::to_string(o.height) + "\n\n";
}

struct Keyframe {
  uint32_t frame;
  std::string position, look_at;  // TOML arrays, "[x, y, z]"
};

// A camera flying between keyframes; far = 0 keeps the default far plane.
inline std::string keyframe_camera_block(double near_plane, double far_plane, const std::vector<Keyframe>& keys) {
  std::string s = "[camera]\npath = \"keyframes\"\nnear = " + std::to_string(near_plane) + "\n";
  if (far_plane > 0) s += "far = " + std::to_string(far_plane) + "\n";
  for (const Keyframe& k : keys)
    s += "\n[[camera.keyframe]]\nframe = " + std::to_string(k.frame) + "\nposition = " + k.position +
         "\nlook_at = " + k.look_at + "\n";
  return s + "\n";
}

// [[model]]; ratios "" keeps the default chain, `more` adds lines.
inline std::string model_block(const std::string& name, const std::string& file, const std::string& ratios = "",
                               const std::string& more = "") {
  std::string s = "[[model]]\nname = \"" + name + "\"\nfile = \"" + file + "\"\n";
  if (!ratios.empty()) s += "ratios = " + ratios + "\n";
  return s + more + "\n";
}

// [[instances]] of a model scattered over the square [-half, half] x [-half, half] (y = 0).
inline std::string scattered_block(const std::string& model, uint32_t count, double half, const std::string& more = "") {
  const std::string h = std::to_string(half);
  return "[[instances]]\nmodel = \"" + model + "\"\ncount = " + std::to_string(count) + "\nbox_min = [-" + h +
         ", 0, -" + h + "]\nbox_max = [" + h + ", 0, " + h + "]\n" + more + "\n";
}

// One instance of a model at a point (a grid of one), scaled.
inline std::string single_block(const std::string& model, const std::string& at, double scale) {
  return "[[instances]]\nmodel = \"" + model + "\"\ncount = 1\nplacement = \"grid\"\nbox_min = " + at +
         "\nbox_max = " + at + "\nscale = " + std::to_string(scale) + "\n\n";
}

// 300 balls (6,240 triangles at full detail) scattered over 200 x 200 m and a grid of 100
// pebbles (528) under an orbiting camera, 24 frames; `extra` TOML tables come first.
inline std::filesystem::path balls_and_pebbles(const std::filesystem::path& dir, uint64_t budget,
                                               const std::string& ball_ratios, const std::string& pebble_ratios = "",
                                               const std::string& extra = "") {
  write_text(dir / "ball.off", sphere_off(40, 80));
  write_text(dir / "pebble.off", sphere_off(12, 24));
  const auto cfg = dir / "scene.toml";
  write_text(cfg, extra + run_block(24) + budget_block(budget) + orbit_camera_block({}) +
                      model_block("ball", "ball.off", ball_ratios) + model_block("pebble", "pebble.off", pebble_ratios) +
                      scattered_block("ball", 300, 100, "scale_range = [1.0, 3.0]\nseed = 7\n") +
                      scattered_block("pebble", 100, 50, "placement = \"grid\"\nscale = 2.0\n"));
  return cfg;
}

}  // namespace lod::test
