// docs/cli.md against the programs: every flag a command's --help prints is documented in that
// command's section, and every flag the section's option list shows is one the command takes.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "integration/run_cli.h"

namespace {

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The text under `heading` (a whole line) up to the next heading of any level.
std::string section(const std::string& doc, const std::string& heading) {
  const size_t at = doc.find("\n" + heading + "\n");
  if (at == std::string::npos) return {};
  const size_t body = at + heading.size() + 2;
  const size_t end = doc.find("\n#", body);
  return doc.substr(body, end == std::string::npos ? std::string::npos : end - body);
}

// The long flags an option list names: "--name" at the start of an option line
// ("  -h,--help", "  --frames INT", "  --cache TEXT ...").
std::set<std::string> listed_flags(const std::string& text) {
  static const std::regex option_line(R"(^\s+(?:-\w,)?(--[a-z0-9][a-z0-9-]*))");
  std::set<std::string> flags;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_search(line, m, option_line)) flags.insert(m[1]);
  }
  return flags;
}

// The fenced option list of a section (the first ``` block).
std::string fenced_block(const std::string& text) {
  const size_t open = text.find("```");
  if (open == std::string::npos) return {};
  const size_t body = text.find('\n', open) + 1;
  const size_t close = text.find("```", body);
  return text.substr(body, close == std::string::npos ? std::string::npos : close - body);
}

class CliDocs : public ::testing::TestWithParam<const char*> {};

TEST_P(CliDocs, EveryFlagOfTheCommandIsDocumentedAndNoOther) {
  const std::string doc = read_text(std::filesystem::path(LOD_SOURCE_DIR) / "docs" / "cli.md");
  ASSERT_FALSE(doc.empty()) << "docs/cli.md is missing or empty";
  const std::string command = GetParam();
  const std::string part = section(doc, "### `lod " + command + "`");
  ASSERT_FALSE(part.empty()) << "docs/cli.md has no section \"### `lod " << command << "`\"";

  const lod::test::CliResult help = lod::test::run_lod(command + " --help");
  ASSERT_EQ(help.code, 0) << help.out;
  const std::set<std::string> taken = listed_flags(help.out);
  ASSERT_GT(taken.size(), 1u) << "no options read from `lod " << command << " --help`:\n" << help.out;
  for (const std::string& flag : taken) {
    if (flag == "--help") continue;  // every command's; the page says so once
    EXPECT_NE(part.find(flag), std::string::npos) << "`lod " << command << "` takes " << flag
                                                  << ", which docs/cli.md does not document";
  }
  for (const std::string& flag : listed_flags(fenced_block(part)))
    EXPECT_TRUE(taken.count(flag)) << "docs/cli.md lists " << flag << " for `lod " << command
                                   << "`, which the command does not take";
}

INSTANTIATE_TEST_SUITE_P(LodCommands, CliDocs, ::testing::Values("run", "bake", "inspect", "export"));

}  // namespace
