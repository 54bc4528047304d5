// bundletrack_eval --sequence DIR --poses DIR [--sequence DIR --poses DIR ...] [--json FILE] [--in-view]
// Scores pose files (<poses>/<frame name>.txt, 4x4 T_cam_obj) against each sequence's
// annotated_poses/ and model/points.xyz; prints one row per sequence and their mean. A frame
// without a pose file is a failure, never skipped; one without an annotated pose is not scored.
// Where bundletrack_track's track.csv lies beside the poses directory (OUT/track.csv for
// OUT/poses), the frames it reports lost are counted, and a second table (and JSON block
// "lost_as_failed") scores them as failures, as bundletrack_track's own summary does: a lost
// frame keeps the last pose, which the first table scores as an estimate.
// --in-view scores only the frames in which the object is seen, those whose masks/<name>.png has
// a pixel on the object (for synthetic sequences the renderer's exact mask), as benchmarks that
// annotate only visible objects do; the frames left out are counted.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <string>

#include "command_line.hpp"

#include "bundletrack/eval/score_table.hpp"
#include "bundletrack/io/image_files.hpp"
#include "bundletrack/io/point_files.hpp"
#include "bundletrack/io/pose_files.hpp"
#include "bundletrack/io/rgbd_sequence.hpp"
#include "bundletrack/tracking/track_result.hpp"

namespace bt = bundletrack;
namespace fs = std::filesystem;

