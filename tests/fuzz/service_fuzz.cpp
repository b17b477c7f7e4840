// libFuzzer target for the service itself, through the public C API only (include/lodkit/
// lodkit.h), built by scripts/fuzz.sh. Each input is a scene config variant (selector, budget
// count, strict mode, thread count) followed by a sequence of operations a host might issue:
// objects created, destroyed, moved and given options; views that look anywhere, away from
// everything included; budgets, pixel errors, hysteresis and blend times of any value; commits,
// steps, and frames acquired, held across steps and released.
//
// Seeds: scripts/fuzz.sh runs this binary with LOD_FUZZ_WRITE_SEEDS=DIR first; it writes, in the
// operation encoding below, a few runs a host would make (a crowd under a binding budget
// watched by a moving camera, objects coming and going) and exits. Mutation takes them from
// there: anywhere else the camera may turn, any value a setter may get.
//
// Checks beyond the sanitizers, on every frame: its tick is the last commit's; it counts the
// live objects of that commit; every entry names a live object of it, once, with the transform
// that commit gave it, a level of its chain and a blend weight in [0, 1]; its triangles are the
// sum of its entries' levels; and a triangle budget holds unless even the coarsest levels
// exceed it.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include <unistd.h>

#include "lodkit/lodkit.h"

namespace {

namespace fs = std::filesystem;

[[noreturn]] void violated(const char* what, uint64_t a = 0, uint64_t b = 0) {
  std::fprintf(stderr, "frame invariant violated: %s (%llu, %llu)\n", what, (unsigned long long)a,
               (unsigned long long)b);
  std::abort();
}

// A closed UV sphere of `rings` x `segments` quads (poles as fans) written as OFF.
void write_sphere(const fs::path& path, int rings, int segments, float squash) {
  std::ofstream out(path);
  const int vertices = 2 + (rings - 1) * segments;
  const int faces = 2 * segments * (rings - 1);
  out << "OFF\n" << vertices << ' ' << faces << " 0\n";
  out << "0 " << squash << " 0\n0 " << -squash << " 0\n";
  for (int r = 1; r < rings; ++r) {
    const double phi = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double theta = 2 * M_PI * s / segments;
      out << std::sin(phi) * std::cos(theta) << ' ' << squash * std::cos(phi) << ' ' << std::sin(phi) * std::sin(theta)
          << '\n';
    }
  }
  const auto at = [&](int r, int s) { return 2 + (r - 1) * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) out << "3 0 " << at(1, s + 1) << ' ' << at(1, s) << '\n';
  for (int r = 1; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      out << "3 " << at(r, s) << ' ' << at(r, s + 1) << ' ' << at(r + 1, s) << '\n';
      out << "3 " << at(r, s + 1) << ' ' << at(r + 1, s + 1) << ' ' << at(r + 1, s) << '\n';
    }
  for (int s = 0; s < segments; ++s) out << "3 1 " << at(rings - 1, s) << ' ' << at(rings - 1, s + 1) << '\n';
}

struct Fixture {
  fs::path dir;
  std::vector<fs::path> configs;  // indexed by the input's first byte
  std::vector<fs::path> meshes;
};

Fixture make_fixture() {
  Fixture f;
  f.dir = fs::temp_directory_path() / ("lodkit-service-fuzz-" + std::to_string(::getpid()));
  fs::create_directories(f.dir);
  ::setenv("LOD_CACHE_DIR", (f.dir / "cache").c_str(), 1);  // baked once, loaded by every input
  f.meshes = {f.dir / "ball.off", f.dir / "lens.off"};
  write_sphere(f.meshes[0], 24, 40, 1.0f);  // 1,840 triangles
  write_sphere(f.meshes[1], 10, 16, 0.3f);  // 288 triangles
  const char* selectors[] = {"greedy", "greedy_multi", "benefit_cost"};
  const char* counts[] = {"triangles", "levels"};
  for (const char* selector : selectors)
    for (const char* count : counts)
      for (int strict = 0; strict < (std::strcmp(count, "triangles") == 0 ? 2 : 1); ++strict)  // strict counts blends in triangles
        for (int threads = 1; threads <= 2; ++threads) {
          const fs::path path = f.dir / (std::string(selector) + "-" + count + "-" + std::to_string(strict) + "-" +
                                         std::to_string(threads) + ".toml");
          std::ofstream(path) << "[run]\nthreads = " << threads << "\n\n[budget]\ntriangles = 20000\ncount = \""
                              << count << "\"\nselector = \"" << selector << "\"\nstrict = "
                              << (strict ? "true" : "false") << "\n";
          f.configs.push_back(path);
        }
  return f;
}

