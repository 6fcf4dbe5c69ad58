// docs/observables.md names config keys as `section.key`: every such key of [observables] and
// [output] must exist in `hardbody config-reference` (hb::config_reference()), and every key
// the reference lists for those sections must be named. The doc once described keys that the
// config rejects (log_lags, body_axis, q_tolerance, r_max, max_origins).
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "io/config.hpp"

namespace {

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Keys of [section] in the reference: the first cell of each table row under "## [section]".
std::set<std::string> reference_keys(const std::string& ref, const std::string& section) {
  std::set<std::string> keys;
  std::istringstream in(ref);
  std::string line;
  bool inside = false;
  const std::regex row("^\\| `([a-z_0-9]+)` \\|");
  while (std::getline(in, line)) {
    if (line.starts_with("## ")) inside = line == "## [" + section + "]";
    std::smatch m;
    if (inside && std::regex_search(line, m, row)) keys.insert(m[1]);
  }
  return keys;
}

}  // namespace

TEST(DocsKeys, ObservablesDocNamesExactlyTheConfigKeys) {
  const std::string doc = read(std::string(HB_SOURCE_DIR) + "/docs/observables.md");
  ASSERT_FALSE(doc.empty()) << "docs/observables.md not found under " << HB_SOURCE_DIR;
  const std::string ref = hb::config_reference();
  for (const std::string section : {"observables", "output"}) {
    const auto known = reference_keys(ref, section);
    ASSERT_FALSE(known.empty()) << section;
    std::set<std::string> named;
    const std::regex key("`" + section + "\\.([a-z_0-9]+)`");
    for (auto it = std::sregex_iterator(doc.begin(), doc.end(), key); it != std::sregex_iterator(); ++it)
      named.insert((*it)[1]);
    for (const auto& k : named)
      EXPECT_TRUE(known.count(k)) << "docs/observables.md names `" << section << "." << k
                                  << "`, which hardbody config-reference does not list";
    for (const auto& k : known)
      EXPECT_TRUE(named.count(k)) << "docs/observables.md does not document `" << section << "." << k << "`";
  }
  // Library-only fields must not be presented as config keys.
  for (const char* field : {"log_lags", "body_axis", "q_tolerance", "r_max", "max_origins"})
    EXPECT_EQ(doc.find(std::string("`observables.") + field + "`"), std::string::npos) << field;
}
