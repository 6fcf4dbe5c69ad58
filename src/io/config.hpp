// The run configuration (TOML), validated in full before anything is written. Every problem is
// reported as one ConfigError naming the file, the key and, where known, the line.
#pragma once
#include <string>
#include <vector>

#include "setup/config.hpp"

namespace hb {

// Reads and validates a config file; `overrides` are "section.key=value" strings (--set) whose
// values are TOML literals. Throws ConfigError.
Config load_config(const std::string& path, const std::vector<std::string>& overrides = {});
// Parses and validates TOML text (for tests); `name` is used in messages.
Config parse_config(const std::string& text, const std::string& name,
                    const std::vector<std::string>& overrides = {});
// The fully resolved config, every key present, as TOML text.
std::string to_toml(const Config& c);
// Markdown reference of every key (docs/config.md), generated from the schema and the registry.
std::string config_reference();

}  // namespace hb
