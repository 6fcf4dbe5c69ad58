// "Did you mean ...?" for unknown keys: the config file (io/config.cpp) and the pair queries
// (io/pair_query.cpp) suggest the nearest known key with the same rule.
#pragma once
#include <algorithm>
#include <cctype>
#include <string>
#include <string_view>
#include <vector>

namespace hb {

// Optimal string alignment distance (edits: insert, delete, substitute, swap two neighbours),
// ignoring case: "Radius", "raduis" and "radus" are all one edit from "radius".
inline std::size_t edit_distance(std::string_view a, std::string_view b) {
  auto low = [](char c) { return char(std::tolower(static_cast<unsigned char>(c))); };
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = low(a[i - 1]) == low(b[j - 1]) ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && low(a[i - 1]) == low(b[j - 2]) && low(a[i - 2]) == low(b[j - 1]))
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

// The known key nearest to `key` within a third of the key's length (at least one edit), the
// first of equals; "" when none is that near.
inline std::string nearest_key(std::string_view key, const std::vector<std::string>& known) {
  std::size_t best = std::max<std::size_t>(1, key.size() / 3) + 1;
  std::string pick;
  for (const auto& k : known) {
    const std::size_t e = edit_distance(key, k);
    if (e < best) {
      best = e;
      pick = k;
    }
  }
  return pick;
}

// " (did you mean 'x'?)" for the nearest known key, "" when none is near.
inline std::string did_you_mean(std::string_view key, const std::vector<std::string>& known) {
  const std::string pick = nearest_key(key, known);
  return pick.empty() ? "" : " (did you mean '" + pick + "'?)";
}

}  // namespace hb
