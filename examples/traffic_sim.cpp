// traffic_sim: a headless traffic simulation embedding lodkit through <lodkit/lodkit.hpp> only.
//
// A static town (a grid of blocks, four buildings each, from a few models) and tens of
// thousands of vehicles driving along the lanes of its street grid: they enter at a lane's
// start and leave at its end, where they are destroyed and new ones spawn elsewhere. Two views:
// a street-level camera driving down a street and an overhead one above the town's centre.
//
//   simulation thread  each tick: moves every vehicle (one set_transforms batch), destroys the
//                      ones that left, creates replacements, moves the street camera, commit(tick)
//   LOD thread         the service free-running (start()) at its rate, independent of the ticks
//   consumer threads   acquire the newest frame and check it (below); any number of them
//   main thread        prints figures once a second and a summary at the end
//
// Checks on every frame a consumer reads: frame indices increase and ticks never go back; every
// visible entry's handle was alive at the frame's tick (created in a tick <= it, destroyed in a
// later one), its level exists in its model and some view sees it; object_count is the number of
// objects the simulation had at that tick; tris_selected <= budget unless over_budget. Exit 0
// only if every check held, frames were read and they followed the ticks.
//
// usage: traffic_sim --data DIR [--vehicles N] [--blocks B] [--seconds S] [--tick-hz HZ]
//                    [--rate-hz HZ] [--budget M] [--threads N] [--consumers N] [--cache DIR]
//                    [--buildings a.off,b.off] [--cars c.off,d.off]
// DIR holds the .off meshes (a lodkit build's data/ folder has them); bakes are cached in
// --cache (default: traffic_cache), so a second run starts at once.
#include <lodkit/lodkit.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Args {
  fs::path data;
  fs::path cache = "traffic_cache";
  uint32_t vehicles = 20000;
  uint32_t blocks = 24;
  double seconds = 10;
  double tick_hz = 30;
  double rate_hz = 60;
  uint64_t budget = 1000000;
  uint32_t threads = 0;
  uint32_t consumers = 1;
  std::vector<std::string> buildings = {"bull.off", "lion.off", "dino.off"};
  std::vector<std::string> cars = {"cow.off", "elephant.off"};
};

std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string part; std::getline(in, part, ',');)
    if (!part.empty()) out.push_back(part);
  return out;
}

bool parse_args(int argc, char** argv, Args& a) {
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (i + 1 >= argc) {
      std::fprintf(stderr, "%s needs a value\n", k.c_str());
      return false;
    }
    const char* v = argv[++i];
    if (k == "--data") a.data = v;
    else if (k == "--cache") a.cache = v;
    else if (k == "--vehicles") a.vehicles = uint32_t(std::strtoul(v, nullptr, 10));
    else if (k == "--blocks") a.blocks = uint32_t(std::strtoul(v, nullptr, 10));
    else if (k == "--seconds") a.seconds = std::strtod(v, nullptr);
    else if (k == "--tick-hz") a.tick_hz = std::strtod(v, nullptr);
    else if (k == "--rate-hz") a.rate_hz = std::strtod(v, nullptr);
    else if (k == "--budget") a.budget = std::strtoull(v, nullptr, 10);
    else if (k == "--threads") a.threads = uint32_t(std::strtoul(v, nullptr, 10));
    else if (k == "--consumers") a.consumers = uint32_t(std::strtoul(v, nullptr, 10));
    else if (k == "--buildings") a.buildings = split_commas(v);
    else if (k == "--cars") a.cars = split_commas(v);
    else {
      std::fprintf(stderr, "unknown option %s\n", k.c_str());
      return false;
    }
  }
  if (a.data.empty()) return std::fprintf(stderr, "--data DIR (the folder with the .off meshes) is required\n"), false;
  if (a.blocks < 1 || a.tick_hz <= 0 || a.seconds <= 0 || a.consumers < 1 || a.buildings.empty() || a.cars.empty())
    return std::fprintf(stderr, "need --blocks >= 1, --tick-hz > 0, --seconds > 0, --consumers >= 1, models\n"), false;
  return true;
}

