// The documentation as a user meets it: the README short and the guide pages short, every
// relative link (and its #anchor) resolving, the product speaking of itself rather than of its
// work log (no reference tags, tracker numbers, measurement rounds or machine anecdotes), and
// docs/configuration.md listing exactly the keys the scene config reader accepts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "jobs/scene_config.h"

namespace fs = std::filesystem;

namespace {

const fs::path kRoot = LOD_SOURCE_DIR;
constexpr size_t kReadmeMaxLines = 400;
constexpr size_t kGuidePageLinesBelow = 600;

std::string read_text(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

size_t line_count(const std::string& text) {
  return size_t(std::count(text.begin(), text.end(), '\n')) + (!text.empty() && text.back() != '\n');
}

std::vector<fs::path> markdown_files() {
  std::vector<fs::path> out{kRoot / "README.md"};
  for (const auto& e : fs::directory_iterator(kRoot / "docs"))
    if (e.path().extension() == ".md") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// GitHub's heading anchors: lower case, punctuation dropped, spaces to '-'.
std::set<std::string> heading_anchors(const std::string& text) {
  std::set<std::string> out;
  std::istringstream in(text);
  std::string line;
  bool fence = false;
  while (std::getline(in, line)) {
    if (line.rfind("```", 0) == 0) fence = !fence;
    if (fence || line.empty() || line[0] != '#') continue;
    const size_t start = line.find_first_not_of('#');
    if (start == std::string::npos || line[start] != ' ') continue;
    std::string slug;
    for (char c : line.substr(start + 1)) {
      const unsigned char u = static_cast<unsigned char>(c);
      if (std::isalnum(u) || c == '-' || c == '_') slug += char(std::tolower(u));
      else if (c == ' ') slug += '-';
    }
    out.insert(slug);
  }
  return out;
}

// ---- comments of source files -------------------------------------------------------------

struct Comment {
  size_t line;
  std::string text;
};

// Comments of C and C++ text: // and /* */, outside strings, character literals and raw strings.
std::vector<Comment> c_comments(const std::string& s) {
  std::vector<Comment> out;
  size_t line = 1;
  for (size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (c == '\n') {
      ++line;
    } else if (c == '/' && i + 1 < s.size() && s[i + 1] == '/') {
      const size_t end = s.find('\n', i);
      out.push_back({line, s.substr(i, end == std::string::npos ? std::string::npos : end - i)});
      i = (end == std::string::npos ? s.size() : end) - 1;
    } else if (c == '/' && i + 1 < s.size() && s[i + 1] == '*') {
      const size_t end = std::min(s.find("*/", i + 2), s.size());
      const std::string body = s.substr(i, end - i);
      out.push_back({line, body});
      line += size_t(std::count(body.begin(), body.end(), '\n'));
      i = end + 1;
    } else if (c == 'R' && i + 1 < s.size() && s[i + 1] == '"' &&
               (i == 0 || !(std::isalnum(static_cast<unsigned char>(s[i - 1])) || s[i - 1] == '_'))) {
      const size_t open = s.find('(', i);
      if (open == std::string::npos) break;
      const std::string close = ")" + s.substr(i + 2, open - i - 2) + "\"";
      const size_t end = std::min(s.find(close, open), s.size());
      line += size_t(std::count(s.begin() + long(i), s.begin() + long(end), '\n'));
      i = end + close.size() - 1;
    } else if (c == '"' || (c == '\'' && !(i > 0 && std::isalnum(static_cast<unsigned char>(s[i - 1]))))) {
      for (++i; i < s.size() && s[i] != c && s[i] != '\n'; ++i)
        if (s[i] == '\\') ++i;
      if (i < s.size() && s[i] == '\n') ++line;
    }
  }
  return out;
}

// Comments of TOML, shell and CMake text: from a '#' outside quotes to the end of the line.
std::vector<Comment> hash_comments(const std::string& s) {
  std::vector<Comment> out;
  std::istringstream in(s);
  std::string l;
  for (size_t line = 1; std::getline(in, l); ++line) {
    char quote = 0;
    for (size_t i = 0; i < l.size(); ++i) {
      const char c = l[i];
      if (quote) {
        if (c == '\\') ++i;
        else if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '#' && (i == 0 || (l[i - 1] != '$' && l[i - 1] != '{'))) {
        out.push_back({line, l.substr(i)});
        break;
      }
    }
  }
  return out;
}

bool is_c_source(const fs::path& p) {
  const std::string e = p.extension().string();
  return e == ".h" || e == ".hpp" || e == ".cpp" || e == ".c" || e == ".cc";
}
bool is_hash_source(const fs::path& p) {
  const std::string e = p.extension().string();
  return e == ".toml" || e == ".sh" || e == ".cmake" || e == ".py" || p.filename() == "CMakeLists.txt" ||
         p == kRoot / ".ci" / "run";
}

std::vector<fs::path> source_files() {
  std::vector<fs::path> out;
  for (const char* top : {"cli", "cmake", "configs", "examples", "include", "jobs", "preprocess", "runtime", "scripts",
                          "tests", "viewer", ".ci"}) {
    if (!fs::exists(kRoot / top)) continue;
    for (const auto& e : fs::recursive_directory_iterator(kRoot / top))
      if (e.is_regular_file() && (is_c_source(e.path()) || is_hash_source(e.path()))) out.push_back(e.path());
  }
  out.push_back(kRoot / "CMakeLists.txt");
  return out;
}

// Words of a work log, not of a product. Each is precise enough that ordinary prose passes:
// a numbered round but not "stops early", a tracker number but not "an issue", a reference tag
// but not "R = 1".
struct Rule {
  const char* name;
  std::regex pattern;
};
const std::vector<Rule>& work_log_rules() {
  static const std::vector<Rule> rules = {
      {"a reference tag (R0..R4): name the method and its authors", std::regex(R"(\bR[0-4]\b)")},
      {"an issue number", std::regex(R"(\bissues? #?[0-9]+)", std::regex::icase)},
      {"a measurement round (stop N)", std::regex(R"(\bstops? [0-9]+\b)", std::regex::icase)},
      {"\"session\"", std::regex(R"(\bsessions?\b)", std::regex::icase)},
      {"where the work ran (the branch, the VM or the machine) instead of what the code is",
       std::regex(R"(\bthis (branch|vm|machine)\b)", std::regex::icase)},
  };
  return rules;
}
// Ordinary uses of the word, in code and its comments.
const char* const kSessionAllowed[] = {"mpi session", "viewer session"};

std::string lowered(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// What `text` says that a product should not; empty when nothing.
std::vector<std::string> work_log_words(const std::string& text, bool prose) {
  std::string t = text;
  const std::string low = lowered(t);
  for (const char* ok : kSessionAllowed)
    for (size_t at = low.find(ok); at != std::string::npos; at = low.find(ok, at + 1))
      t.replace(at, std::string(ok).size(), std::string(std::string(ok).size(), ' '));
  std::vector<std::string> found;
  for (const Rule& r : work_log_rules()) {
    std::smatch m;
    if (std::regex_search(t, m, r.pattern)) found.push_back(r.name + std::string(": \"") + m.str() + "\"");
  }
  static const std::regex helper(R"(\bhelpers?\b)", std::regex::icase);
  std::smatch m;  // in prose a helper is a process; in code a helper function is ordinary
  if (prose && std::regex_search(t, m, helper)) found.push_back("\"helper\": \"" + m.str() + "\"");
  return found;
}

}  // namespace

TEST(DocsLayout, ReadmeIsAtMostFourHundredLines) {
  EXPECT_LE(line_count(read_text(kRoot / "README.md")), kReadmeMaxLines);
}

TEST(DocsLayout, EveryGuidePageIsUnderSixHundredLines) {
  size_t pages = 0;
  for (const fs::path& p : markdown_files()) {
    if (p.filename() == "README.md") continue;
    ++pages;
    EXPECT_LT(line_count(read_text(p)), kGuidePageLinesBelow) << p;
  }
  EXPECT_GE(pages, 8u) << "docs/ lost guide pages";
}

TEST(DocsLayout, EveryRelativeLinkAndAnchorResolves) {
  const std::regex link(R"(\]\(([^)\s]+)\))");
  size_t checked = 0;
  for (const fs::path& p : markdown_files()) {
    const std::string text = read_text(p);
    for (auto it = std::sregex_iterator(text.begin(), text.end(), link); it != std::sregex_iterator(); ++it) {
      const std::string target = (*it)[1].str();
      if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0) continue;
      const size_t hash = target.find('#');
      const std::string file = target.substr(0, hash);
      const fs::path resolved = file.empty() ? p : (p.parent_path() / file).lexically_normal();
      ++checked;
      ASSERT_TRUE(fs::exists(resolved)) << p << ": link to " << target << " names no file";
      if (hash != std::string::npos && resolved.extension() == ".md") {
        EXPECT_TRUE(heading_anchors(read_text(resolved)).count(target.substr(hash + 1)))
            << p << ": link to " << target << " names no heading";
      }
    }
  }
  EXPECT_GT(checked, 10u);
}

TEST(ProductText, ReadmeAndDocsSpeakOfTheProductNotOfItsWorkLog) {
  for (const fs::path& p : markdown_files()) {
    std::istringstream in(read_text(p));
    std::string line;
    for (size_t n = 1; std::getline(in, line); ++n)
      for (const std::string& w : work_log_words(line, true)) ADD_FAILURE() << p.string() << ":" << n << ": " << w;
  }
}

TEST(ProductText, CommentsAndConfigsSpeakOfTheProductNotOfItsWorkLog) {
  size_t files = 0;
  for (const fs::path& p : source_files()) {
    const std::string text = read_text(p);
    ++files;
    for (const Comment& c : is_c_source(p) ? c_comments(text) : hash_comments(text))
      for (const std::string& w : work_log_words(c.text, false))
        ADD_FAILURE() << p.string() << ":" << c.line << ": " << w;
  }
  EXPECT_GT(files, 100u);
}

TEST(ProductText, TestNamesSpeakOfBehaviours) {
  const std::regex test(R"(\bTEST(_F|_P)?\(\s*(\w+)\s*,\s*(\w+)\s*\))");
  const std::regex bad(R"(R[0-4](?![0-9a-z])|Issue[0-9]|Stop[0-9]|Session|Helper|ThisBranch|ThisVm|ThisVM|ThisMachine)");
  size_t names = 0;
  for (const fs::path& p : source_files()) {
    if (!is_c_source(p)) continue;
    const std::string text = read_text(p);
    for (auto it = std::sregex_iterator(text.begin(), text.end(), test); it != std::sregex_iterator(); ++it) {
      ++names;
      const std::string name = (*it)[2].str() + "." + (*it)[3].str();
      EXPECT_FALSE(std::regex_search(name, bad)) << p << ": test " << name;
    }
  }
  EXPECT_GT(names, 500u);
}

// The scene config reader refuses an unknown key naming the keys it knows there; probing every
// table with a key nobody uses enumerates what it accepts, with no list kept beside it.
namespace {

constexpr const char* kProbe = "zz_undocumented_probe";

// The keys the reader lists for `table` when given the probe there; nullopt when `table` is
// not a table the reader descends into (as a table or an array of tables).
std::optional<std::set<std::string>> known_keys(const std::string& table) {
  for (const bool array : {false, true}) {
    std::string toml;
    if (!table.empty()) toml = (array ? "[[" : "[") + table + (array ? "]]\n" : "]\n");
    toml += std::string(kProbe) + " = 1\n";
    lod::SceneConfig config;
    const lod::Status s = lod::parse_scene_config(toml, "probe.toml", {}, config, /*objects_optional=*/true);
    const std::string& m = s.message;
    const std::string marker = "unknown key (known here: ";
    const size_t at = m.find(marker);
    if (s.ok || at == std::string::npos || m.find(std::string(kProbe) + ": " + marker) == std::string::npos) {
      if (table.empty()) break;
      continue;
    }
    // The refused key must be the probe in this table, not some other table's complaint.
    const std::string where = m.substr(std::string("probe.toml: ").size(), m.find(std::string(kProbe)) -
                                                                                std::string("probe.toml: ").size());
    std::string expected = table.empty() ? "" : table;
    std::string got = where;
    if (!got.empty() && got.back() == '.') got.pop_back();
    got = std::regex_replace(got, std::regex(R"(\[0\])"), "");
    if (got != expected) continue;
    std::set<std::string> keys;
    std::string list = m.substr(at + marker.size(), m.find(')', at) - at - marker.size());
    std::istringstream in(list);
    for (std::string k; std::getline(in, k, ',');) keys.insert(k.substr(k.find_first_not_of(' ')));
    return keys;
  }
  return std::nullopt;
}

// docs/configuration.md: "## `[table]`" or "## `[[table]]`" headings, each followed by a table
// whose rows start "| `key` |".
std::map<std::string, std::set<std::string>> documented_keys() {
  std::map<std::string, std::set<std::string>> out;
  std::istringstream in(read_text(kRoot / "docs" / "configuration.md"));
  const std::regex heading(R"(^## `\[{1,2}([a-z_.]+)\]{1,2}`\s*$)");
  const std::regex row(R"(^\| `([a-z_0-9]+)` \|)");
  std::string line, current;
  bool in_section = false;
  while (std::getline(in, line)) {
    std::smatch m;
    if (line.rfind("## ", 0) == 0) {
      in_section = std::regex_match(line, m, heading);
      current = in_section ? m[1].str() : "";
      if (in_section) out[current];
    } else if (in_section && std::regex_search(line, m, row)) {
      out[current].insert(m[1].str());
    }
  }
  return out;
}

}  // namespace

TEST(DocsConfiguration, DocumentsExactlyTheKeysTheReaderAccepts) {
  // What the reader accepts: the root's tables, their keys, and any key that is itself a table.
  std::map<std::string, std::set<std::string>> accepted;
  const auto root = known_keys("");
  ASSERT_TRUE(root) << "the reader no longer names the keys it knows when refusing one";
  std::vector<std::string> todo(root->begin(), root->end());
  while (!todo.empty()) {
    const std::string table = todo.back();
    todo.pop_back();
    const auto keys = known_keys(table);
    ASSERT_TRUE(keys) << "the reader knows '" << table << "' at the top but does not take it as a table";
    accepted[table] = *keys;
    for (const std::string& k : *keys)
      if (known_keys(table + "." + k)) todo.push_back(table + "." + k);
  }
  ASSERT_GE(accepted.size(), 10u);

  const auto documented = documented_keys();
  for (const auto& [table, keys] : accepted) {
    const auto it = documented.find(table);
    if (it == documented.end()) {
      ADD_FAILURE() << "docs/configuration.md has no section for [" << table << "]";
      continue;
    }
    for (const std::string& k : keys)
      EXPECT_TRUE(it->second.count(k)) << "[" << table << "] " << k << ": accepted by the reader, not documented";
    for (const std::string& k : it->second)
      EXPECT_TRUE(keys.count(k)) << "[" << table << "] " << k << ": documented, refused by the reader";
  }
  for (const auto& [table, keys] : documented)
    EXPECT_TRUE(accepted.count(table)) << "docs/configuration.md documents [" << table
                                       << "], which the reader refuses";
}

// The probe itself must be able to fail: a key the reader refuses is not reported as accepted.
TEST(DocsConfiguration, TheProbeSeesTheReaderRefuseAKey) {
  const auto budget = known_keys("budget");
  ASSERT_TRUE(budget);
  EXPECT_TRUE(budget->count("triangles"));
  EXPECT_FALSE(budget->count(kProbe));
  EXPECT_FALSE(known_keys("budget.triangles")) << "a number is not a table";
  EXPECT_FALSE(known_keys("no_such_table"));
}
