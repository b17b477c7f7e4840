// RunOutputs: the files `lod run` writes, filled as frames come. Each frame's object goes to the
// --json file and its row to the report's frames.csv as soon as it is added (StreamedFile:
// bounded memory, the file appears under its name only when whole); what needs every frame
// (the summary, the plots) is written by finish() from RunTotals and RunPlots, which hold a
// bounded amount whatever the run's length. The --json file is byte for byte what dumping the
// whole document with nlohmann::json's dump(1) gives: {"frames": [...], "summary": {...}}.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

#include "cli/run_plots.h"
#include "cli/run_report.h"
#include "cli/streamed_file.h"

namespace lod::cli {

class RunOutputs {
 public:
  // Either may be empty (not written). The report's folder is created here.
  Status open(const std::filesystem::path& json_file, const std::filesystem::path& report_dir);
  // The frame's JSON object and CSV row; an error (a full disk) names the file.
  Status add(const FrameRecord& r);
  uint64_t frames() const { return frames_; }
  uint64_t frames_per_bucket() const { return plots_.frames_per_bucket(); }
  // Closes the --json file with the summary, the report's frames.csv, and writes its
  // summary.json, graph.dot and plots.
  Status finish(const RunSummary& s, const std::string& graph_dot);

 private:
  std::filesystem::path report_dir_;
  StreamedFile json_, csv_;
  RunPlots plots_;
  uint64_t frames_ = 0;
  std::string scratch_;
};

// `text` with `spaces` spaces before every line (before the first one too when `first`).
std::string indent_lines(const std::string& text, int spaces, bool first = true);

}  // namespace lod::cli
