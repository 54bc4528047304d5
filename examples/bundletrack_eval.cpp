// bundletrack_eval --sequence DIR --poses DIR [--sequence DIR --poses DIR ...] [--json FILE]
// Scores pose files (<poses>/<frame name>.txt, 4x4 T_cam_obj) against each sequence's
// annotated_poses/ and model/points.xyz; prints one row per sequence and their mean. A frame
// without a pose file is a failure, never skipped; one without an annotated pose is not scored.
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include "bundletrack/eval/score_table.hpp"
#include "bundletrack/io/point_files.hpp"
#include "bundletrack/io/pose_files.hpp"
#include "bundletrack/io/rgbd_sequence.hpp"

namespace bt = bundletrack;
namespace fs = std::filesystem;

namespace {

const char* const kUsage =
    "usage: bundletrack_eval --sequence DIR --poses DIR [--sequence DIR --poses DIR ...] [--json FILE]\n";

/// Scoring needs only the frames' names (rgb/ or rgb.txt), the ground truth and the model: a sequence without
/// depth/ or with an empty first mask is scored all the same. A frame without an annotated pose is
/// not scored (counted in `unscored`).
bt::NamedScore evaluate(const fs::path& sequence_dir, const fs::path& poses_dir, int& unscored) {
  if (!fs::is_directory(sequence_dir)) throw bt::InputError(sequence_dir, "sequence directory not found");
  const std::vector<std::string> names =
      bt::io::frameFiles(sequence_dir, bt::io::Layout::Auto, bt::io::SequenceSettings().max_time_difference).names;
  if (!fs::is_directory(sequence_dir / "annotated_poses"))
    throw bt::InputError(sequence_dir / "annotated_poses", "directory not found");
  const std::vector<Eigen::Vector3f> model = bt::io::readPoints(sequence_dir / "model" / "points.xyz");
  if (!fs::is_directory(poses_dir)) throw bt::InputError(poses_dir, "poses directory not found");
  std::vector<bt::SE3d> truth;
  std::vector<std::optional<bt::SE3d>> estimate;
  for (const std::string& name : names) {
    const fs::path true_pose = sequence_dir / "annotated_poses" / (name + ".txt");
    if (!fs::exists(true_pose)) {
      ++unscored;
      continue;
    }
    truth.push_back(bt::io::readPose(true_pose));
    const fs::path file = poses_dir / (name + ".txt");
    estimate.push_back(fs::exists(file) ? std::optional(bt::io::readPose(file)) : std::nullopt);
  }
  return {sequence_dir.filename().string(), bt::scoreSequence(model, truth, estimate)};
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
    int unscored = 0;
    for (std::size_t k = 0; k < sequences.size(); ++k) rows.push_back(evaluate(sequences[k], poses[k], unscored));
    std::cout << bt::formatScoreTable(rows);
    if (unscored > 0) std::cout << unscored << " frames without an annotated pose were not scored\n";
    if (!json.empty()) bt::writeScoreJson(json, rows);
  } catch (const std::exception& error) {
    std::cerr << "error: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