namespace {

/// Whether each frame of track.csv (columns frame,status,...) was reported lost; none without the file.
std::optional<std::map<std::string, bool>> lostFrames(const fs::path& csv) {
  if (!fs::exists(csv)) return std::nullopt;
  std::ifstream in(csv);
  std::string line;
  if (!in || !std::getline(in, line)) throw bt::InputError(csv, "cannot read the header line");
  if (line.rfind("frame,status,", 0) != 0)
    throw bt::InputError(csv, "line 1: expected a header starting with 'frame,status,' (bundletrack_track's track.csv)");
  std::map<std::string, bool> lost;
  for (int number = 2; std::getline(in, line); ++number) {
    const std::size_t first = line.find(','), second = first == std::string::npos ? first : line.find(',', first + 1);
    if (second == std::string::npos) throw bt::InputError(csv, "line " + std::to_string(number) + ": expected frame,status,...");
    const std::string status = line.substr(first + 1, second - first - 1);
    const std::optional<bt::TrackStatus> tracker_status = bt::statusFromName(status);
    if (!tracker_status && status != "not_started")  // bundletrack_track's row before an object's first frame
      throw bt::InputError(csv, "line " + std::to_string(number) + ": unknown status '" + status + "'");
    lost[line.substr(0, first)] = tracker_status == bt::TrackStatus::Lost;
  }
  return lost;
}

struct Scored {
  bt::NamedScore score;
  std::optional<bt::NamedScore> lost_as_failed;  ///< where the run's track.csv says which frames were lost
};

/// Scoring needs only the frames' names (rgb/ or rgb.txt), the ground truth and the model: a sequence without
/// depth/ or with an empty first mask is scored all the same. A frame without an annotated pose is
/// not scored (counted in `unscored`), nor, with `in_view`, one whose mask is empty (`out_of_view`).
Scored evaluate(const fs::path& sequence_dir, const fs::path& poses_dir, bool in_view, int& unscored, int& out_of_view) {
  if (!fs::is_directory(sequence_dir)) throw bt::InputError(sequence_dir, "sequence directory not found");
  const std::vector<std::string> names =
      bt::io::frameFiles(sequence_dir, bt::io::Layout::Auto, bt::io::SequenceSettings().max_time_difference).names;
  if (!fs::is_directory(sequence_dir / "annotated_poses"))
    throw bt::InputError(sequence_dir / "annotated_poses", "directory not found");
  const std::vector<Eigen::Vector3f> model = bt::io::readPoints(sequence_dir / "model" / "points.xyz");
  if (!fs::is_directory(poses_dir)) throw bt::InputError(poses_dir, "poses directory not found");
  const fs::path csv = fs::absolute(poses_dir).lexically_normal().parent_path() / "track.csv";
  const std::optional<std::map<std::string, bool>> lost = lostFrames(csv);
  std::vector<bt::SE3d> truth;
  std::vector<std::optional<bt::SE3d>> estimate, estimate_unless_lost;
  int lost_scored = 0;
  for (const std::string& name : names) {
    const fs::path true_pose = sequence_dir / "annotated_poses" / (name + ".txt");
    if (!fs::exists(true_pose)) {
      ++unscored;
      continue;
    }
    if (in_view && cv::countNonZero(bt::io::readMask(sequence_dir / "masks" / (name + ".png"))) == 0) {
      ++out_of_view;
      continue;
    }
    truth.push_back(bt::io::readPose(true_pose));
    const fs::path file = poses_dir / (name + ".txt");
    estimate.push_back(fs::exists(file) ? std::optional(bt::io::readPose(file)) : std::nullopt);
    const auto row = lost ? lost->find(name) : std::map<std::string, bool>::const_iterator{};
    if (lost && estimate.back() && row == lost->end())
      throw bt::InputError(csv, "no row for frame " + name + ", whose pose is in " + poses_dir.string() +
                                    ": not the track.csv of the run that wrote these poses");
    const bool frame_lost = lost && row != lost->end() && row->second;
    lost_scored += frame_lost;
    estimate_unless_lost.push_back(frame_lost ? std::nullopt : estimate.back());
  }
  const std::string name = sequence_dir.filename().string();
  Scored scored{{name, bt::scoreSequence(model, truth, estimate)}, std::nullopt};
  if (lost) {
    std::cout << name << ": " << lost_scored << " of the scored frames reported lost in " << csv.string() << '\n';
    scored.lost_as_failed = bt::NamedScore{name, bt::scoreSequence(model, truth, estimate_unless_lost)};
  }
  return scored;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> sequences, poses;
  std::string json;
  bool in_view = false;
  bt::examples::CommandLine command_line(
      "Scores pose files (POSES/<frame>.txt, 4x4 T_cam_obj) against each sequence's annotated_poses/ and\n"
      "model/points.xyz: one row per sequence and their mean. A frame without a pose file is a failure.",
      "bundletrack_eval");
  command_line.add_option("--sequence", sequences, "a sequence directory (give one --poses for each, in the same order)")
      ->type_name("DIR")
      ->required();
  command_line.add_option("--poses", poses, "the poses of the --sequence at the same position (OUT/poses of bundletrack_track);\n"
                                            "with OUT/track.csv beside it, lost frames are also scored as failures")
      ->type_name("DIR")
      ->required();
  command_line.add_option("--json", json, "also write the scores as JSON to FILE")->type_name("FILE");
  command_line.add_flag("--in-view", in_view, "score only the frames whose masks/<frame>.png has a pixel on the object");
  command_line.parseOrExit(argc, argv);
  if (sequences.size() != poses.size()) command_line.fail("give one --poses for every --sequence");
  try {
    std::vector<bt::NamedScore> rows, lost_as_failed;
    int unscored = 0, out_of_view = 0;
    for (std::size_t k = 0; k < sequences.size(); ++k) {
      const Scored scored = evaluate(sequences[k], poses[k], in_view, unscored, out_of_view);
      rows.push_back(scored.score);
      if (scored.lost_as_failed) lost_as_failed.push_back(*scored.lost_as_failed);
    }
    // The lost-as-failed table only when it covers every sequence, so that its mean compares with the first.
    if (!lost_as_failed.empty() && lost_as_failed.size() != rows.size()) {
      std::cout << "no table with lost frames scored as failures: not every --poses directory has a track.csv beside it\n";
      lost_as_failed.clear();
    }
    std::cout << bt::formatScoreTable(rows);
    if (!lost_as_failed.empty()) std::cout << "lost frames scored as failures:\n" << bt::formatScoreTable(lost_as_failed);
    if (unscored > 0) std::cout << unscored << " frames without an annotated pose were not scored\n";
    if (in_view) std::cout << out_of_view << " frames with an empty mask (object out of view) were not scored (--in-view)\n";
    if (!json.empty()) bt::writeScoreJson(json, rows, lost_as_failed);
  } catch (const std::exception& error) {
    std::cerr << "error: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
