// Ranks as threads for the distributed bakes' tests: HlodRankComm's two collectives over
// shared slots and a barrier, so N threads run one job as N MPI ranks would.
#pragma once
#include <barrier>
#include <cstdint>
#include <vector>

#include "jobs/hlod_distributed_bake.h"

namespace lod::test {

struct ThreadRanks {
  explicit ThreadRanks(int n) : size(n), sync(n), slots(size_t(n)) {}
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
    return c;
  }
  int size;
  std::barrier<> sync;
  std::vector<std::vector<uint8_t>> slots;
};

}  // namespace lod::test
