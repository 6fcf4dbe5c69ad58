// Shared by the config tests: a good one-species config and the error message of a bad one.
#pragma once
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "io/config.hpp"

namespace hb::testing_config {

// 256 spheres of radius 0.5 at phi = 0.3; [system] is line 1.
inline const char* const kGoodSpheres = R"([system]
particles = 256
packing_fraction = 0.3
seed = 7
[shape]
type = "sphere"
radius = 0.5
[run]
equilibrate_time = 1.0
time = 2.0
)";

// The ConfigError message of parsing `text` as cfg.toml with overrides `ov` ("" if it parses).
inline std::string error_of(const std::string& text, const std::vector<std::string>& ov = {}) {
  try {
    parse_config(text, "cfg.toml", ov);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

// s with the first `a` replaced by `b` (a must occur).
inline std::string replace(std::string s, const std::string& a, const std::string& b) {
  const auto p = s.find(a);
  EXPECT_NE(p, std::string::npos) << a;
  return s.replace(p, a.size(), b);
}

}  // namespace hb::testing_config