// A model's extent, read from its OFF file: the API deals in baked levels, not in sizes, and
// the town needs to scale buildings and vehicles to metres.
struct Extent {
  float min[3] = {0, 0, 0}, max[3] = {0, 0, 0};
  float size() const { return std::max({max[0] - min[0], max[1] - min[1], max[2] - min[2]}); }
};

bool off_extent(const fs::path& path, Extent& e, std::string& error) {
  std::ifstream in(path);
  std::string magic;
  if (!(in >> magic) || magic.find("OFF") == std::string::npos) return error = path.string() + ": not an OFF file", false;
  auto next_number = [&](double& x) {
    std::string tok;
    while (in >> tok) {
      if (tok[0] == '#') {
        std::getline(in, tok);
        continue;
      }
      char* end = nullptr;
      x = std::strtod(tok.c_str(), &end);
      return *end == '\0';
    }
    return false;
  };
  double nv = 0, nf = 0, ne = 0;
  if (!next_number(nv) || !next_number(nf) || !next_number(ne) || nv < 1)
    return error = path.string() + ": bad OFF header", false;
  for (int d = 0; d < 3; ++d) e.min[d] = 1e30f, e.max[d] = -1e30f;
  for (uint64_t v = 0; v < uint64_t(nv); ++v)
    for (int d = 0; d < 3; ++d) {
      double x = 0;
      if (!next_number(x)) return error = path.string() + ": truncated vertex list", false;
      e.min[d] = std::min(e.min[d], float(x));
      e.max[d] = std::max(e.max[d], float(x));
    }
  if (!(e.size() > 0)) return error = path.string() + ": all vertices at one point", false;
  return true;
}

struct Model {
  lod::ModelId id = 0;
  Extent extent;
  uint32_t levels = 0;
};

// Placement of a model scaled to `metres`, standing on the ground at (x, z), turned by `yaw`.
lod::Transform place(const Model& m, float metres, float x, float z, float yaw) {
  lod::Transform t;
  t.scale = metres / m.extent.size();
  // Centre the model's footprint on (x, z) and its lowest point on y = 0 (before the turn:
  // small models, so the footprint offset after turning is not worth a rotation here).
  t.position[0] = x - t.scale * 0.5f * (m.extent.min[0] + m.extent.max[0]);
  t.position[1] = -t.scale * m.extent.min[1];
  t.position[2] = z - t.scale * 0.5f * (m.extent.min[2] + m.extent.max[2]);
  t.rotation[0] = 0;
  t.rotation[1] = std::sin(0.5f * yaw);
  t.rotation[2] = 0;
  t.rotation[3] = std::cos(0.5f * yaw);
  return t;
}

// The street grid: streets along x at z = k * block and along z at x = k * block, k = 0..B,
// each with one lane per direction, 3 m either side of its centre line. A lane runs the whole
// town; `s` is the distance along it.
struct Lane {
  float x0, z0;  // start
  float dx, dz;  // unit direction
};

std::vector<Lane> make_lanes(uint32_t blocks, float block) {
  std::vector<Lane> lanes;
  const float length = float(blocks) * block;
  for (uint32_t k = 0; k <= blocks; ++k) {
    const float c = float(k) * block;
    lanes.push_back({0, c + 3, 1, 0});          // along +x
    lanes.push_back({length, c - 3, -1, 0});    // along -x
    lanes.push_back({c - 3, 0, 0, 1});          // along +z
    lanes.push_back({c + 3, length, 0, -1});    // along -z
  }
  return lanes;
}

struct Vehicle {
  lod::ObjectHandle handle = 0;
  uint32_t model = 0;  // index into cars
  uint32_t lane = 0;
  float s = 0;
  float speed = 0;
};

// What the simulation knows about every object's life, for the consumers' checks. Guarded by
// one mutex; the simulation writes before each commit, consumers read while checking a frame.
struct Ledger {
  struct Life {
    uint64_t born = 0;                 // first tick it is part of
    uint64_t died = UINT64_MAX;        // first tick it is no longer part of
  };
  std::mutex mutex;
  std::unordered_map<lod::ObjectHandle, Life> lives;
  std::map<uint64_t, uint32_t> live_at_tick;  // objects alive at each committed tick

