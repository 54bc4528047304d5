#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>

#include <opencv2/core.hpp>

#include "bundletrack/config/config.hpp"
#include "bundletrack/core/error.hpp"

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

/// Sets a numeric entry from a YAML node, checking type and range.
inline void setNumber(const ConfigEntry& entry, const cv::FileNode& node, const std::filesystem::path& path) {
  const std::string name = entry.name();
  if (!node.isInt() && !node.isReal()) throw InputError(path, name + " must be a number");
  const double value = node.isInt() ? double(int(node)) : double(node);
  std::visit(
      [&](const auto& target) {
        using T = std::decay_t<decltype(target)>;
        if constexpr (!std::is_same_v<T, ConfigChoice>) {
          using N = std::remove_pointer_t<T>;
          if (!std::is_floating_point_v<N> && node.isReal() && value != std::floor(value))
            throw InputError(path, name + " must be a whole number");
          if (!(value >= entry.min && value <= entry.max)) {
            std::ostringstream range;
            range << name << " = " << value << " is out of range [" << entry.min << ", " << entry.max << "]"
                  << (*entry.unit ? std::string(" ") + entry.unit : "");
            throw InputError(path, range.str());
          }
          *target = static_cast<N>(value);
        }
      },
      entry.value);
}

}  // namespace detail

/// Reads a YAML configuration (section: { key: value } as in configEntries) over the defaults.
/// An unknown key, a value that is not a number, a non-integer for an integer setting, a value
/// out of range or a name that is not among a choice's is an InputError naming the file and key.
inline Config loadConfig(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, std::filesystem::exists(path) ? "cannot open file" : "file not found");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  if (yaml.rfind("%YAML", 0) != 0) yaml = "%YAML:1.0\n---\n" + yaml;  // OpenCV needs the directive
  cv::FileStorage storage;
  try {
    storage.open(yaml, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& error) {
    throw InputError(path, "not valid YAML (" + std::string(error.err) + ")");
  }
  Config config;
  const std::vector<ConfigEntry> entries = configEntries(config);
  const cv::FileNode root = storage.root();
  if (!root.isMap() && !root.empty()) throw InputError(path, "expected sections of key: value pairs");
  for (const cv::FileNode section : root) {
    if (!section.isMap()) throw InputError(path, "'" + section.name() + "' must be a section of key: value pairs");
    for (const cv::FileNode node : section) {
      const std::string name = section.name() + "." + node.name();
      const auto entry = std::find_if(entries.begin(), entries.end(), [&](const ConfigEntry& e) { return e.name() == name; });
      if (entry == entries.end()) throw InputError(path, "unknown key '" + name + "'");
      if (const auto* choice = std::get_if<ConfigChoice>(&entry->value)) {
        const std::string value = node.isString() ? std::string(node) : std::string();
        if (std::find(choice->names.begin(), choice->names.end(), value) == choice->names.end())
          throw InputError(path, name + " = '" + value + "': expected " + choice->alternatives());
        choice->set(value);
      } else {
        detail::setNumber(*entry, node, path);
      }
    }
  }
  return config;
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
