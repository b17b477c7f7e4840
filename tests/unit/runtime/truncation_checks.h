// The check every file reader's tests make: an encoded file cut short at each length is
// refused, the message naming the file first. Shared by the .lod and .hlod reader tests.
#pragma once
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/status.h"

namespace lod::test {

// `decode(prefix)` for every prefix of `bytes` shorter than it, shortest first: each must return
// a refusal whose message starts with "`name`: " (the decode's own checks, such as its output
// left untouched, go in `decode`). Stops at the first prefix accepted.
template <class Decode>
void expect_every_truncation_refused(const std::vector<uint8_t>& bytes, const std::string& name, Decode&& decode) {
  for (size_t len = 0; len < bytes.size(); ++len) {
    const Status st = decode(std::span<const uint8_t>(bytes).first(len));
    ASSERT_FALSE(st) << "accepted a file cut to " << len << " of " << bytes.size() << " bytes";
    EXPECT_EQ(st.message.rfind(name + ": ", 0), 0u) << st.message;
  }
}

}  // namespace lod::test
