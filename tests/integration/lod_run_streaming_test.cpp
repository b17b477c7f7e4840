// `lod run` over long runs: every frame streamed to the files, the summary agreeing with them,
// and runs bounded by --max-seconds or stopped by a signal ending with whole files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "run_cli.h"
#include "test_support.h"

namespace {

using lod::test::read_json;
using lod::test::run_lod;

// frames.csv: the header's names and every row's numbers.
struct Csv {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  size_t column(const std::string& name) const {
    return size_t(std::find(columns.begin(), columns.end(), name) - columns.begin());
  }
};

Csv read_csv(const std::filesystem::path& p) {
  Csv csv;
  std::ifstream f(p);
  std::string line;
  std::getline(f, line);
  std::stringstream h(line);
  for (std::string c; std::getline(h, c, ',');) csv.columns.push_back(c);
  while (std::getline(f, line)) {
    std::stringstream r(line);
    std::vector<double> row;
    for (std::string c; std::getline(r, c, ',');) row.push_back(std::stod(c));
    csv.rows.push_back(std::move(row));
  }
  return csv;
}

std::string run_args(const std::filesystem::path& cfg, const std::filesystem::path& dir) {
  return "run --config " + cfg.string() + " --quiet --cache " + (dir / "cache").string() + " --report " +
         (dir / "report").string();
}

TEST(LodRunStreaming, FilesHoldEveryFrameAndTheSummaryAgreesWithThem) {
  const auto dir = lod::test::temp_dir("lodrun-stream");
  const auto cfg = lod::test::balls_and_pebbles(dir, 150000, "[1.0, 0.5, 0.25, 0.12, 0.06]");
  const uint64_t frames = 300;
  auto r = run_lod(run_args(cfg, dir) + " --frames " + std::to_string(frames) + " --json " + (dir / "run.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = read_json(dir / "run.json");
  const auto csv = read_csv(dir / "report" / "frames.csv");
  const auto& s = j["summary"];
  ASSERT_EQ(j["frames"].size(), frames);
  ASSERT_EQ(csv.rows.size(), frames);
  EXPECT_EQ(s["frames"].get<uint64_t>(), frames);
  EXPECT_EQ(s["frames_requested"].get<uint64_t>(), frames);
  EXPECT_EQ(s["stopped_by"], "frames");
  EXPECT_EQ(s["percentile_relative_error"].get<double>(), 0.0) << "a short run's percentiles are exact";
  EXPECT_EQ(s["plot_frames_per_bucket"].get<uint64_t>(), 1u);
  EXPECT_EQ(read_json(dir / "report" / "summary.json"), s);

  // The rows are the frames, in order, the same in both files; the summary is made of them.
  const size_t c_frame = csv.column("frame"), c_sel = csv.column("tris_selected"), c_over = csv.column("over_budget"),
               c_total = csv.column("total_ms");
  ASSERT_LT(c_total, csv.columns.size());
  uint64_t over = 0;
  double selected = 0, max_ms = 0;
  std::vector<double> totals;
  for (size_t i = 0; i < frames; ++i) {
    const auto& f = j["frames"][i];
    const auto& row = csv.rows[i];
    ASSERT_EQ(row.size(), csv.columns.size()) << "row " << i;
    EXPECT_EQ(f["frame"].get<double>(), row[c_frame]);
    if (i > 0) {
      EXPECT_EQ(f["frame"].get<uint64_t>(), j["frames"][i - 1]["frame"].get<uint64_t>() + 1);
    }
    EXPECT_EQ(f["tris_selected"].get<double>(), row[c_sel]);
    EXPECT_EQ(f["over_budget"].get<bool>(), row[c_over] != 0);
    over += f["over_budget"].get<bool>();
    selected += f["tris_selected"].get<double>();
    const double ms = f["ms"]["total"].get<double>();
    max_ms = std::max(max_ms, ms);
    totals.push_back(ms);
  }
  std::sort(totals.begin(), totals.end());
  EXPECT_EQ(s["over_budget_frames"].get<uint64_t>(), over);
  EXPECT_NEAR(s["mean_tris_selected"].get<double>(), selected / double(frames), 1e-9 * selected);
  EXPECT_EQ(s["max_ms"].get<double>(), max_ms);
  EXPECT_DOUBLE_EQ(s["median_ms"].get<double>(), 0.5 * (totals[149] + totals[150]));
  for (const char* f : {"triangles.svg", "drawn.svg", "levels.svg", "level_changes.svg", "pixel_error.svg",
                        "stage_ms.svg", "graph.dot"})
    EXPECT_TRUE(std::filesystem::exists(dir / "report" / f)) << f;
  for (const auto& e : std::filesystem::directory_iterator(dir / "report"))
    EXPECT_NE(e.path().extension(), ".tmp") << "no temporary left: " << e.path();
}

// The most frames --frames takes: the run starts at once (nothing sized by the frame count),
// --max-seconds ends it with exit 0, and what it wrote is whole and bounded.
TEST(LodRunStreaming, MaxSecondsBoundsTheLongestRun) {
  const auto dir = lod::test::temp_dir("lodrun-max-seconds");
  const auto cfg = lod::test::balls_and_pebbles(dir, 150000, "[1.0, 0.5, 0.25, 0.12, 0.06]");
  auto r = run_lod(run_args(cfg, dir) + " --frames 100000000 --max-seconds 2");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("stopped by --max-seconds 2 after"), std::string::npos) << r.out;
  const auto s = read_json(dir / "report" / "summary.json");
  EXPECT_EQ(s["stopped_by"], "max_seconds");
  EXPECT_EQ(s["max_seconds"].get<double>(), 2.0);
  EXPECT_EQ(s["frames_requested"].get<uint64_t>(), 100000000u);
  const uint64_t frames = s["frames"].get<uint64_t>();
  EXPECT_GT(frames, 0u);
  EXPECT_LT(frames, 100000000u);
  EXPECT_EQ(read_csv(dir / "report" / "frames.csv").rows.size(), frames) << "a row for every frame run";
  for (const char* f : {"triangles.svg", "stage_ms.svg", "levels.svg"})
    EXPECT_LT(std::filesystem::file_size(dir / "report" / f), 1u << 20) << f << ": the plots' size is bounded";
}

// SIGTERM (as `timeout` sends it): the run stops, writes whole files and its summary, and exits
// 128 + 15.
TEST(LodRunStreaming, ASignalStopsTheRunWithWholeFiles) {
  const auto dir = lod::test::temp_dir("lodrun-signal");
  const auto cfg = lod::test::balls_and_pebbles(dir, 150000, "[1.0, 0.5, 0.25, 0.12, 0.06]");
  // Baked first, so that the signal comes during the frames.
  ASSERT_EQ(run_lod(run_args(cfg, dir) + " --frames 2").code, 0);
  auto r = lod::test::run_shell("timeout --preserve-status -s TERM 2 " + std::string(LOD_CLI_PATH) + " " +
                                run_args(cfg, dir) + " --frames 100000000 --json " + (dir / "run.json").string());
  ASSERT_EQ(r.code, 128 + 15) << r.out;
  EXPECT_NE(r.out.find("stopped by SIGTERM after"), std::string::npos) << r.out;
  const auto s = read_json(dir / "report" / "summary.json");
  EXPECT_EQ(s["stopped_by"], "signal");
  EXPECT_EQ(s["stop_signal"].get<int>(), 15);
  const uint64_t frames = s["frames"].get<uint64_t>();
  EXPECT_GT(frames, 0u);
  EXPECT_EQ(read_csv(dir / "report" / "frames.csv").rows.size(), frames);
  const auto j = read_json(dir / "run.json");
  EXPECT_EQ(j["frames"].size(), frames);
  EXPECT_EQ(j["summary"], s);
}

}  // namespace
