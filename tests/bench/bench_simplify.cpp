// Side-by-side simplification benchmark on real scans: lodkit QEM (both halves in
// parallel, 2 threads), lodkit aggressive (grid clustering), meshopt_simplify,
// meshopt_simplifySloppy and OpenMesh's Decimater (ModQuadric + ModNormalFlipping, through
// preprocess/decimater_chain), all timed in the same run and measured by the same code
// (preprocess/surface_error: symmetric Hausdorff approximation, max and RMS).
//
//   bench_simplify [--csv FILE] [--quick] [--no-big] [--no-openmesh] [--meshes DIR] [--only NAME]
//
// Figures are ratios between peers of the same run; absolute times depend on the machine.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "preprocess/cluster_simplifier.h"
#include "preprocess/decimater_chain.h"
#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "preprocess/qem_simplifier.h"
#include "preprocess/surface_error.h"
#include "test_support.h"

#ifdef LOD_HAVE_MESHOPTIMIZER
#include <meshoptimizer.h>
#endif

namespace {

using lod::ChainLevelOut;
using lod::MeshData;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double process_cpu_seconds() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// CPU seconds (all threads) of the last timed run, next to its wall time.
double g_last_cpu = 0;

// Best of `repeats` wall-clock runs.
double time_best(int repeats, const std::function<void()>& fn) {
  double best = 1e30;
  for (int i = 0; i < repeats; ++i) {
    const double c0 = process_cpu_seconds();
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    const double wall = seconds_since(t0);
    if (wall < best) best = wall, g_last_cpu = process_cpu_seconds() - c0;
  }
  return best;
}

// Best wall time of one method over repeats interleaved with its peers' (so that a neighbour's
// burst on the shared machine hits every method alike), with the CPU seconds of that run.
struct BestOf {
  double wall = 1e30, cpu = 0;
  void run(const std::function<void()>& fn) {
    const double c0 = process_cpu_seconds();
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    const double w = seconds_since(t0);
    if (w < wall) wall = w, cpu = process_cpu_seconds() - c0;
  }
};

const lod::ParallelFor kTwoThreads = [](size_t n, const std::function<void(size_t)>& body) {
  std::vector<std::thread> threads;
  for (size_t i = 1; i < n; ++i) threads.emplace_back(body, i);
  if (n) body(0);
  for (auto& t : threads) t.join();
};

// 1:4 midpoint subdivision (each face into four), for a mesh four times the size.
MeshData subdivide(const MeshData& in) {
  MeshData out;
  out.source = in.source + " (1:4 subdivided)";
  out.positions = in.positions;
  std::unordered_map<uint64_t, uint32_t> mid;
  mid.reserve(in.indices.size());
  auto midpoint = [&](uint32_t a, uint32_t b) {
    const uint64_t key = a < b ? (uint64_t(a) << 32 | b) : (uint64_t(b) << 32 | a);
    auto [it, fresh] = mid.emplace(key, uint32_t(out.positions.size() / 3));
    if (fresh)
      for (int k = 0; k < 3; ++k) out.positions.push_back(0.5f * (in.positions[3 * size_t(a) + k] + in.positions[3 * size_t(b) + k]));
    return it->second;
  };
  out.indices.reserve(4 * in.indices.size());
  for (size_t t = 0; t < in.indices.size(); t += 3) {
    const uint32_t a = in.indices[t], b = in.indices[t + 1], c = in.indices[t + 2];
    const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
    out.indices.insert(out.indices.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
  }
  return out;
}

float diagonal(const MeshData& m) {
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (size_t v = 0; v < m.vertex_count(); ++v)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], m.positions[3 * v + k]), hi[k] = std::max(hi[k], m.positions[3 * v + k]);
  return std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

struct Row {
  std::string mesh, method;
  size_t input = 0;
  double ratio = 0;
  size_t target = 0, achieved = 0;
  double seconds = 0;
  double cpu_seconds = 0;  // all threads
  double max_rel = 0, rms_rel = 0;  // fractions of the bounding-box diagonal
  double mtris_per_s() const { return seconds > 0 ? double(input) / seconds / 1e6 : 0; }
};

struct Bench {
  std::vector<Row> rows;
  lod::SurfaceErrorMeter meter;
  float diag = 1;
  std::string mesh;
  size_t input = 0;