  // Forget what no frame still to be read can ask about (ticks never go back).
  void prune(uint64_t oldest_tick_in_use) {
    const std::lock_guard<std::mutex> lock(mutex);
    for (auto it = lives.begin(); it != lives.end();)
      it = it->second.died <= oldest_tick_in_use ? lives.erase(it) : std::next(it);
    live_at_tick.erase(live_at_tick.begin(), live_at_tick.lower_bound(oldest_tick_in_use));
  }
};

// Figures shared between the threads; the main thread prints deltas once a second.
struct Counters {
  std::atomic<uint64_t> ticks{0}, spawned{0}, despawned{0}, live_vehicles{0};
  std::atomic<double> sim_ms{0};
  std::atomic<uint64_t> frames{0}, entries{0}, seen_view0{0}, seen_view1{0}, tris{0}, over_budget{0};
  std::atomic<uint64_t> tick_lag{0}, max_frame_tick{0}, violations{0}, checks{0};
};

struct Violations {
  std::mutex mutex;
  std::vector<std::string> first;
  void add(Counters& c, std::string what) {
    if (c.violations.fetch_add(1) < 10) {
      const std::lock_guard<std::mutex> lock(mutex);
      first.push_back(std::move(what));
    }
  }
};

struct Town {
  float block = 60;
  std::vector<Lane> lanes;
  float lane_length = 0;
};

void simulate(lod::Service& service, const Args& args, const Town& town, const std::vector<Model>& cars,
              std::vector<Vehicle> vehicles, uint64_t first_tick, uint32_t static_objects, Ledger& ledger,
              Counters& c, Violations& bad, const std::atomic<bool>& stop) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<uint32_t> pick_lane(0, uint32_t(town.lanes.size() - 1));
  std::uniform_int_distribution<uint32_t> pick_car(0, uint32_t(cars.size() - 1));
  std::uniform_real_distribution<float> pick_speed(8, 16);
  const float dt = float(1.0 / args.tick_hz);
  std::vector<lod::ObjectHandle> handles;
  std::vector<lod::Transform> transforms;
  std::vector<lod::ObjectHandle> leaving;
  auto transform_of = [&](const Vehicle& v) {
    const Lane& l = town.lanes[v.lane];
    return place(cars[v.model], 4.5f, l.x0 + l.dx * v.s, l.z0 + l.dz * v.s, std::atan2(l.dx, l.dz));
  };
  float camera_s = 0;
  auto next = Clock::now();
  for (uint64_t tick = first_tick + 1; !stop.load(); ++tick) {
    const auto t0 = Clock::now();
    handles.clear();
    transforms.clear();
    leaving.clear();
    size_t kept = 0;
    for (Vehicle& v : vehicles) {
      v.s += v.speed * dt;
      if (v.s > town.lane_length) {
        leaving.push_back(v.handle);
        continue;
      }
      handles.push_back(v.handle);
      transforms.push_back(transform_of(v));
      vehicles[kept++] = v;
    }
    vehicles.resize(kept);
    const size_t moved = service.set_transforms(handles, transforms);
    if (moved != handles.size())
      bad.add(c, "tick " + std::to_string(tick) + ": set_transforms took " + std::to_string(moved) + " of " +
                     std::to_string(handles.size()) + " (" + service.last_error() + ")");
    {
      const std::lock_guard<std::mutex> lock(ledger.mutex);
      for (lod::ObjectHandle h : leaving) {
        if (!service.destroy(h)) bad.add(c, "destroy refused a live vehicle: " + service.last_error());
        ledger.lives[h].died = tick;
      }
      // As many newcomers as left, each at the start of a lane.
      for (size_t k = 0; k < leaving.size(); ++k) {
        Vehicle v;
        v.model = pick_car(rng);
        v.lane = pick_lane(rng);
        v.speed = pick_speed(rng);
        v.handle = service.create(cars[v.model].id, transform_of(v));
        if (v.handle == 0) {
          bad.add(c, "create refused a vehicle: " + service.last_error());
          continue;
        }
        ledger.lives[v.handle].born = tick;
        vehicles.push_back(v);
      }
      ledger.live_at_tick[tick] = static_objects + uint32_t(vehicles.size());
    }
    // The street camera drives down lane 0 at 12 m/s, eye 1.7 m above the road.
    camera_s = std::fmod(camera_s + 12 * dt, town.lane_length);
    const Lane& cl = town.lanes[0];
    lod::Camera street;
    street.eye[0] = cl.x0 + cl.dx * camera_s;
    street.eye[1] = 1.7f;
    street.eye[2] = cl.z0 + cl.dz * camera_s;
    street.forward[0] = cl.dx;
    street.forward[1] = -0.05f;
    street.forward[2] = cl.dz;
    street.near_z = 0.5f;
    street.far_z = 1500;
    if (!service.set_view(0, street)) bad.add(c, "set_view(0) refused: " + service.last_error());
    service.commit(tick);

    c.ticks = tick;
    c.spawned += vehicles.size() - kept;  // the newcomers that were accepted
    c.despawned += leaving.size();
    c.live_vehicles = vehicles.size();
    c.sim_ms = c.sim_ms.load() + std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    next += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / args.tick_hz));
    std::this_thread::sleep_until(next);
  }
}

