#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>

#include <opencv2/core.hpp>

#include "bundletrack/config/config.hpp"
#include "bundletrack/core/error.hpp"
#include "bundletrack/io/file_access.hpp"

namespace bundletrack {

namespace detail {

/// A setting's value as the YAML reader reads it back: the shortest text of a number that
/// round-trips, `.inf`, or a choice's name.
inline std::string valueText(const ConfigEntry& entry) {
  return std::visit(
      [](const auto& value) -> std::string {
        using T = std::decay_t<decltype(value)>;
        if constexpr (std::is_same_v<T, ConfigChoice>) {
          return value.get();
        } else {
          using N = std::remove_pointer_t<T>;
          if constexpr (std::is_floating_point_v<N>) {
            if (std::isinf(*value)) return ".inf";
            char buffer[32];
            return std::string(buffer, std::size_t(std::to_chars(buffer, buffer + sizeof(buffer), *value).ptr - buffer));
          } else {
            return std::to_string(*value);
          }
        }
      },
      entry.value);
}

/// Sets a numeric entry to `value`, checking that an integer setting gets a whole number and that
/// the value is in range; `source` (a file, or a command-line option) names it in the error.
inline void assignNumber(const ConfigEntry& entry, double value, const std::filesystem::path& source) {
  const std::string name = entry.name();
  std::visit(
      [&](const auto& target) {
        using T = std::decay_t<decltype(target)>;
        if constexpr (std::is_same_v<T, ConfigChoice>) {
          throw InputError(source, name + " is a choice (" + target.alternatives() + "), not a number");
        } else {
          using N = std::remove_pointer_t<T>;
          if (!std::is_floating_point_v<N> && value != std::floor(value))
            throw InputError(source, name + " must be a whole number");
          if (!(value >= entry.min && value <= entry.max)) {
            std::ostringstream range;
            range << name << " = " << value << " is out of range [" << entry.min << ", " << entry.max << "]"
                  << (*entry.unit ? std::string(" ") + entry.unit : "");
            throw InputError(source, range.str());
          }
          *target = static_cast<N>(value);
        }
      },
      entry.value);
}

/// Sets a numeric entry from a YAML node.
inline void setNumber(const ConfigEntry& entry, const cv::FileNode& node, const std::filesystem::path& path) {
  if (!node.isInt() && !node.isReal()) throw InputError(path, entry.name() + " must be a number");
  assignNumber(entry, node.isInt() ? double(int(node)) : double(node), path);
}

}  // namespace detail

/// Sets the numeric setting `key` (section.key) to `value` as the YAML reader would, checking
/// whole numbers and range; `source` (e.g. the command-line option) names it in the InputError.
inline void setNumber(Config& config, const std::string& key, double value, const std::string& source) {
  const std::vector<ConfigEntry> entries = configEntries(config);
  const auto entry = std::find_if(entries.begin(), entries.end(), [&](const ConfigEntry& e) { return e.name() == key; });
  if (entry == entries.end()) throw InputError(source, "unknown setting '" + key + "'");
  detail::assignNumber(*entry, value, source);
}

/// Settings that are valid one by one but not together; `source` names where they came from.
inline void requireConsistent(const Config& config, const std::filesystem::path& source) {
  const auto& depth = config.sequence.frame.depth_filter;
  if (!(depth.min_depth < depth.max_depth)) {
    std::ostringstream problem;
    problem << "depth.min_depth = " << depth.min_depth << " m is not below depth.max_depth = " << depth.max_depth
            << " m: every reading would be invalid";
    throw InputError(source, problem.str());
  }
}

/// A YAML configuration (section: { key: value } as in configEntries) over the defaults, read
/// from `yaml`, the text of `path`.
/// An unknown key, a key or section given twice, a value that is not a number, a non-integer for
/// an integer setting, a value out of range, a name that is not among a choice's or settings that
/// contradict each other (requireConsistent) is an InputError naming the file and key.
/// The settings file's shape, checked line by line before OpenCV parses it: comments, blank
/// lines, the YAML directive and document start, "section:" at the margin and indented
/// "key: value". OpenCV's YAML parser loops without end on some malformed text (found by
/// fuzz_config), so nothing else reaches it.
inline void requireSettingsShape(const std::string& yaml, const std::filesystem::path& path) {
  static const std::regex blank(R"(\s*(#.*)?)"), header(R"((%YAML.*|---\s*))"),
      section(R"([A-Za-z_][A-Za-z0-9_]*[ \t]*:[ \t]*(#.*)?)"), entry(R"([ \t]+[A-Za-z_][A-Za-z0-9_]*[ \t]*:[ \t]*[^ \t#].*)");
  std::istringstream lines(yaml);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (std::regex_match(line, blank) || std::regex_match(line, header) || std::regex_match(line, section) ||
        std::regex_match(line, entry))
      continue;
    throw InputError(path, "line " + std::to_string(number) + ": expected 'section:' at the margin or an indented "
                           "'key: value' (the settings are sections of key: value pairs), got '" + line.substr(0, 60) + "'");
  }
}

