// Ranks as threads for the distributed bakes' tests: HlodRankComm's two collectives over
// shared slots and a barrier, so N threads run one job as N MPI ranks would. With
// `per_node` > 1, consecutive ranks form nodes that share memory (node_buffer), as the ranks
// of one machine do under MPI.
#pragma once
#include <algorithm>
#include <barrier>
#include <cstdint>
#include <deque>
#include <memory>
#include <span>
#include <vector>

#include "jobs/hlod_distributed_bake.h"

namespace lod::test {

struct ThreadRanks {
  explicit ThreadRanks(int n, int node_ranks = 1) : size(n), per_node(node_ranks), sync(n), slots(size_t(n)) {
    for (int first = 0; first < n; first += per_node)
      nodes.push_back(std::make_unique<Node>(std::min(per_node, n - first)));
  }
  HlodRankComm comm(int rank) {
    HlodRankComm c;
    c.rank = rank;
    c.size = size;
    c.broadcast = [this, rank](std::vector<uint8_t>& bytes) {
      if (rank == 0) slots[0] = bytes;
      sync.arrive_and_wait();
      if (rank != 0) bytes = slots[0];
      sync.arrive_and_wait();
    };
    c.gather = [this, rank](const std::vector<uint8_t>& mine) {
      slots[size_t(rank)] = mine;
      sync.arrive_and_wait();
      std::vector<std::vector<uint8_t>> all;
      if (rank == 0) all = slots;
      sync.arrive_and_wait();
      return all;
    };
    if (per_node > 1) {
      add_node(c, *nodes[size_t(rank / per_node)], rank % per_node == 0);
      for (int r = 0; r < size; ++r) c.node_of.push_back(r / per_node * per_node);
    }
    return c;
  }

  struct Node {
    explicit Node(int n) : ranks(n), sync(n) {}
    int ranks;
    std::barrier<> sync;
    std::deque<std::vector<uint64_t>> buffers;  // 8-byte words: aligned for any array in them
    std::deque<size_t> sizes;
    uint64_t memory = UINT64_MAX;  // what a node buffer may hold
  };
  static void add_node(HlodRankComm& c, Node& node, bool first) {
    c.node_size = node.ranks;
    c.node_first = first;
    c.node_barrier = [&node] { node.sync.arrive_and_wait(); };
    c.node_buffer = [&node, first](uint64_t bytes) {
      if (first) {
        if (bytes > node.memory) bytes = 0;  // as MPI when /dev/shm cannot hold it
        node.buffers.emplace_back(size_t((bytes + 7) / 8));
        node.sizes.push_back(size_t(bytes));
      }
      node.sync.arrive_and_wait();
      std::span<uint8_t> out(reinterpret_cast<uint8_t*>(node.buffers.back().data()), node.sizes.back());
      node.sync.arrive_and_wait();
      return out;
    };
    c.node_release = [&node, first] {
      node.sync.arrive_and_wait();
      if (first) node.buffers.clear(), node.sizes.clear();
      node.sync.arrive_and_wait();
    };
  }

  int size, per_node;
  std::barrier<> sync;
  std::vector<std::vector<uint8_t>> slots;
  std::vector<std::unique_ptr<Node>> nodes;
};

}  // namespace lod::test