void check_frame(const lod::Frame& f, const Args& args, const std::vector<uint32_t>& level_counts, Ledger& ledger,
                 Counters& c, Violations& bad) {
  const std::string at = "frame " + std::to_string(f.index) + " (tick " + std::to_string(f.tick) + "): ";
  const size_t n = f.handles.size();
  if (f.models.size() != n || f.levels.size() != n || f.view_masks.size() != n || f.visible != n)
    bad.add(c, at + "per-entry columns disagree with " + std::to_string(n) + " handles");
  if (f.budget != args.budget) bad.add(c, at + "budget " + std::to_string(f.budget) + " != " + std::to_string(args.budget));
  if (!f.over_budget && f.tris_selected > f.budget)
    bad.add(c, at + "tris_selected " + std::to_string(f.tris_selected) + " > budget without over_budget");
  uint64_t v0 = 0, v1 = 0;
  {
    const std::lock_guard<std::mutex> lock(ledger.mutex);
    const auto live = ledger.live_at_tick.find(f.tick);
    if (live != ledger.live_at_tick.end() && live->second != f.object_count)
      bad.add(c, at + "object_count " + std::to_string(f.object_count) + ", the simulation had " +
                     std::to_string(live->second));
    for (size_t i = 0; i < std::min({n, f.models.size(), f.levels.size(), f.view_masks.size()}); ++i) {
      const auto life = ledger.lives.find(f.handles[i]);
      if (life == ledger.lives.end() || life->second.born > f.tick || life->second.died <= f.tick)
        bad.add(c, at + "entry " + std::to_string(i) + ": handle " + std::to_string(f.handles[i]) +
                       " was not alive at this tick");
      if (f.models[i] >= level_counts.size() || f.levels[i] >= level_counts[f.models[i]])
        bad.add(c, at + "entry " + std::to_string(i) + ": level " + std::to_string(f.levels[i]) + " of model " +
                       std::to_string(f.models[i]) + " does not exist");
      const uint8_t mask = f.view_masks[i];
      if (mask == 0 || (mask >> f.view_count) != 0)
        bad.add(c, at + "entry " + std::to_string(i) + ": view mask " + std::to_string(mask) + " with " +
                       std::to_string(f.view_count) + " views");
      v0 += mask & 1u;
      v1 += (mask >> 1) & 1u;
    }
  }
  c.frames += 1;
  c.entries += n;
  c.seen_view0 += v0;
  c.seen_view1 += v1;
  c.tris += f.tris_selected;
  c.over_budget += f.over_budget ? 1 : 0;
  const uint64_t committed = c.ticks.load();
  c.tick_lag += committed > f.tick ? committed - f.tick : 0;
  uint64_t seen = c.max_frame_tick.load();
  while (f.tick > seen && !c.max_frame_tick.compare_exchange_weak(seen, f.tick)) {
  }
}