inline Config parseConfig(std::string yaml, const std::filesystem::path& path) {
  requireSettingsShape(yaml, path);
  if (yaml.rfind("%YAML", 0) != 0) yaml = "%YAML:1.0\n---\n" + yaml;  // OpenCV needs the directive
  cv::FileStorage storage;
  try {
    storage.open(yaml, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& error) {
    throw InputError(path, "not valid YAML (" + std::string(error.err) + ")");
  } catch (const std::exception& error) {  // OpenCV's parser lets some throw through (fuzz_config)
    throw InputError(path, "not valid YAML (" + std::string(error.what()) + ")");
  }
  Config config;
  const std::vector<ConfigEntry> entries = configEntries(config);
  const cv::FileNode root = storage.root();
  if (!root.isMap() && !root.empty()) throw InputError(path, "expected sections of key: value pairs");
  std::vector<std::string> seen_sections, seen_keys;
  const auto once = [&](std::vector<std::string>& seen, const std::string& name, const char* what) {
    if (std::find(seen.begin(), seen.end(), name) != seen.end())
      throw InputError(path, std::string(what) + " '" + name + "' is given twice (which one is meant?)");
    seen.push_back(name);
  };
  for (const cv::FileNode section : root) {
    if (!section.isMap()) throw InputError(path, "'" + section.name() + "' must be a section of key: value pairs");
    once(seen_sections, section.name(), "section");
    // A section's choices first, then its numbers, in any order in the file: a choice may be a
    // preset (sensor.model) that the section's numbers refine.
    std::vector<std::pair<const ConfigEntry*, cv::FileNode>> numbers;
    for (const cv::FileNode node : section) {
      const std::string name = section.name() + "." + node.name();
      once(seen_keys, name, "key");
      const auto entry = std::find_if(entries.begin(), entries.end(), [&](const ConfigEntry& e) { return e.name() == name; });
      if (entry == entries.end()) throw InputError(path, "unknown key '" + name + "'");
      if (const auto* choice = std::get_if<ConfigChoice>(&entry->value)) {
        const std::string value = node.isString() ? std::string(node) : std::string();
        if (std::find(choice->names.begin(), choice->names.end(), value) == choice->names.end())
          throw InputError(path, name + " = '" + value + "': expected " + choice->alternatives());
        choice->set(value);
      } else {
        numbers.emplace_back(&*entry, node);
      }
    }
    for (const auto& [entry, node] : numbers) detail::setNumber(*entry, node, path);
  }
  requireConsistent(config, path);
  return config;
}

/// Reads a YAML configuration file (parseConfig).
inline Config loadConfig(const std::filesystem::path& path) {
  std::ifstream in = io::openForReading(path);
  std::stringstream text;
  text << in.rdbuf();
  return parseConfig(text.str(), path);
}

/// The configuration as YAML that loadConfig reads back, each key under a comment with its
/// meaning and unit (or its choices).
inline std::string printConfig(Config config) {
  std::ostringstream out;
  std::string section;
  for (const ConfigEntry& entry : configEntries(config)) {
    if (section != entry.section) out << (section = entry.section) << ":\n";
    out << "  # " << entry.meaning;
    if (const auto* choice = std::get_if<ConfigChoice>(&entry.value)) out << " (" << choice->alternatives() << ")";
    else if (*entry.unit) out << " [" << entry.unit << "]";
    out << "\n  " << entry.key << ": " << detail::valueText(entry) << "\n";
  }
  return out.str();
}

/// The reference table of every setting with its default, as Markdown (the README's table).
inline std::string settingsTable() {
  Config defaults;
  std::ostringstream out;
  out << "| key | default | unit | meaning |\n|---|---|---|---|\n";
  for (const ConfigEntry& entry : configEntries(defaults)) {
    out << "| `" << entry.name() << "` | " << detail::valueText(entry) << " | " << entry.unit << " | " << entry.meaning;
    if (const auto* choice = std::get_if<ConfigChoice>(&entry.value)) out << " (" << choice->alternatives(", ") << ")";
    out << " |\n";
  }
  return out.str();
}

}  // namespace bundletrack
