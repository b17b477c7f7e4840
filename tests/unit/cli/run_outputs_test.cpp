// RunOutputs and RunTotals: the streamed --json file and frames.csv hold every frame, the JSON
// exactly as dumping the whole document would; the summary agrees with the frames; the plots
// stay the same size however long the run.
#include "cli/run_outputs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli/run_totals.h"
#include "cli/svg_plot.h"
#include "test_support.h"

namespace {

using namespace lod::cli;

std::string read_all(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// A frame whose figures vary with n, one of them a spike.
FrameRecord frame(uint64_t n) {
  FrameRecord r;
  r.frame = n + 1;
  r.objects = 100;
  r.visible = uint32_t(40 + n % 13);
  r.tris_in_view = 100000 + 37 * (n % 101);
  r.tris_selected = 50000 + 11 * (n % 17);
  r.budget = 50100;
  r.over_budget = n % 9 == 0;
  r.lowered_steps = uint32_t(n % 3);
  r.levels[0] = r.visible - 10;
  r.levels[2] = 10;
  r.chain_levels[0] = r.visible - 10;
  r.chain_levels[2] = 10;
  for (size_t s = 0; s < lod::kStageCount; ++s) r.stage_ms[s] = 0.001 * double((n * (s + 3)) % 29);
  r.total_ms = n == 57 ? 40.0 : 0.25 + 0.01 * double(n % 23);
  r.tris_morph_extra = n % 5;
  r.benefit = 1.5 * double(n % 7);
  r.benefit_optimum_fraction = n % 4 == 0 ? 0.9 + 0.001 * double(n % 50) : -1;
  r.pixel_error_max = float(n % 6);
  r.pixel_error_mean = 0.5f;
  r.level_changes = uint32_t(n % 8);
  return r;
}

RunSummary summary_of(const std::vector<FrameRecord>& frames, size_t exact = 16384) {
  RunTotals t(exact);
  for (const auto& r : frames) t.add(r);
  RunSummary s;
  s.config = "scene.toml";
  s.frames_requested = frames.size();
  t.fill(s);
  return s;
}

TEST(RunOutputs, TheJsonFileIsTheWholeDocumentDumpedAndTheCsvHasARowPerFrame) {
  for (size_t n : {size_t(0), size_t(1), size_t(3), size_t(300)}) {
    const auto dir = lod::test::temp_dir("run-outputs");
    std::vector<FrameRecord> frames;
    RunOutputs out;
    ASSERT_TRUE(out.open(dir / "run.json", dir / "report"));
    for (uint64_t i = 0; i < n; ++i) {
      frames.push_back(frame(i));
      ASSERT_TRUE(out.add(frames.back()));
    }
    const RunSummary s = summary_of(frames);
    ASSERT_TRUE(out.finish(s, "digraph {}\n"));

    nlohmann::json whole;
    whole["frames"] = nlohmann::json::array();
    for (const auto& r : frames) whole["frames"].push_back(frame_json(r));
    whole["summary"] = summary_json(s);
    EXPECT_EQ(read_all(dir / "run.json"), whole.dump(1) + "\n") << n << " frames";

    std::string csv = csv_header();
    for (const auto& r : frames) csv += csv_row(r);
    EXPECT_EQ(read_all(dir / "report" / "frames.csv"), csv);
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), std::ptrdiff_t(n + 1));
    EXPECT_EQ(nlohmann::json::parse(read_all(dir / "report" / "summary.json")), summary_json(s));
    for (const char* f : {"triangles.svg", "drawn.svg", "levels.svg", "level_changes.svg", "pixel_error.svg",
                          "stage_ms.svg", "graph.dot"})
      EXPECT_TRUE(std::filesystem::exists(dir / "report" / f)) << f;
  }
}

TEST(RunOutputs, PlotsKeepAFixedSizeAndNameTheirBuckets) {
  const auto dir = lod::test::temp_dir("run-plots");
  RunOutputs out;
  ASSERT_TRUE(out.open("", dir));
  for (uint64_t i = 0; i < 20000; ++i) ASSERT_TRUE(out.add(frame(i)));
  RunSummary s;
  ASSERT_TRUE(out.finish(s, ""));
  EXPECT_EQ(out.frames(), 20000u);
  EXPECT_EQ(out.frames_per_bucket(), 32u);  // 1024 buckets of a power of two frames
  const std::string svg = read_all(dir / "stage_ms.svg");
  EXPECT_NE(svg.find("each bucket of 32 frames"), std::string::npos);
  // Every polyline: at most two points per bucket; the 40 ms spike of frame 57 is drawn.
  size_t at = 0, lines = 0;
  while ((at = svg.find("points='", at)) != std::string::npos) {
    const size_t end = svg.find('\'', at + 8);
    const std::string pts = svg.substr(at + 8, end - at - 8);
    EXPECT_LE(size_t(std::count(pts.begin(), pts.end(), ',')), 2048u);
    at = end;
    ++lines;
  }
  EXPECT_EQ(lines, lod::kStageCount + 1);
  EXPECT_LT(svg.size(), 400000u) << "bounded";
}

