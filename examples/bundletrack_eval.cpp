// bundletrack_eval --sequence DIR --poses DIR [--sequence DIR --poses DIR ...] [--json FILE]
// Scores pose files (<poses>/<frame name>.txt, 4x4 T_cam_obj) against each sequence's
// annotated_poses/ and model/points.xyz; prints one row per sequence and their mean. A frame
// without a pose file is a failure, never skipped.
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include "bundletrack/eval/score_table.hpp"
#include "bundletrack/io/ycbineoat_sequence.hpp"

namespace bt = bundletrack;
namespace fs = std::filesystem;

namespace {

const char* const kUsage =
    "usage: bundletrack_eval --sequence DIR --poses DIR [--sequence DIR --poses DIR ...] [--json FILE]\n";

bt::NamedScore evaluate(const fs::path& sequence_dir, const fs::path& poses_dir) {
  const bt::io::YcbineoatSequence sequence(sequence_dir);
  if (!sequence.hasGroundTruth()) throw bt::InputError(sequence_dir / "annotated_poses", "directory not found");
  if (!sequence.hasModel()) throw bt::InputError(sequence_dir / "model" / "points.xyz", "file not found");
  if (!fs::is_directory(poses_dir)) throw bt::InputError(poses_dir, "poses directory not found");
  std::vector<bt::SE3d> truth;
  std::vector<std::optional<bt::SE3d>> estimate;
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    truth.push_back(sequence.groundTruthPose(i));
    const fs::path file = poses_dir / (sequence.frameNames()[i] + ".txt");
    estimate.push_back(fs::exists(file) ? std::optional(bt::io::readPose(file)) : std::nullopt);
  }
  return {sequence_dir.filename().string(), bt::scoreSequence(sequence.modelPoints(), truth, estimate)};
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<fs::path> sequences, poses;
  fs::path json;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return 0;
    }
    if (i + 1 >= argc) {
      std::cerr << "error: " << arg << " needs a value\n" << kUsage;
      return 2;
    }
    if (arg == "--sequence") sequences.emplace_back(argv[++i]);
    else if (arg == "--poses") poses.emplace_back(argv[++i]);
    else if (arg == "--json") json = argv[++i];
    else {
      std::cerr << "error: unknown option '" << arg << "'\n" << kUsage;
      return 2;
    }
  }
  if (sequences.empty() || sequences.size() != poses.size()) {
    std::cerr << "error: give one --poses for every --sequence\n" << kUsage;
    return 2;
  }
  try {
    std::vector<bt::NamedScore> rows;
    for (std::size_t k = 0; k < sequences.size(); ++k) rows.push_back(evaluate(sequences[k], poses[k]));
    std::cout << bt::formatScoreTable(rows);
    if (!json.empty()) bt::writeScoreJson(json, rows);
  } catch (const std::exception& error) {
    std::cerr << "error: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