  void add(const std::string& method, double ratio, size_t target, double seconds, const float* positions,
           size_t vertex_count, const uint32_t* indices, size_t index_count) {
    Row r;
    r.mesh = mesh, r.method = method, r.input = input, r.ratio = ratio, r.target = target;
    r.achieved = index_count / 3, r.seconds = seconds, r.cpu_seconds = g_last_cpu;
    // Only the vertices the triangles use: meshoptimizer's results index the whole input, and
    // the meter samples every vertex it is given, so unused input vertices (distance 0) would
    // dilute their RMS.
    std::vector<uint32_t> map(vertex_count, ~0u), idx(index_count);
    std::vector<float> pos;
    for (size_t i = 0; i < index_count; ++i) {
      const uint32_t v = indices[i];
      if (map[v] == ~0u) {
        map[v] = uint32_t(pos.size() / 3);
        pos.insert(pos.end(), positions + 3 * size_t(v), positions + 3 * size_t(v) + 3);
      }
      idx[i] = map[v];
    }
    lod::SurfaceError e;
    const lod::Status s = meter.measure({pos.data(), pos.size() / 3, idx.data(), idx.size()}, e);
    if (s.ok) r.max_rel = e.max / diag, r.rms_rel = e.rms / diag;
    else std::fprintf(stderr, "measure failed: %s\n", s.message.c_str());
    std::printf("%-10s %-17s %7.4f%% target %8zu got %8zu  %7.3f s (cpu %7.3f s) %6.2f Mtri/s  max %.5f%%  rms %.6f%%\n",
                mesh.c_str(), method.c_str(), 100 * ratio, target, r.achieved, seconds, r.cpu_seconds, r.mtris_per_s(),
                100 * r.max_rel, 100 * r.rms_rel);
    std::fflush(stdout);
    rows.push_back(r);
  }
  const Row* find(const std::string& m, const std::string& method, double ratio) const {
    for (const Row& r : rows)
      if (r.mesh == m && r.method == method && r.ratio == ratio) return &r;
    return nullptr;
  }
};

void run_mesh(Bench& b, const std::string& name, const MeshData& mesh, const std::vector<double>& ratios,
              bool openmesh) {
  b.mesh = name;
  b.input = mesh.triangle_count();
  b.diag = diagonal(mesh);
  lod::SurfaceErrorSettings settings;
  settings.surface_samples = 30000;
  lod::Status s = b.meter.set_reference({mesh.positions.data(), mesh.vertex_count(), mesh.indices.data(), mesh.indices.size()},
                                        settings, name);
  if (!s.ok) {
    std::fprintf(stderr, "%s\n", s.message.c_str());
    return;
  }
  const size_t T = mesh.triangle_count();
  // Best of several runs: the machine is shared, and a single run measures the neighbours too.
  const int repeats = T < 200000 ? 9 : T < 2000000 ? 5 : 2;
  std::printf("\n== %s: %zu triangles, %zu vertices\n", name.c_str(), T, mesh.vertex_count());
  std::vector<size_t> targets;
  for (double r : ratios) targets.push_back(size_t(std::llround(r * double(T))));

  // One run for the whole chain (what baking does).
  {
    std::vector<ChainLevelOut> levels(targets.size());
    const double sec = time_best(repeats, [&] {
      lod::qem_simplify_chain_split(levels.data(), mesh.positions.data(), mesh.vertex_count(), mesh.indices.data(),
                                    mesh.indices.size(), targets.data(), targets.size(), {}, kTwoThreads);
    });
    std::printf("%-10s %-16s whole chain of %zu levels in %.3f s (%.2f Mtri/s)\n", name.c_str(), "lodkit-qem-chain",
                targets.size(), sec, double(T) / sec / 1e6);
    Row r;
    r.mesh = name, r.method = "lodkit-qem-chain", r.input = T, r.seconds = sec;
    r.achieved = levels.back().triangle_count(), r.target = targets.back(), r.ratio = 0;
    b.rows.push_back(r);
  }

  for (size_t i = 0; i < ratios.size(); ++i) {
    const double ratio = ratios[i];
    const size_t target = targets[i];
    // The four methods take turns, best of `repeats` each.
    BestOf qem_time, aggressive_time, meshopt_time, sloppy_time;
    ChainLevelOut level;
    std::vector<uint32_t> aggressive_idx(mesh.indices.size());
    std::vector<float> aggressive_pos(mesh.positions.size());
    lod::ClusterResult res;
    std::vector<uint32_t> meshopt_idx(mesh.indices.size()), sloppy_idx(mesh.indices.size());
    size_t meshopt_n = 0, sloppy_n = 0;
    for (int rep = 0; rep < repeats; ++rep) {
      qem_time.run([&] {
        lod::qem_simplify_chain_split(&level, mesh.positions.data(), mesh.vertex_count(), mesh.indices.data(),
                                      mesh.indices.size(), &target, 1, {}, kTwoThreads);
      });
      aggressive_time.run([&] {
        lod::cluster_simplify(aggressive_idx.data(), aggressive_pos.data(), mesh.positions.data(), mesh.vertex_count(),
                              mesh.indices.data(), mesh.indices.size(), target, {}, &res);
      });
#ifdef LOD_HAVE_MESHOPTIMIZER
      meshopt_time.run([&] {
        float err = 0;
        meshopt_n = meshopt_simplify(meshopt_idx.data(), mesh.indices.data(), mesh.indices.size(), mesh.positions.data(),
                                     mesh.vertex_count(), 12, 3 * target, 1.0f, 0, &err);
      });
      sloppy_time.run([&] {
        float err = 0;
        sloppy_n = meshopt_simplifySloppy(sloppy_idx.data(), mesh.indices.data(), mesh.indices.size(),
                                          mesh.positions.data(), mesh.vertex_count(), 12, 3 * target, 1.0f, &err);
      });
#endif
    }
    g_last_cpu = qem_time.cpu;
    b.add("lodkit-qem-2t", ratio, target, qem_time.wall, level.positions.data(), level.positions.size() / 3,
          level.indices.data(), level.indices.size());
    const size_t aggressive_count = res.triangles;
    g_last_cpu = aggressive_time.cpu;
    b.add("lodkit-aggressive", ratio, target, aggressive_time.wall, aggressive_pos.data(), res.vertices,
          aggressive_idx.data(), 3 * res.triangles);
#ifdef LOD_HAVE_MESHOPTIMIZER
    {
      g_last_cpu = meshopt_time.cpu;
      b.add("meshopt", ratio, target, meshopt_time.wall, mesh.positions.data(), mesh.vertex_count(),
            meshopt_idx.data(), meshopt_n);
      if (double(meshopt_n / 3) > 1.02 * double(target)) {
        // meshopt_simplify stopped above the target: compare errors at the count it reached too.
        ChainLevelOut at_count;
        const size_t reached = meshopt_n / 3;
        lod::qem_simplify_chain_split(&at_count, mesh.positions.data(), mesh.vertex_count(), mesh.indices.data(),
                                      mesh.indices.size(), &reached, 1, {}, kTwoThreads);
        b.add("qem@meshopt-count", ratio, reached, 0, at_count.positions.data(), at_count.positions.size() / 3,
              at_count.indices.data(), at_count.indices.size());
      }
    }
    {
      g_last_cpu = sloppy_time.cpu;
      b.add("meshopt-sloppy", ratio, target, sloppy_time.wall, mesh.positions.data(), mesh.vertex_count(),
            sloppy_idx.data(), sloppy_n);
      std::vector<uint32_t> idx(mesh.indices.size());
      size_t n = 0;
      // Sloppy at the count the aggressive one reached, for RMS at equal count. Its grid
      // steps rarely land on that count exactly, so the requests bracket it (one result below,
      // one above) and its RMS there is interpolated (log-log) between the two.
      std::vector<uint32_t> below, above;
      const double want = double(aggressive_count);
      double ask = want;
      for (int tries = 0; tries < 8 && (below.empty() || above.empty()); ++tries) {
        n = meshopt_simplifySloppy(idx.data(), mesh.indices.data(), mesh.indices.size(), mesh.positions.data(),
                                   mesh.vertex_count(), 12, 3 * size_t(ask), 1.0f, nullptr);
        const double got = double(n / 3);
        if (got <= want && (below.empty() || got > double(below.size() / 3))) below.assign(idx.begin(), idx.begin() + n);
        if (got >= want && (above.empty() || got < double(above.size() / 3))) above.assign(idx.begin(), idx.begin() + n);
        if (got == 0 || ask >= double(mesh.triangle_count())) break;
        ask = std::min(double(mesh.triangle_count()), got < want ? ask * std::max(1.01, want / got) : ask * 0.99);
      }
      const Row* lo = nullptr;
      const Row* hi = nullptr;
      if (!below.empty()) {
        b.add("sloppy-below", ratio, aggressive_count, 0, mesh.positions.data(), mesh.vertex_count(), below.data(),
              below.size());
        lo = &b.rows.back();
      }
      if (!above.empty()) {
        b.add("sloppy-above", ratio, aggressive_count, 0, mesh.positions.data(), mesh.vertex_count(), above.data(),
              above.size());
        hi = &b.rows.back();
      }
      if (lo && hi) lo = &b.rows[b.rows.size() - 2];  // the push above may have moved it
      Row r = lo ? *lo : *hi;
      if (lo && hi && hi->achieved > lo->achieved && lo->rms_rel > 0 && hi->rms_rel > 0) {
        const double f = (std::log(want) - std::log(double(lo->achieved))) /
                         (std::log(double(hi->achieved)) - std::log(double(lo->achieved)));
        r.rms_rel = std::exp(std::log(lo->rms_rel) + f * (std::log(hi->rms_rel) - std::log(lo->rms_rel)));
        r.max_rel = std::exp(std::log(lo->max_rel) + f * (std::log(hi->max_rel) - std::log(lo->max_rel)));
        r.achieved = aggressive_count;
      }
      r.method = "sloppy@aggr-count";
      r.seconds = r.cpu_seconds = 0;  // not a timed run
      b.rows.push_back(r);
    }
#endif
  }

  if (openmesh) {
    // Debian's OpenMesh has its asserts on: one chain run, on small meshes only.
    std::vector<float> om_ratios = {1.0f};
    for (double r : ratios) om_ratios.push_back(float(r));
    std::vector<lod::ChainLevel> levels;
    lod::DecimaterChainStats stats;
    const auto t0 = std::chrono::steady_clock::now();
    s = lod::bake_decimater_chain(mesh, om_ratios, levels, &stats, nullptr);
    const double sec = seconds_since(t0);
    if (!s.ok) {
      std::fprintf(stderr, "openmesh: %s\n", s.message.c_str());
      return;
    }
    std::printf("%-10s %-16s whole chain of %zu levels in %.3f s (%.3f Mtri/s)\n", name.c_str(), "openmesh-chain",
                ratios.size(), sec, double(T) / sec / 1e6);
    Row r;
    r.mesh = name, r.method = "openmesh-chain", r.input = T, r.seconds = sec;
    r.achieved = levels.back().triangle_count(), r.target = targets.back(), r.ratio = 0;
    b.rows.push_back(r);
    for (size_t i = 1; i < levels.size(); ++i)
      b.add("openmesh(chain)", ratios[i - 1], targets[i - 1], 0, levels[i].positions.data(), levels[i].vertex_count(),
            levels[i].indices.data(), levels[i].indices.size());
  }
}

// One panel per mesh: RMS error (log, % of the diagonal) against ratio (log), one line per
// method, so the CSV has a picture next to it.
void write_plot(const std::string& path, const std::vector<Row>& rows) {
  const char* methods[] = {"lodkit-qem-2t", "lodkit-aggressive", "meshopt", "meshopt-sloppy"};
  const char* colours[] = {"#1f77b4", "#2ca02c", "#d62728", "#ff7f0e"};
  std::vector<std::string> meshes;
  for (const Row& r : rows)
    if (r.ratio > 0 && std::find(meshes.begin(), meshes.end(), r.mesh) == meshes.end()) meshes.push_back(r.mesh);
  const double w = 520, h = 260, left = 60, top = 30;
  std::ofstream out(path);
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << w << "' height='" << h * double(meshes.size()) + 40
      << "' font-family='sans-serif' font-size='11'>\n<rect width='100%' height='100%' fill='white'/>\n";
  for (size_t i = 0; i < 4; ++i)
    out << "<text x='" << left + 110 * double(i) << "' y='16' fill='" << colours[i] << "'>" << methods[i] << "</text>\n";
  for (size_t m = 0; m < meshes.size(); ++m) {
    double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
    for (const Row& r : rows) {
      if (r.mesh != meshes[m] || r.ratio <= 0 || r.rms_rel <= 0) continue;
      x0 = std::min(x0, std::log10(r.ratio)), x1 = std::max(x1, std::log10(r.ratio));
      y0 = std::min(y0, std::log10(r.rms_rel)), y1 = std::max(y1, std::log10(r.rms_rel));
    }
    if (x1 <= x0) x1 = x0 + 1;
    if (y1 <= y0) y1 = y0 + 1;
    const double oy = top + h * double(m), pw = w - left - 20, ph = h - 60;
    auto px = [&](double r) { return left + (std::log10(r) - x0) / (x1 - x0) * pw; };
    auto py = [&](double e) { return oy + 10 + (y1 - std::log10(e)) / (y1 - y0) * ph; };
    out << "<text x='" << left << "' y='" << oy + 5 << "'>" << meshes[m]
        << ": RMS distance (% of diagonal, log) vs ratio (log)</text>\n";
    out << "<rect x='" << left << "' y='" << oy + 10 << "' width='" << pw << "' height='" << ph
        << "' fill='none' stroke='#999'/>\n";
    for (size_t k = 0; k < 4; ++k) {
      std::string pts;
      for (const Row& r : rows)
        if (r.mesh == meshes[m] && r.method == methods[k] && r.ratio > 0 && r.rms_rel > 0) {
          pts += std::to_string(px(r.ratio)) + "," + std::to_string(py(r.rms_rel)) + " ";
          out << "<circle cx='" << px(r.ratio) << "' cy='" << py(r.rms_rel) << "' r='2.5' fill='" << colours[k] << "'/>\n";
        }
      out << "<polyline points='" << pts << "' fill='none' stroke='" << colours[k] << "'/>\n";
    }
    for (const Row& r : rows)
      if (r.mesh == meshes[m] && r.method == methods[0] && r.ratio > 0) {
        char label[32];
        std::snprintf(label, sizeof label, "%g%%", 100 * r.ratio);
        out << "<text x='" << px(r.ratio) - 10 << "' y='" << oy + 25 + ph << "'>" << label << "</text>\n";
      }
    char lo[32], hi[32];
    std::snprintf(lo, sizeof lo, "%.2g", 100 * std::pow(10.0, y0));
    std::snprintf(hi, sizeof hi, "%.2g", 100 * std::pow(10.0, y1));
    out << "<text x='4' y='" << oy + 20 << "'>" << hi << "</text><text x='4' y='" << oy + 10 + ph << "'>" << lo
        << "</text>\n";
  }
  out << "</svg>\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string csv = "bench_simplify.csv";
  bool quick = false, big = true, openmesh = true;
  std::string only;
  std::filesystem::path dir = lod::test::shared_meshes();
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--csv" && i + 1 < argc) csv = argv[++i];
    else if (a == "--quick") quick = true;
    else if (a == "--no-big") big = false;
    else if (a == "--no-openmesh") openmesh = false;
    else if (a == "--meshes" && i + 1 < argc) dir = argv[++i];
    else if (a == "--only" && i + 1 < argc) only = argv[++i];
    else {
      std::fprintf(stderr,
                   "usage: bench_simplify [--csv FILE] [--quick] [--no-big] [--no-openmesh] [--meshes DIR] [--only NAME]\n");
      return 2;
    }
  }
  if (dir.empty()) {
    std::fprintf(stderr, "no mesh directory (../shared/data/meshes absent; pass --meshes DIR)\n");
    return 0;
  }
#ifndef LOD_HAVE_MESHOPTIMIZER
  std::printf("meshoptimizer not found at configure time: its columns are skipped\n");
#endif
  // The reference's ratios (Yu, Liang and Chen): bunny-sized 50..3 %, large scans 25..0.18 %; 50 % and 1.5 %
  // everywhere so the QEM error criterion (50 % .. 1.5 %) is covered on every mesh.
  const std::vector<double> small = {0.5, 0.25, 0.12, 0.06, 0.03, 0.015};
  const std::vector<double> large = {0.5, 0.25, 0.12, 0.06, 0.03, 0.015, 0.0075, 0.0037, 0.0018};
  const std::vector<double> huge = {0.25, 0.03, 0.0018};
  struct Entry {
    const char* name;
    const char* file;
  };
  std::vector<Entry> meshes = {{"bunny", "stanford-bunny.obj"},
                               {"armadillo", "stanford-armadillo-100k.obj"},
                               {"buddha", "happy-buddha-res3.ply"},
                               {"dragon", "stanford-dragon.ply"}};
  if (quick) meshes = {{"bunny", "stanford-bunny.obj"}, {"dragon", "stanford-dragon.ply"}};
  Bench b;
  MeshData dragon;
  for (const Entry& e : meshes) {
    // --only dragon-x4 still loads the dragon it is made from.
    if (!only.empty() && only != e.name && !(only == "dragon-x4" && std::string(e.name) == "dragon")) continue;
    const auto path = dir / e.file;
    if (!std::filesystem::exists(path)) {
      std::printf("skip %s: %s absent\n", e.name, path.c_str());
      continue;
    }
    MeshData mesh;
    const lod::Status s = lod::load_mesh(path, mesh);
    if (!s.ok) {
      std::printf("skip %s: %s\n", e.name, s.message.c_str());
      continue;
    }
    lod::clean_mesh(mesh);
    const bool is_large = mesh.triangle_count() >= 300000;
    if (only != "dragon-x4")
      run_mesh(b, e.name, mesh, is_large ? large : small, openmesh && mesh.triangle_count() <= 100000);
    if (std::string(e.name) == "dragon") dragon = std::move(mesh);
  }
  if (big && !quick && dragon.triangle_count() && (only.empty() || only == "dragon-x4")) {
    const MeshData x4 = subdivide(dragon);
    dragon = MeshData{};
    run_mesh(b, "dragon-x4", x4, huge, false);
  }