void consume(const lod::Service& service, const Args& args, const std::vector<uint32_t>& level_counts, Ledger& ledger,
             Counters& c, Violations& bad, std::atomic<uint64_t>& latest_tick, const std::atomic<bool>& stop) {
  uint64_t last_index = 0, last_tick = 0;
  bool any = false;
  while (!stop.load()) {
    const lod::FrameRef frame = service.acquire_frame();
    if (!frame || (any && frame->index == last_index)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    c.checks += 1;
    if (any && frame->index < last_index)
      bad.add(c, "frame index went back: " + std::to_string(frame->index) + " after " + std::to_string(last_index));
    if (any && frame->tick < last_tick)
      bad.add(c, "tick went back: frame " + std::to_string(frame->index) + " has tick " + std::to_string(frame->tick) +
                     " after " + std::to_string(last_tick));
    check_frame(*frame, args, level_counts, ledger, c, bad);
    any = true;
    last_index = frame->index;
    last_tick = std::max(last_tick, frame->tick);
    latest_tick = last_tick;
  }
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (!parse_args(argc, argv, args)) return 2;

  lod::ServiceOptions options;
  options.threads = args.threads;
  options.rate_hz = args.rate_hz;
  options.budget = args.budget;
  options.cache_dir = args.cache;
  // Models here are meshes: bake them (cached), with chains deep enough that 20,000 vehicles
  // and a town fit M at their coarsest levels (lodkit's defaults stop near 6 %).
  options.baker = lod::mesh_baker({1.0f, 0.5f, 0.25f, 0.12f, 0.06f, 0.03f, 0.015f, 0.0075f, 0.004f});
  lod::Service service(options);

  // Models: buildings and vehicles, baked on first use.
  auto load_models = [&](const std::vector<std::string>& files, std::vector<Model>& out) {
    for (const std::string& file : files) {
      Model m;
      std::string error;
      const fs::path path = args.data / file;
      if (!off_extent(path, m.extent, error)) return std::fprintf(stderr, "%s\n", error.c_str()), false;
      if (!service.add_model(path, &m.id)) return std::fprintf(stderr, "%s\n", service.last_error().c_str()), false;
      m.levels = service.level_count(m.id);
      std::printf("model %-14s %u levels, %llu .. %llu triangles\n", file.c_str(), m.levels,
                  (unsigned long long)service.level_triangles(m.id, 0),
                  (unsigned long long)service.level_triangles(m.id, m.levels ? m.levels - 1 : 0));
      out.push_back(m);
    }
    return true;
  };
  const auto bake_start = Clock::now();
  std::vector<Model> buildings, cars;
  if (!load_models(args.buildings, buildings) || !load_models(args.cars, cars)) return 1;
  std::printf("models ready in %.2f s\n", std::chrono::duration<double>(Clock::now() - bake_start).count());
  std::vector<uint32_t> level_counts(service.model_count(), 0);
  for (const auto* group : {&buildings, &cars})
    for (const Model& m : *group) level_counts[m.id] = m.levels;

  Town town;
  town.lanes = make_lanes(args.blocks, town.block);
  town.lane_length = float(args.blocks) * town.block;
  Ledger ledger;
  Counters counters;
  Violations bad;

  // Tick 1: the town and the first vehicles, spread along the lanes.
  const uint64_t first_tick = 1;
  uint32_t static_objects = 0;
  std::vector<Vehicle> vehicles;
  {
    std::mt19937 rng(1);
    const std::lock_guard<std::mutex> lock(ledger.mutex);
    for (uint32_t bx = 0; bx < args.blocks; ++bx)
      for (uint32_t bz = 0; bz < args.blocks; ++bz)
        for (int q = 0; q < 4; ++q) {  // four buildings per block, 12 m from its centre
          const Model& m = buildings[(bx * 7 + bz * 13 + uint32_t(q)) % buildings.size()];
          const float x = (float(bx) + 0.5f) * town.block + (q & 1 ? 12.f : -12.f);
          const float z = (float(bz) + 0.5f) * town.block + (q & 2 ? 12.f : -12.f);
          const lod::ObjectHandle h = service.create(m.id, place(m, 18, x, z, float(q) * 1.5707964f));
          if (h == 0) return std::fprintf(stderr, "create (building): %s\n", service.last_error().c_str()), 1;
          ledger.lives[h].born = first_tick;
          ++static_objects;
        }
    std::uniform_int_distribution<uint32_t> pick_lane(0, uint32_t(town.lanes.size() - 1));
    std::uniform_int_distribution<uint32_t> pick_car(0, uint32_t(cars.size() - 1));
    std::uniform_real_distribution<float> pick_s(0, town.lane_length), pick_speed(8, 16);
    for (uint32_t i = 0; i < args.vehicles; ++i) {
      Vehicle v;
      v.model = pick_car(rng);
      v.lane = pick_lane(rng);
      v.s = pick_s(rng);
      v.speed = pick_speed(rng);
      const Lane& l = town.lanes[v.lane];
      v.handle = service.create(cars[v.model].id, place(cars[v.model], 4.5f, l.x0 + l.dx * v.s, l.z0 + l.dz * v.s,
                                                        std::atan2(l.dx, l.dz)));
      if (v.handle == 0) return std::fprintf(stderr, "create (vehicle): %s\n", service.last_error().c_str()), 1;
      ledger.lives[v.handle].born = first_tick;
      vehicles.push_back(v);
    }
    ledger.live_at_tick[first_tick] = static_objects + uint32_t(vehicles.size());
  }
  // View 1: overhead, above the town's centre, looking straight down.
  lod::Camera overhead;
  const float centre = 0.5f * town.lane_length;
  overhead.eye[0] = centre;
  overhead.eye[1] = std::max(200.f, 1.1f * town.lane_length);
  overhead.eye[2] = centre;
  overhead.forward[0] = 0, overhead.forward[1] = -1, overhead.forward[2] = 0;
  overhead.up[0] = 0, overhead.up[1] = 0, overhead.up[2] = -1;
  overhead.near_z = 10;
  overhead.far_z = overhead.eye[1] + 100;
  lod::Camera street;  // replaced every tick by the simulation
  street.eye[0] = town.lanes[0].x0, street.eye[1] = 1.7f, street.eye[2] = town.lanes[0].z0;
  street.forward[0] = 1, street.forward[1] = 0, street.forward[2] = 0;
  if (!service.set_view(0, street) || !service.set_view(1, overhead) || !service.set_view_count(2))
    return std::fprintf(stderr, "set_view: %s\n", service.last_error().c_str()), 1;
  service.commit(first_tick);
  counters.ticks = first_tick;
  counters.live_vehicles = vehicles.size();
  std::printf("town: %u blocks, %u buildings, %u lanes of %.0f m, %zu vehicles\n", args.blocks * args.blocks,
              static_objects, uint32_t(town.lanes.size()), double(town.lane_length), vehicles.size());

  if (!service.start()) return std::fprintf(stderr, "start: %s\n", service.last_error().c_str()), 1;
  std::atomic<bool> stop{false};
  std::thread sim(simulate, std::ref(service), std::cref(args), std::cref(town), std::cref(cars), std::move(vehicles),
                  first_tick, static_objects, std::ref(ledger), std::ref(counters), std::ref(bad), std::cref(stop));
  std::vector<std::atomic<uint64_t>> latest(args.consumers);
  std::vector<std::thread> consumers;
  for (uint32_t k = 0; k < args.consumers; ++k)
    consumers.emplace_back(consume, std::cref(service), std::cref(args), std::cref(level_counts), std::ref(ledger),
                           std::ref(counters), std::ref(bad), std::ref(latest[k]), std::cref(stop));

  std::printf("%5s %6s %8s %7s %9s %9s %9s %10s %5s %7s %7s %6s\n", "t_s", "ticks", "sim_ms", "frames", "visible",
              "street", "overhead", "tris", "over", "lag", "spawned", "lod_ms");
  const auto start = Clock::now();
  uint64_t prev_ticks = counters.ticks, prev_frames = 0, prev_entries = 0, prev_v0 = 0, prev_v1 = 0, prev_tris = 0,
           prev_over = 0, prev_lag = 0, prev_spawned = 0;
  double prev_sim_ms = 0;
  for (int second = 1; second <= int(std::ceil(args.seconds)); ++second) {
    std::this_thread::sleep_until(start + std::chrono::duration<double>(std::min<double>(second, args.seconds)));
    const uint64_t ticks = counters.ticks, frames = counters.frames, entries = counters.entries;
    const uint64_t v0 = counters.seen_view0, v1 = counters.seen_view1, tris = counters.tris;
    const uint64_t over = counters.over_budget, lag = counters.tick_lag, spawned = counters.spawned;
    const double sim_ms = counters.sim_ms;
    const uint64_t df = std::max<uint64_t>(1, frames - prev_frames), dt = std::max<uint64_t>(1, ticks - prev_ticks);
    std::printf("%5d %6llu %8.2f %7llu %9.0f %9.0f %9.0f %10.0f %5llu %7.2f %7llu %6.2f\n", second,
                (unsigned long long)(ticks - prev_ticks), (sim_ms - prev_sim_ms) / double(dt),
                (unsigned long long)(frames - prev_frames), double(entries - prev_entries) / double(df),
                double(v0 - prev_v0) / double(df), double(v1 - prev_v1) / double(df),
                double(tris - prev_tris) / double(df), (unsigned long long)(over - prev_over),
                double(lag - prev_lag) / double(df), (unsigned long long)(spawned - prev_spawned),
                service.stats().last_ms);
    std::fflush(stdout);
    prev_ticks = ticks, prev_frames = frames, prev_entries = entries, prev_v0 = v0, prev_v1 = v1, prev_tris = tris;
    prev_over = over, prev_lag = lag, prev_spawned = spawned, prev_sim_ms = sim_ms;
    // Lives that ended before every consumer's newest tick can no longer be asked about.
    uint64_t oldest = UINT64_MAX;
    for (const auto& l : latest) oldest = std::min<uint64_t>(oldest, l.load());
    if (oldest != UINT64_MAX && oldest > 0) ledger.prune(oldest);
  }
  stop = true;
  sim.join();
  for (std::thread& t : consumers) t.join();
  service.stop();

  const lod::ServiceStats stats = service.stats();
  const uint64_t frames = counters.frames, violations = counters.violations;
  const bool followed = counters.max_frame_tick.load() > first_tick;  // frames saw the simulation move
  std::printf("\nsummary: %llu ticks, %llu frames published (%.2f ms mean, %llu lost to errors), %llu frames checked by "
              "%u consumer(s), %.0f visible on average, %llu over budget, %llu vehicles spawned and despawned\n",
              (unsigned long long)counters.ticks.load(), (unsigned long long)stats.frames, stats.mean_ms,
              (unsigned long long)stats.errors, (unsigned long long)frames, args.consumers,
              frames ? double(counters.entries.load()) / double(frames) : 0.0,
              (unsigned long long)counters.over_budget.load(), (unsigned long long)counters.despawned.load());
  for (const std::string& v : bad.first) std::printf("violation: %s\n", v.c_str());
  const bool ok = violations == 0 && frames > 0 && followed && stats.errors == 0;
  if (!followed) std::printf("failed: no frame carried a tick after the first\n");
  if (frames == 0) std::printf("failed: no frame was read\n");
  if (stats.errors) std::printf("failed: %llu frames lost to errors\n", (unsigned long long)stats.errors);
  std::printf("%s: %llu violations\n", ok ? "ok" : "FAILED", (unsigned long long)violations);
  return ok ? 0 : 1;
}
