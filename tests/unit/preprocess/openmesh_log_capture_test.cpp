// OpenMeshLogCapture: the capturing thread's OpenMesh messages land in text(), on one line;
// other threads' go where they always went.
#include "preprocess/openmesh_log_capture.h"

#include <gtest/gtest.h>

#include <OpenMesh/Core/System/omstream.hh>

#include <iostream>
#include <sstream>
#include <string>
#include <thread>

namespace lod::detail {
namespace {

// Redirects std::cerr (where omerr() forwards) for one test; restored even on early return.
class CerrToString {
 public:
  CerrToString() : saved_(std::cerr.rdbuf(text_.rdbuf())) {}
  ~CerrToString() { std::cerr.rdbuf(saved_); }
  std::string str() const { return text_.str(); }

 private:
  std::ostringstream text_;
  std::streambuf* saved_;
};

TEST(OpenMeshLogCapture, CollectsThisThreadsMessagesOnOneLine) {
  CerrToString terminal;
  std::string said;
  {
    OpenMeshLogCapture capture;
    ::omerr() << "first  line\n\tsecond" << '\n';
    ::omout() << "from omout\n";
    said = capture.text();
  }
  EXPECT_EQ(said, "first line second from omout");
  EXPECT_EQ(terminal.str(), "");
  ::omerr() << "after\n";  // no capture any more: to the terminal again
  EXPECT_EQ(terminal.str(), "after\n");
}

TEST(OpenMeshLogCapture, LeavesOtherThreadsMessagesAlone) {
  CerrToString terminal;
  OpenMeshLogCapture capture;
  std::thread other([] { ::omerr() << "other thread\n"; });
  other.join();
  ::omerr() << "this thread\n";
  EXPECT_EQ(capture.text(), "this thread");
  EXPECT_EQ(terminal.str(), "other thread\n");
}

TEST(OpenMeshLogCapture, NestsAndStaysSilentForADisabledStream) {
  CerrToString terminal;
  OpenMeshLogCapture outer;
  ::omerr() << "outer a\n";
  {
    OpenMeshLogCapture inner;
    ::omerr() << "inner\n";
    EXPECT_EQ(inner.text(), "inner");
  }
  ::omerr().disable();
  ::omerr() << "while disabled\n";
  ::omerr().enable();
  ::omerr() << "outer b\n";
  EXPECT_EQ(outer.text(), "outer a outer b");
  EXPECT_EQ(terminal.str(), "");
}

TEST(OpenMeshLogCapture, KeepsLongTextShort) {
  OpenMeshLogCapture capture;
  ::omerr() << std::string(1000, 'x') << '\n';
  const std::string said = capture.text();
  EXPECT_EQ(said.size(), 300u);
  EXPECT_EQ(said.substr(297), "...");
}

}  // namespace
}  // namespace lod::detail
