// StreamPager: loader threads around runtime/stream_residency. One mutex guards the queue of
// issued-but-unread nodes and the completions; no lock is held while a node is read.
#include "jobs/stream_pager.h"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

namespace lod {

namespace {

struct Completion {
  uint32_t node;
  Status status;
  std::shared_ptr<HlodPayload> payload;
};

}  // namespace

struct StreamPager::Shared {
  NodeLoader load;
  std::mutex mutex;
  std::condition_variable wake;
  std::vector<uint32_t> queue;    // issued, unread; back() is the most important
  std::vector<Completion> done;   // filled by the loaders, swapped out by update
  std::vector<Completion> taken;  // the frame thread's side of the swap (keeps its capacity)
  bool stop = false;
  std::vector<std::thread> threads;
};

namespace {

Status read_node(const NodeLoader& load, uint32_t node, HlodPayload& out) {
  try {
    return load(node, out);
  } catch (const std::exception& e) {
    return Status::error(std::string("the loader threw: ") + e.what());
  } catch (...) {
    return Status::error("the loader threw");
  }
}

void loader_loop(StreamPager::Shared& sh) {
  std::unique_lock lock(sh.mutex);
  for (;;) {
    sh.wake.wait(lock, [&] { return sh.stop || !sh.queue.empty(); });
    if (sh.stop) return;
    const uint32_t node = sh.queue.back();
    sh.queue.pop_back();
    lock.unlock();
    auto payload = std::make_shared<HlodPayload>();
    Status status = read_node(sh.load, node, *payload);
    lock.lock();
    sh.done.push_back({node, std::move(status), std::move(payload)});
  }
}

std::string node_message(uint32_t node, const std::string& why) {
  return "node " + std::to_string(node) + ": " + why;
}

// What a payload takes in memory, counted as HlodNode::resident_bytes counts it (positions,
// normals, uvs, uv1, colours, indices, material runs).
uint64_t payload_bytes(const HlodPayload& p) {
  return 4ull * (p.positions.size() + p.normals.size() + p.uvs.size() + p.uvs1.size() + p.colors.size() +
                 p.indices.size()) +
         uint64_t(sizeof(LevelSubmesh)) * p.runs.size();
}

}  // namespace

StreamPager::StreamPager(const HlodTree& tree, const StreamPagerConfig& config, NodeLoader load)
    : StreamPager(node_bytes_of(tree), config, std::move(load)) {}

StreamPager::StreamPager(std::span<const uint64_t> node_bytes, const StreamPagerConfig& config,
                         NodeLoader load)
    : config_(config), shared_(std::make_unique<Shared>()) {
  config_.loader_threads = std::max(config_.loader_threads, 1u);
  config_.max_in_flight = std::max(config_.max_in_flight, 1u);
  init_stream_residency(state_, node_bytes, config_.budget_bytes);
  const size_t n = node_bytes.size();
  payloads_.resize(n);
  update_.loaded.reserve(n);
  update_.evicted.reserve(n);
  update_.dropped.reserve(config_.max_in_flight);
  update_.issued.reserve(config_.max_in_flight);
  too_large_.reserve(n);
  issue_buf_.resize(config_.max_in_flight);
  evict_buf_.resize(n);
  too_large_buf_.resize(n);
  shared_->load = std::move(load);
  shared_->queue.reserve(config_.max_in_flight);
  shared_->done.reserve(config_.max_in_flight);
  shared_->taken.reserve(config_.max_in_flight);
  for (uint32_t i = 0; i < config_.loader_threads; ++i)
    shared_->threads.emplace_back(loader_loop, std::ref(*shared_));
}

StreamPager::~StreamPager() {
  {
    std::lock_guard lock(shared_->mutex);
    shared_->stop = true;
  }
  shared_->wake.notify_all();
  for (std::thread& t : shared_->threads) t.join();
}

void StreamPager::take_completions(uint64_t frame) {
  Shared& sh = *shared_;
  {
    std::lock_guard lock(sh.mutex);
    std::swap(sh.done, sh.taken);
  }
  for (Completion& c : sh.taken) {
    // The budget reserved what the tree says; a payload that takes more (a lying or corrupt
    // source) would break it, so it is refused like any bad node.
    if (c.status.ok && payload_bytes(*c.payload) > state_.bytes[c.node]) {
      c.status = Status::error("its payload takes " + std::to_string(payload_bytes(*c.payload)) +
                               " bytes, more than the " + std::to_string(state_.bytes[c.node]) +
                               " its node records");
    }
    if (c.status.ok) {
      stream_loaded(state_, c.node, frame);
      payloads_[c.node] = std::move(c.payload);
      update_.loaded.push_back(c.node);
    } else {
      // Failed for good: reported here once, never issued again; its parent stays drawn.
      stream_failed(state_, c.node);
      update_.failures.push_back({c.node, node_message(c.node, c.status.message), c.status.message});
    }
  }
  sh.taken.clear();
}

void StreamPager::requeue(uint64_t frame, std::span<const HlodRequest> wanted) {
  Shared& sh = *shared_;
  {
    std::lock_guard lock(sh.mutex);
    // Stale: queued, not read yet, and not wanted by this frame's cut.
    const auto stale = std::remove_if(sh.queue.begin(), sh.queue.end(), [&](uint32_t n) {
      if (stream_wanted(state_, n, frame)) return false;
      stream_dropped(state_, n);
      update_.dropped.push_back(n);
      return true;
    });
    sh.queue.erase(stale, sh.queue.end());
    const StreamPlan plan = plan_stream_loads(issue_buf_, evict_buf_, too_large_buf_, state_, frame, wanted,
                                              config_.max_in_flight);
    update_.issued.assign(issue_buf_.begin(), issue_buf_.begin() + plan.issued);
    update_.evicted.assign(evict_buf_.begin(), evict_buf_.begin() + plan.evicted);
    too_large_.assign(too_large_buf_.begin(), too_large_buf_.begin() + plan.too_large);
    sh.queue.insert(sh.queue.end(), update_.issued.begin(), update_.issued.end());
    // This frame's priorities: the best (lowest rank) at the back, where loaders take.
    std::sort(sh.queue.begin(), sh.queue.end(),
              [&](uint32_t a, uint32_t b) { return state_.rank[a] > state_.rank[b]; });
  }
  // One loader per new node: waking them all would only have them compete for the cores.
  for (size_t i = 0; i < update_.issued.size(); ++i) sh.wake.notify_one();
  for (uint32_t n : update_.evicted) payloads_[n].reset();
  for (uint32_t n : too_large_) {
    std::string why = "needs " + std::to_string(state_.bytes[n]) + " bytes, more than the stream budget of " +
                      std::to_string(state_.budget);
    update_.failures.push_back({n, node_message(n, why), why});
  }
}

const StreamUpdate& StreamPager::update(uint64_t frame, std::span<const HlodRequest> wanted,
                                        std::span<const uint32_t> in_use) {
  update_.loaded.clear();
  update_.evicted.clear();
  update_.dropped.clear();
  update_.issued.clear();
  update_.failures.clear();
  take_completions(frame);
  mark_stream_frame(state_, frame, wanted, in_use);
  requeue(frame, wanted);
  return update_;
}

}  // namespace lod
