#include "cli/run_outputs.h"

#include <nlohmann/json.hpp>

#include "runtime/file_write.h"

namespace lod::cli {

std::string indent_lines(const std::string& text, int spaces, bool first) {
  const std::string pad(size_t(spaces), ' ');
  std::string out;
  out.reserve(text.size() + text.size() / 8);
  if (first && !text.empty()) out += pad;
  for (size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] == '\n' && i + 1 < text.size()) out += pad;
  }
  return out;
}

Status RunOutputs::open(const std::filesystem::path& json_file, const std::filesystem::path& report_dir) {
  report_dir_ = report_dir;
  if (!report_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(report_dir, ec);
    if (ec) return Status::error(report_dir.string() + ": cannot create report directory: " + ec.message());
    if (auto st = csv_.open(report_dir / "frames.csv"); !st) return st;
    csv_.write(csv_header());
  }
  if (!json_file.empty()) {
    if (auto st = json_.open(json_file); !st) return st;
    json_.write("{\n \"frames\": [");  // nlohmann's dump(1): the document's keys in order, frames first
  }
  return Status::success();
}

Status RunOutputs::add(const FrameRecord& r) {
  plots_.add(r);
  if (json_.is_open()) {
    // An element of the top object's array: two spaces deeper than dumped alone.
    json_.write(frames_ == 0 ? "\n" : ",\n");
    json_.write(indent_lines(frame_json(r).dump(1), 2));
    if (!json_.ok()) return json_.status();
  }
  if (csv_.is_open()) {
    csv_.write(csv_row(r));
    if (!csv_.ok()) return csv_.status();
  }
  ++frames_;
  return Status::success();
}

Status RunOutputs::finish(const RunSummary& s, const std::string& graph_dot) {
  if (json_.is_open()) {
    json_.write(frames_ == 0 ? "],\n" : "\n ],\n");
    json_.write(" \"summary\": " + indent_lines(summary_json(s).dump(1), 1, false) + "\n}\n");
    if (auto st = json_.close(); !st) return st;
  }
  if (report_dir_.empty()) return Status::success();
  if (auto st = csv_.close(); !st) return st;
  if (auto st = write_file_atomic(report_dir_ / "summary.json", summary_json(s).dump(1) + "\n"); !st) return st;
  if (auto st = write_file_atomic(report_dir_ / "graph.dot", graph_dot); !st) return st;
  return plots_.write(report_dir_, s);
}

}  // namespace lod::cli
