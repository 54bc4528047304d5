#pragma once

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bundletrack/core/error.hpp"
#include "bundletrack/eval/sequence_score.hpp"

namespace bundletrack {

struct NamedScore {
  std::string sequence;
  SequenceScore score;
};

/// The mean of each column over the sequences (frames and missing are summed), like the paper's tables.
inline SequenceScore meanScore(const std::vector<NamedScore>& rows) {
  SequenceScore mean;
  for (const auto& [name, s] : rows) {
    mean.add_auc += s.add_auc, mean.adds_auc += s.adds_auc, mean.deg5cm5 += s.deg5cm5, mean.iou25 += s.iou25;
    mean.rotation_error_deg += s.rotation_error_deg, mean.translation_error_cm += s.translation_error_cm;
    mean.final_add_cm += s.final_add_cm, mean.frames += s.frames, mean.missing += s.missing;
  }
  const double n = rows.empty() ? 1.0 : double(rows.size());
  mean.add_auc /= n, mean.adds_auc /= n, mean.deg5cm5 /= n, mean.iou25 /= n;
  mean.rotation_error_deg /= n, mean.translation_error_cm /= n, mean.final_add_cm /= n;
  return mean;
}

/// Whether a table of several rows ends with their mean (not for two scorings of one run).
enum class MeanRow { Add, Omit };

inline std::string formatScoreTable(const std::vector<NamedScore>& rows, MeanRow mean = MeanRow::Add) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof(line), "%-24s %7s %7s %8s %7s %8s %8s %7s %8s\n", "sequence", "ADD", "ADD-S", "5deg5cm",
                "IoU25", "R_err", "T_err", "frames", "missing");
  out += line;
  // A mean error over no frame is not a number: n/a, not 0.
  const auto error = [](double value, const char* unit) {
    char text[32];
    if (std::isfinite(value)) std::snprintf(text, sizeof(text), "%6.2f%s", value, unit);
    else std::snprintf(text, sizeof(text), "%8s", "n/a");
    return std::string(text);
  };
  const auto row = [&](const std::string& name, const SequenceScore& s) {
    std::snprintf(line, sizeof(line), "%-24s %7.2f %7.2f %7.1f%% %6.1f%% %s %s %7d %8d\n", name.c_str(), s.add_auc,
                  s.adds_auc, s.deg5cm5, s.iou25, error(s.rotation_error_deg, "dg").c_str(),
                  error(s.translation_error_cm, "cm").c_str(), s.frames, s.missing);
    out += line;
  };
  for (const auto& r : rows) row(r.sequence, r.score);
  if (rows.size() > 1 && mean == MeanRow::Add) row("mean", meanScore(rows));
  // A large model is scored on a subsample (scoringSubsample): say so, with its bound.
  for (const auto& r : rows) {
    const SequenceScore& s = r.score;
    if (s.scored_points == 0 || s.scored_points >= s.model_points) continue;
    std::snprintf(line, sizeof(line), "%s: ADD and ADD-S on %zu of the model's %zu points (evenly strided); each ADD-S "
                  "distance at most %.2f cm above the whole model's\n", r.sequence.c_str(), s.scored_points,
                  s.model_points, s.subsample_bound_cm);
    out += line;
  }
  return out;
}

/// JSON with one object per sequence and the mean: ADD, ADD_S, deg5cm5, IoU25, Rerr_deg, Terr_cm,
/// frames, missing. With `lost_as_failed` (the same sequences, the frames the tracker reported
/// lost scored as failures), the same again under "lost_as_failed".
inline void writeScoreJson(const std::filesystem::path& path, const std::vector<NamedScore>& rows,
                           const std::vector<NamedScore>& lost_as_failed = {}) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot write file");
  const auto number = [](double v) { return std::isfinite(v) ? std::to_string(v) : std::string("null"); };
  const auto object = [&](const std::string& name, const SequenceScore& s) {
    std::string escaped;
    for (const char c : name) {
      if (c == '"' || c == '\\') escaped += '\\';
      escaped += c;
    }
    return "{\"sequence\": \"" + escaped + "\", \"ADD\": " + number(s.add_auc) + ", \"ADD_S\": " + number(s.adds_auc) +
           ", \"deg5cm5\": " + number(s.deg5cm5) + ", \"IoU25\": " + number(s.iou25) +
           ", \"Rerr_deg\": " + number(s.rotation_error_deg) + ", \"Terr_cm\": " + number(s.translation_error_cm) +
           ", \"frames\": " + std::to_string(s.frames) + ", \"missing\": " + std::to_string(s.missing) + "}";
  };
  const auto table = [&](const std::vector<NamedScore>& scores, const std::string& indent) {
    std::string text = indent + "\"sequences\": [\n";
    for (std::size_t k = 0; k < scores.size(); ++k)
      text += indent + "  " + object(scores[k].sequence, scores[k].score) + (k + 1 < scores.size() ? ",\n" : "\n");
    return text + indent + "],\n" + indent + "\"mean\": " + object("mean", meanScore(scores));
  };
  out << "{\n" << table(rows, "  ");
  if (!lost_as_failed.empty()) out << ",\n  \"lost_as_failed\": {\n" << table(lost_as_failed, "    ") << "\n  }";
  out << "\n}\n";
  if (!out) throw InputError(path, "write failed");
}

}  // namespace bundletrack