  std::ofstream out(csv);
  out << "mesh,method,input_triangles,ratio,target,achieved,seconds,cpu_seconds,input_mtris_per_s,max_rel_diag,"
         "rms_rel_diag\n";
  for (const Row& r : b.rows)
    out << r.mesh << ',' << r.method << ',' << r.input << ',' << r.ratio << ',' << r.target << ',' << r.achieved << ','
        << r.seconds << ',' << r.cpu_seconds << ',' << r.mtris_per_s() << ',' << r.max_rel << ',' << r.rms_rel << '\n';
  const std::string svg = csv.size() > 4 && csv.substr(csv.size() - 4) == ".csv" ? csv.substr(0, csv.size() - 4) + ".svg"
                                                                                 : csv + ".svg";
  write_plot(svg, b.rows);
  std::printf("\nwrote %s and %s\n", csv.c_str(), svg.c_str());

#ifdef LOD_HAVE_MESHOPTIMIZER
  // The figures, as ratios of the same run.
  std::printf("\n%-10s %8s | %9s %9s %9s %9s  | %9s %9s %9s\n", "mesh", "ratio", "qem/mo t", "cpu/cpu", "rms/mo",
              "max/mo", "aggr/sl t", "rms/sl@n", "count%");
  for (const Row& q : b.rows) {
    if (q.method != "lodkit-qem-2t") continue;
    const Row* mo = b.find(q.mesh, "meshopt", q.ratio);
    const Row* ag = b.find(q.mesh, "lodkit-aggressive", q.ratio);
    const Row* sl = b.find(q.mesh, "meshopt-sloppy", q.ratio);
    const Row* sn = b.find(q.mesh, "sloppy@aggr-count", q.ratio);
    if (!mo || !ag || !sl || !sn) continue;
    // Where meshopt stopped above the target, its errors are compared with QEM at its count.
    const Row* qe = b.find(q.mesh, "qem@meshopt-count", q.ratio);
    const Row& qm = qe ? *qe : q;
    std::printf("%-10s %7.3f%% | %9.2f %9.2f %9.2f %9.2f%s | %9.2f %9.2f %+8.1f%%\n", q.mesh.c_str(), 100 * q.ratio,
                mo->seconds / q.seconds, q.cpu_seconds > 0 ? mo->cpu_seconds / q.cpu_seconds : 0,
                mo->rms_rel > 0 ? qm.rms_rel / mo->rms_rel : 0, mo->max_rel > 0 ? qm.max_rel / mo->max_rel : 0,
                qe ? "*" : " ", sl->seconds / ag->seconds, sn->rms_rel > 0 ? ag->rms_rel / sn->rms_rel : 0,
                100.0 * (double(q.achieved) - double(q.target)) / double(std::max<size_t>(q.target, 1)));
  }
  for (const Row& c : b.rows) {
    if (c.method != "openmesh-chain") continue;
    for (const Row& q : b.rows)
      if (q.mesh == c.mesh && q.method == "lodkit-qem-chain")
        std::printf("%-10s chain: lodkit QEM %.3f s vs OpenMesh Decimater %.3f s = %.1fx\n", c.mesh.c_str(), q.seconds,
                    c.seconds, c.seconds / q.seconds);
  }
  std::printf("(qem/mo t: meshopt_simplify wall time / lodkit QEM (2 threads) wall time, >= 1 is faster; cpu/cpu:\n"
              " the same with CPU seconds summed over threads, i.e. per-core efficiency; rms/mo, max/mo: error ratios,\n"
              " <= 1 is better; aggr/sl t: sloppy time / aggressive time; rms/sl@n: aggressive RMS / sloppy RMS at\n"
              " the aggressive count, interpolated between sloppy results just below and above it; count%%: QEM\n"
              " achieved vs target; *: meshopt stopped above the target, errors compared with QEM at the count\n"
              " meshopt reached)\n");
#endif
  return 0;
}