const Fixture& fixture() {
  static const Fixture f = make_fixture();
  // Registered after f is built, so it runs before f is destroyed.
  static const int cleanup = std::atexit([] {
    std::error_code ec;
    fs::remove_all(fixture().dir, ec);
  });
  (void)cleanup;
  return f;
}

// Reads the input as a stream of small values; past its end every read gives 0.
class Bytes {
 public:
  Bytes(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  bool done() const { return at_ >= size_; }
  uint8_t u8() { return at_ < size_ ? data_[at_++] : 0; }
  uint32_t u32() {
    uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v = v << 8 | u8();
    return v;
  }
  // A float that is usually ordinary and sometimes hostile: from a table of edge values, a
  // small grid, or raw bits.
  float number(float scale) {
    static const float kEdges[] = {0.0f, -0.0f, 1.0f, -1.0f, 1e-20f, -1e-20f, 1e20f, -1e20f, 1e-3f, 179.9f, 180.0f,
                                   360.0f, NAN, INFINITY, -INFINITY, 3.4e38f};
    const uint8_t kind = u8();
    if (kind < 16) return kEdges[kind];
    if (kind < 32) {
      float raw;
      const uint32_t bits = u32();
      std::memcpy(&raw, &bits, 4);
      return raw;
    }
    return (float(kind - 32) / 223.0f * 2.0f - 1.0f) * scale + float(int8_t(u8())) * scale / 64.0f;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
};

struct Object {
  lod_model model = 0;
  lod_transform transform{};
};

// What the host has told the service: objects as staged, and as of the last commit.
struct Host {
  lod_service* service = nullptr;
  std::vector<lod_model> models;
  std::vector<uint32_t> level_counts;
  std::map<lod_object, Object> staged, committed;
  std::vector<lod_object> ever;  // every handle handed out, destroyed ones too (stale handles)
  uint64_t tick = 0;
  bool committed_once = false;
  bool triangle_budget = true;
  std::vector<const lod_frame*> held;
};

lod_transform read_transform(Bytes& in) {
  lod_transform t{};
  for (float& p : t.position) p = in.u8() < 224 ? float(int8_t(in.u8())) / 4.0f : in.number(200.0f);
  const uint8_t rot = in.u8();
  if (rot < 128) {
    t.rotation[3] = 1.0f;
  } else {
    for (float& q : t.rotation) q = in.number(1.0f);
  }
  t.scale = in.u8() < 240 ? 0.05f + float(in.u8()) / 16.0f : in.number(10.0f);
  return t;
}

lod_view read_view(Bytes& in) {
  lod_view v{};
  for (float& e : v.eye) e = in.number(300.0f);
  const uint8_t look = in.u8();
  if (look < 64) {  // at the scene
    v.forward[0] = -v.eye[0], v.forward[1] = -v.eye[1], v.forward[2] = -v.eye[2];
  } else if (look < 96) {  // at the sky
    v.forward[1] = 1.0f;
  } else {
    for (float& d : v.forward) d = in.number(1.0f);
  }
  v.up[1] = 1.0f;
  if (in.u8() > 200)
    for (float& u : v.up) u = in.number(1.0f);
  const uint8_t fov = in.u8();
  v.fov_y_deg = fov < 200 ? 10.0f + float(fov) * 0.8f : in.number(180.0f);
  v.width = in.u8() < 240 ? 64u + in.u8() * 8u : in.u32();
  v.height = in.u8() < 240 ? 64u + in.u8() * 8u : in.u32();
  v.near_z = in.u8() < 240 ? 0.1f : in.number(10.0f);
  v.far_z = in.u8() < 240 ? 5000.0f : in.number(5000.0f);
  return v;
}

lod_object pick_handle(Host& h, Bytes& in) {
  if (h.ever.empty()) return in.u32();
  const uint8_t k = in.u8();
  if (k == 255) return in.u32();  // unknown
  return h.ever[k % h.ever.size()];
}

void release_held(Host& h, size_t keep) {
  while (h.held.size() > keep) {
    lod_frame_release(h.service, h.held.front());
    h.held.erase(h.held.begin());
  }
}

void check_frame(const Host& h, const lod_frame* frame) {
  lod_frame_info info;
  lod_frame_info_get(frame, &info);
  if (info.tick != h.tick) violated("frame tick is not the last commit's", info.tick, h.tick);
  if (info.objects != h.committed.size()) violated("live objects at the frame's tick", info.objects, h.committed.size());
  if (info.visible > info.objects) violated("more entries than objects", info.visible, info.objects);
  uint64_t triangles = 0;
  std::map<lod_object, int> seen;
  for (uint32_t i = 0; i < info.visible; ++i) {
    lod_frame_entry e;
    if (lod_frame_entry_get(frame, i, &e) != 0) violated("an entry below `visible` is refused", i, info.visible);
    const auto it = h.committed.find(e.object);
    if (it == h.committed.end()) violated("an entry names an object not live at the frame's tick", e.object);
    if (++seen[e.object] > 1) violated("an object has two entries", e.object);
    if (std::memcmp(&e.transform, &it->second.transform, sizeof e.transform) != 0)
      violated("an entry's transform is not the one committed", e.object);
    const uint32_t levels = h.level_counts[it->second.model];
    if (e.level >= levels || e.from_level >= levels) violated("an entry's level is outside its chain", e.level, levels);
    if (!(e.morph >= 0.0f && e.morph <= 1.0f)) violated("an entry's blend weight is outside [0, 1]", i);
    if (e.view_mask == 0) violated("an entry no view sees", e.object);
    triangles += lod_model_level_triangles(h.service, h.models[it->second.model], e.level);
  }
  lod_frame_entry past;
  if (lod_frame_entry_get(frame, info.visible, &past) == 0) violated("the entry past the end is served", info.visible);
  if (triangles != info.tris_selected) violated("triangles are not the sum of the entries' levels", triangles,
                                                info.tris_selected);
  if (h.triangle_budget && !info.over_budget && info.tris_selected > info.budget)
    violated("the budget does not hold", info.tris_selected, info.budget);
}

void step_and_check(Host& h, double dt) {
  if (lod_step(h.service, dt) != 0) return;  // a refused dt is a clean refusal
  const lod_frame* f = lod_frame_acquire(h.service);
  if (!f) violated("no frame after a step");
  check_frame(h, f);
  h.held.push_back(f);
  release_held(h, 2);  // holds up to two frames across steps, as a slow consumer would
}

// A setter refuses exactly the values its contract excludes, and says why.
void expect_refusal(int answer, bool should_refuse, const char* what) {
  if ((answer != 0) != should_refuse) {
    std::fprintf(stderr, "%s: ", what);
    violated(should_refuse ? "an invalid value was accepted" : "a valid value was refused");
  }
  if (should_refuse && lod_last_error()[0] == '\0') {
    std::fprintf(stderr, "%s: ", what);
    violated("a refusal without a message");
  }
}

void run_operation(Host& h, Bytes& in) {
  static const double kDt[] = {1.0 / 60, 0.0, 0.5, 1e-9, -1.0, NAN, INFINITY, 1e9};
  switch (in.u8() % 14) {
    case 0:
    case 1: {  // objects are the common case
      const uint32_t m = in.u8();
      const lod_transform t = read_transform(in);
      const lod_model model = m < 250 ? h.models[m % h.models.size()] : lod_model(m);
      const lod_object o = lod_object_create(h.service, model, &t);
      if (o != 0) {
        if (m >= 250 && model >= h.models.size()) violated("an unknown model made an object", model);
        h.staged[o] = Object{lod_model(m % h.models.size()), t};
        h.ever.push_back(o);
      }
      break;
    }
    case 2: {
      const lod_object o = pick_handle(h, in);
      const bool live = h.staged.count(o) != 0;
      if ((lod_object_destroy(h.service, o) == 0) != live) violated("destroy's answer disagrees with liveness", o);
      h.staged.erase(o);
      break;
    }
    case 3: {
      const lod_object o = pick_handle(h, in);
      const lod_transform t = read_transform(in);
      if (lod_object_set_transform(h.service, o, &t) == 0) {
        if (!h.staged.count(o)) violated("a stale handle was moved", o);
        h.staged[o].transform = t;
      }
      break;
    }
    case 4: {
      const lod_object o = pick_handle(h, in);
      lod_object_options opt;
      lod_object_options_default(&opt);
      opt.lod_bias = in.u8() < 200 ? float(int8_t(in.u8())) / 32.0f : in.number(4.0f);
      opt.min_level = in.u8() % 6;
      opt.max_level = in.u8() < 128 ? 255u : in.u8() % 6;
      opt.priority = in.u8() < 200 ? 0.25f + float(in.u8()) / 32.0f : in.number(4.0f);
      opt.forced_level = int32_t(in.u8() % 8) - 2;
      opt.never_cull = in.u8() > 200;
      lod_object_set_options(h.service, o, &opt);
      break;
    }
    case 5: {
      const uint32_t index = in.u8() % 10;  // 8 and 9 are refused
      const lod_view v = read_view(in);
      lod_set_view(h.service, index, &v);
      break;
    }
    case 6:
      lod_set_view_count(h.service, in.u8() % 10);
      break;
    case 7: {
      static const uint64_t kBudgets[] = {0, 1, 100, 2000, 20000, 1000000, UINT64_MAX};
      const uint8_t k = in.u8();
      const uint64_t budget = k < 7 ? kBudgets[k] : uint64_t(k) * 97;
      expect_refusal(lod_set_budget(h.service, budget), budget < LOD_MIN_BUDGET, "budget");
      break;
    }
    case 8: {
      const float pixels = in.number(4.0f);
      expect_refusal(lod_set_pixel_error(h.service, pixels), !(pixels > 0.0f && pixels <= LOD_MAX_PIXEL_ERROR),
                     "pixel error");
      break;
    }
    case 9: {
      const float band = in.number(1.0f);
      expect_refusal(lod_set_hysteresis(h.service, band), !(band >= 0.0f && band <= LOD_MAX_HYSTERESIS), "hysteresis");
      break;
    }
    case 10: {
      const float seconds = in.number(1.0f);
      expect_refusal(lod_set_blend_seconds(h.service, seconds), !(seconds >= 0.0f && seconds <= LOD_MAX_BLEND_SECONDS),
                     "blend time");
      break;
    }
    case 11:
    case 12: {
      // Mostly forward (equal ticks are allowed); sometimes back, which is refused with the
      // changes kept staged for the next commit.
      const uint8_t step = in.u8();
      const uint64_t tick = step < 224 ? h.tick + step % 4 : h.tick - std::min<uint64_t>(h.tick, step % 8);
      const bool refused = lod_commit(h.service, tick) != 0;
      if (refused != (tick < h.tick)) violated("a commit's answer disagrees with its tick", tick, h.tick);
      if (refused) break;
      h.tick = tick;
      h.committed = h.staged;
      h.committed_once = true;
      break;
    }
    case 13:
      if (!h.committed_once) break;
      step_and_check(h, kDt[in.u8() % 8]);
      break;
  }
}

// The operation encoding above, written: the seeds.
class Ops {
 public:
  explicit Ops(uint8_t config) { bytes_.push_back(config); }
  Ops& create(uint8_t model, float x, float y, float z) {  // identity rotation, scale 1.05
    bytes_.insert(bytes_.end(), {0, model, 0, quarter(x), 0, quarter(y), 0, quarter(z), 0, 0, 16});
    return *this;
  }
  Ops& destroy(uint8_t which) { return put({2, which}); }
  Ops& commit() { return put({11, 1}); }
  Ops& step() { return put({13, 0}); }
  Ops& budget(uint8_t k) { return put({7, k}); }
  // View 0 at `eye`, looking at the origin, 60.4 degrees, 1280 x 720, near 0.1, far 5000.
  Ops& view(float x, float y, float z) {
    put({5, 0});
    for (float v : {x, y, z}) {
      uint32_t bits;
      std::memcpy(&bits, &v, 4);
      put({16, uint8_t(bits >> 24), uint8_t(bits >> 16), uint8_t(bits >> 8), uint8_t(bits)});
    }
    return put({0, 0, 63, 0, 152, 0, 82, 0, 0});
  }
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  static uint8_t quarter(float v) { return uint8_t(int8_t(v * 4.0f)); }
  Ops& put(std::initializer_list<uint8_t> b) {
    bytes_.insert(bytes_.end(), b);
    return *this;
  }
  std::vector<uint8_t> bytes_;
};

void write_seeds(const fs::path& dir) {
  fs::create_directories(dir);
  std::vector<Ops> seeds;
  for (uint8_t config : {0, 6, 12}) {  // greedy, greedy_multi and benefit_cost; triangles, not strict, 1 thread
    Ops crowd(config);  // twenty balls, 36,800 triangles at full detail, under 20,000
    for (int k = 0; k < 20; ++k) crowd.create(0, float(k % 5) * 6 - 12, 0, float(k / 5) * 6 - 9);
    crowd.commit().view(0, 6, 30).step().view(10, 4, 20).step().view(-20, 8, 15).step();
    seeds.push_back(crowd);
    Ops churn(config + 1);  // the same with two threads, objects coming and going, a tighter budget
    for (int k = 0; k < 12; ++k) churn.create(uint8_t(k % 2), float(k) * 3 - 18, 0, 0);
    churn.commit().view(0, 4, 25).step().budget(3).step().destroy(2).destroy(5).commit().step();
    churn.create(1, 0, 0, 5).commit().view(5, 2, 12).step().step();
    seeds.push_back(churn);
  }
  for (size_t k = 0; k < seeds.size(); ++k) {
    std::ofstream out(dir / ("run-" + std::to_string(k)), std::ios::binary);
    out.write(reinterpret_cast<const char*>(seeds[k].bytes().data()), std::streamsize(seeds[k].bytes().size()));
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* seeds = std::getenv("LOD_FUZZ_WRITE_SEEDS")) {
    write_seeds(seeds);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const Fixture& f = fixture();
  Bytes in(data, size);
  const uint8_t variant = in.u8() % f.configs.size();
  char error[512] = "";
  Host h;
  h.service = lod_service_create(f.configs[variant].c_str(), error, sizeof error);
  if (!h.service) {
    std::fprintf(stderr, "service refused its config: %s\n", error);
    std::abort();
  }
  h.triangle_budget = f.configs[variant].filename().string().find("-triangles-") != std::string::npos;
  for (const fs::path& mesh : f.meshes) {
    lod_model m = 0;
    if (lod_model_add(h.service, mesh.c_str(), &m, error, sizeof error) != 0) {
      std::fprintf(stderr, "%s: %s\n", mesh.c_str(), error);
      std::abort();
    }
    h.models.push_back(m);
    h.level_counts.push_back(lod_model_level_count(h.service, m));
  }
  for (int ops = 0; !in.done() && ops < 400; ++ops) run_operation(h, in);
  if (h.committed_once) step_and_check(h, 1.0 / 60);
  release_held(h, 0);
  lod_service_destroy(h.service);
  return 0;
}