TEST(SvgLinePlot, DrawsValuesAtTheirFramesAndAnEmptyLogPlot) {
  PlotOptions o;
  o.width = 100 + 80 + 180;  // 100 pixels of plot
  const std::string at = svg_line_plot({{"a", "#000", {1.0, 2.0}, false, {0.0, 50.0}}, {"b", "#000", {1.0}, false, {100.0}}}, o);
  EXPECT_NE(at.find("points='80,"), std::string::npos) << at;
  EXPECT_NE(at.find(" 130,"), std::string::npos) << "frame 50 of 100 halfway" << at;
  o.log_y = true;
  const std::string empty = svg_line_plot({{"a", "#000", {}, false, {}}}, o);
  EXPECT_NE(empty.find("</svg>"), std::string::npos);
}

TEST(RunTotals, SummarizesEveryFrameExactlyWhileThePercentilesFit) {
  std::vector<FrameRecord> frames;
  for (uint64_t i = 0; i < 500; ++i) frames.push_back(frame(i));
  const RunSummary s = summary_of(frames);
  EXPECT_EQ(s.frames, 500u);
  size_t over = 0, binding = 0, optimum = 0;
  double sel = 0, drawn = 0, maxms = 0, opt_min = 1;
  std::vector<double> totals;
  for (const auto& r : frames) {
    over += r.over_budget;
    binding += r.over_budget || r.lowered_steps > 0;
    sel += double(r.tris_selected);
    drawn += double(r.drawn());
    maxms = std::max(maxms, r.total_ms);
    totals.push_back(r.total_ms);
    if (r.benefit_optimum_fraction >= 0) ++optimum, opt_min = std::min(opt_min, r.benefit_optimum_fraction);
  }
  std::sort(totals.begin(), totals.end());
  EXPECT_EQ(s.over_budget_frames, over);
  EXPECT_EQ(s.binding_frames, binding);
  EXPECT_EQ(s.optimum_frames, optimum);
  EXPECT_EQ(s.min_benefit_optimum_fraction, opt_min);
  EXPECT_DOUBLE_EQ(s.mean_tris_selected, sel / 500);
  EXPECT_DOUBLE_EQ(s.mean_tris_drawn, drawn / 500);
  EXPECT_EQ(s.max_ms, 40.0);
  EXPECT_DOUBLE_EQ(s.median_ms, 0.5 * (totals[249] + totals[250]));
  EXPECT_EQ(s.percentile_relative_error, 0.0);
}

TEST(RunTotals, SaysWhenItsPercentilesBecomeApproximate) {
  std::vector<FrameRecord> frames;
  for (uint64_t i = 0; i < 500; ++i) frames.push_back(frame(i));
  const RunSummary exact = summary_of(frames), approx = summary_of(frames, 100);
  EXPECT_EQ(approx.percentile_relative_error, lod::cli::QuantileSketch::kRelativeError);
  EXPECT_NEAR(approx.median_ms, exact.median_ms, 0.02 * exact.median_ms);
  EXPECT_EQ(approx.max_ms, exact.max_ms) << "the maximum stays exact";
  EXPECT_EQ(approx.mean_ms, exact.mean_ms) << "and the means";
  EXPECT_NE(summary_text(approx).find("approximate"), std::string::npos);
  EXPECT_EQ(summary_text(exact).find("approximate"), std::string::npos);
}

TEST(RunOutputs, IndentsLinesAsNlohmannNestsThem) {
  EXPECT_EQ(indent_lines("{\n \"a\": 1\n}", 2), "  {\n   \"a\": 1\n  }");
  EXPECT_EQ(indent_lines("{\n \"a\": 1\n}", 1, false), "{\n  \"a\": 1\n }");
  EXPECT_EQ(indent_lines("", 2), "");
}

}  // namespace
