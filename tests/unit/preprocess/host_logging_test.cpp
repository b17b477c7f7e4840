// Loading meshes must not touch the host's standard streams: a host thread logging to
// std::cerr / std::cout while lodkit reads meshes loses nothing, and the streams keep the
// buffers the host gave them. (The host does not write to OpenMesh's omerr() here while
// loads run: two threads formatting into one non-standard std::ostream race on its state
// whatever lodkit does; openmesh_log_capture_test covers other threads' omerr() lines.)
#include "preprocess/mesh_io.h"

#include <gtest/gtest.h>

#include <atomic>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

// Lines of `text`, in order.
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// Puts a stream's buffer back even when an assertion returns early.
struct RdbufRestore {
  std::ostream& stream;
  std::streambuf* saved;
  ~RdbufRestore() { stream.rdbuf(saved); }
};

TEST(HostLogging, ConcurrentLoadsNeitherSwallowNorRedirectTheHostsStreams) {
  const fs::path dir = test::temp_dir("io-host-logging");
  // The undefined material makes OpenMesh's OBJ reader complain on omerr() on every load.
  test::write_text(dir / "chatty.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl nothing\nf 1 2 3\n");
  test::write_text(dir / "sphere.off", test::sphere_off(20, 30));
  {
    // Warm-up: the first load sets up lodkit's routing of OpenMesh's streams; done here so
    // the measured part below is the steady state every later load runs in.
    MeshData m;
    ASSERT_TRUE(load_mesh(dir / "chatty.obj", m).ok);
  }

  std::ostringstream host_err, host_out;
  RdbufRestore keep_err{std::cerr, std::cerr.rdbuf(host_err.rdbuf())};
  RdbufRestore keep_out{std::cout, std::cout.rdbuf(host_out.rdbuf())};
  std::streambuf* const err_buf = host_err.rdbuf();
  std::streambuf* const out_buf = host_out.rdbuf();

  std::atomic<int> loaders_left{2};
  std::atomic<bool> writing{false};
  std::atomic<int> load_failures{0};
  int written = 0;
  int rdbuf_changes = 0;
  std::thread host([&] {
    writing = true;
    // Keep logging for as long as any load runs, and at least a few hundred lines.
    for (int i = 0; loaders_left.load() > 0 || i < 300; ++i) {
      std::cerr << "cerr " << i << '\n';
      std::cout << "cout " << i << '\n';
      if (std::cerr.rdbuf() != err_buf || std::cout.rdbuf() != out_buf) ++rdbuf_changes;
      written = i + 1;
    }
  });
  std::vector<std::thread> loaders;
  for (int t = 0; t < 2; ++t)
    loaders.emplace_back([&, t] {
      while (!writing) std::this_thread::yield();
      for (int i = 0; i < 40; ++i) {
        MeshData m;
        if (!load_mesh(dir / ((t + i) % 2 ? "chatty.obj" : "sphere.off"), m).ok) ++load_failures;
      }
      --loaders_left;
    });
  for (std::thread& th : loaders) th.join();
  host.join();

  EXPECT_EQ(load_failures.load(), 0);
  EXPECT_EQ(rdbuf_changes, 0);
  EXPECT_EQ(std::cerr.rdbuf(), err_buf);
  EXPECT_EQ(std::cout.rdbuf(), out_buf);

  // Exactly the host's lines, in order: none lost, and none of OpenMesh's chatter about the
  // loads' material (that went into lodkit's capture).
  std::vector<std::string> want_err, want_out;
  for (int i = 0; i < written; ++i) {
    want_err.push_back("cerr " + std::to_string(i));
    want_out.push_back("cout " + std::to_string(i));
  }
  EXPECT_EQ(lines_of(host_err.str()), want_err);
  EXPECT_EQ(lines_of(host_out.str()), want_out);
}

}  // namespace
}  // namespace lod
