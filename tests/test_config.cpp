// YAML configuration: values land where they belong, bad files fail with the file and key named.
#include <doctest/doctest.h>

#include <fstream>

#include "bundletrack/io/config.hpp"
#include "temp_dir.hpp"

namespace bt = bundletrack;

namespace {

std::filesystem::path writeFile(const TempDir& dir, const std::string& name, const std::string& text) {
  const auto path = dir.path() / name;
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("configuration values land in the settings they name, and printing reads back identically") {
  TempDir dir("config");
  const auto path = writeFile(dir, "a.yaml",
                              "graph:\n  max_keyframes: 7\n  edge_gate_distance: 0.03\n"
                              "depth:\n  scale: 0.0001\n  max_depth: 2.5\n"
                              "features:\n  type: orb\n  max_keypoints: 300\n"
                              "ransac:\n  inlier_distance: 0.01\n"
                              "masks:\n  source: propagated\n  growth_px: 12\n"
                              "compute:\n  device: gpu\n");
  const bt::io::Config config = bt::io::loadConfig(path);
  CHECK(config.tracker.max_keyframes == 7);
  CHECK(config.tracker.edge_gate_distance == doctest::Approx(0.03f));
  CHECK(config.sequence.depth_scale == doctest::Approx(0.0001));
  CHECK(config.sequence.frame.depth_filter.max_depth == doctest::Approx(2.5f));
  CHECK(config.features == "orb");
  CHECK(config.orb.max_keypoints == 300);  // the detector-independent settings follow the chosen detector
  CHECK(config.tracker.coarse.ransac.inlier_distance == doctest::Approx(0.01f));
  CHECK(config.masks == "propagated");
  CHECK(config.propagated_masks.growth_px == 12);
  CHECK(config.device == "gpu");  // a section of choices alone
  CHECK(config.tracker.new_keyframe_rotation_deg == 10.0);  // untouched keys keep their defaults
  const std::string printed = bt::io::printConfig(config);
  CHECK(printed.find("compute:\n") != std::string::npos);
  CHECK(printed.find("  device: gpu\n") != std::string::npos);
  const bt::io::Config again = bt::io::loadConfig(writeFile(dir, "b.yaml", printed));
  CHECK(bt::io::printConfig(again) == printed);
  CHECK(bt::io::printConfig(bt::io::loadConfig(writeFile(dir, "empty.yaml", ""))) == bt::io::printConfig({}));
}

TEST_CASE("bad configuration files name the file and the key") {
  TempDir dir("badconfig");
  const auto expect = [&](const std::string& text, const std::string& problem) {
    CAPTURE(text);
    const auto path = writeFile(dir, "c.yaml", text);
    try {
      bt::io::loadConfig(path);
      FAIL("no InputError");
    } catch (const bt::InputError& error) {
      CHECK(error.source() == path);
      CHECK(error.problem().find(problem) != std::string::npos);
    }
  };
  expect("graph:\n  max_keyframe: 3\n", "unknown key 'graph.max_keyframe'");
  expect("tracker:\n  max_keyframes: 3\n", "unknown key 'tracker.max_keyframes'");
  expect("graph:\n  max_keyframes: 0\n", "graph.max_keyframes = 0 is out of range [1, 1000]");
  expect("ransac:\n  inlier_normal_angle_deg: 200\n", "out of range");
  expect("depth:\n  scale: -1\n", "depth.scale = -1 is out of range");
  expect("ransac:\n  max_trials: 2.5\n", "must be a whole number");
  expect("ransac:\n  max_trials: many\n", "must be a number");
  expect("features:\n  type: surf\n", "expected sift | orb | akaze");
  expect("masks:\n  source: network\n", "masks.source = 'network': expected given | propagated");
  expect("compute:\n  device: tpu\n", "compute.device = 'tpu': expected cpu | gpu");
  expect("graph: [1, 2\n", "not valid YAML");
  expect("graph: 3\n", "must be a section");
  try {
    bt::io::loadConfig(dir.path() / "missing.yaml");
    FAIL("no InputError");
  } catch (const bt::InputError& error) {
    CHECK(error.problem() == "file not found");
  }
}
