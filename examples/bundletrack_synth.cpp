// bundletrack_synth --out DIR [options]
// Renders a synthetic RGB-D sequence with exact ground truth in the YCBInEOAT or TUM RGB-D layout.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "command_line.hpp"

#include "bundletrack/synth/synthetic_sequence.hpp"

namespace bt = bundletrack;

int main(int argc, char** argv) {
  bt::synth::SyntheticSequenceSettings settings;
  std::string out, shape = "box", motion = "handheld", sensor = "structured_light", layout_name = "ycbineoat", mask_error = "none";
  std::string resolution = "640x480";
  double focal = 0.0;
  std::vector<int> out_of_view;
  bool no_noise = false, no_shadow = false, labels = false;
  bt::examples::CommandLine command_line(
      "Renders a synthetic RGB-D sequence with exact ground truth (annotated poses, masks, model) in the\n"
      "YCBInEOAT or the TUM RGB-D layout.",
      "bundletrack_synth");
  command_line.add_option("--out", out, "the sequence directory to write (a sequence already there is replaced)")->type_name("DIR")->required();
  command_line.add_option("--frames", settings.frames, "number of frames")->capture_default_str()->check(bt::examples::wholeAtLeast(1));
  command_line.add_option("--shape", shape, "box | cylinder | mug | chair (0.83 m: legs, seat and back; use with --distance)")
      ->capture_default_str()
      ->check(CLI::IsMember({"box", "cylinder", "mug", "chair"}));
  command_line.add_option("--size", settings.size, "the object's bounding-box diagonal in metres (the shape scaled; default its\n"
                                                   "own: box 0.20, cylinder 0.15, mug 0.17, chair 0.83)")
      ->type_name("M")
      ->check(bt::examples::positive());
  command_line.add_flag("--textureless", settings.textureless, "one flat colour instead of the printed texture");
  command_line.add_option("--motion", motion, "handheld (static camera, object turned up to 180 deg) | orbit (camera orbits)")
      ->capture_default_str()
      ->check(CLI::IsMember({"handheld", "orbit"}));
  command_line.add_option("--speed", settings.speed, "motion speed scale; 1 turns the object by at most 1.9 deg per frame")
      ->capture_default_str()
      ->check(bt::examples::positive());
  command_line.add_option("--distance", settings.distance, "metres from the camera to the object (hand-held: the centre of its motion;\n"
                                                           "orbit: at the start); default the motion's own, 0.73 m / about 0.7 m")
      ->type_name("M")
      ->check(bt::examples::positive());
  command_line.add_flag("--occluder", settings.occluder, "an arm passes in front of the object around the middle frame");
  command_line.add_option("--out-of-view", out_of_view, "from frame S the object is carried out of view for N frames, then comes back\n"
                                                        "where its motion has taken it (its masks are empty meanwhile)")
      ->type_name("S N")
      ->expected(2)
      ->check(bt::examples::wholeAtLeast(1));
  command_line.add_option("--motion-blur", settings.motion_blur_samples, "average the colour over N instants of the exposure (1: off)")
      ->capture_default_str()
      ->check(bt::examples::wholeIn(1, 1000));
  command_line.add_option("--sensor", sensor, "depth noise and shadow of structured_light (Kinect v1, Asus Xtion) |\n"
                                              "active_stereo (RealSense D4xx) | time_of_flight (Azure Kinect, no shadow)\n"
                                              "(bundletrack::DepthNoise, synth::SensorSettings::shadow)")
      ->capture_default_str()
      ->check(CLI::IsMember({"structured_light", "active_stereo", "time_of_flight"}));
  command_line.add_option("--resolution", resolution, "the images' width x height in pixels, e.g. 1280x720 (the principal point at\n"
                                                      "their centre)")
      ->type_name("WxH")
      ->capture_default_str();
  command_line.add_option("--focal", focal, "the focal length in pixels (default 600 per 640 px of width: the same\n"
                                            "horizontal field of view, 56 degrees, at any width)")
      ->type_name("PX")
      ->check(bt::examples::positive());
  command_line.add_option("--flying-pixels", settings.sensor.flying_pixels,
                          "probability that a pixel at a depth edge reads a mix of the two surfaces'\n"
                          "depths, as a time-of-flight camera's flying pixels do (0: none)")
      ->type_name("P")
      ->capture_default_str()
      ->check(bt::examples::probability());
  command_line.add_flag("--no-noise", no_noise, "perfect sensor: no depth noise, quantisation, shadow, dropouts or colour noise");
  command_line.add_flag("--no-shadow", no_shadow, "no shadow: every surface the depth camera sees has a reading (before dropouts)");
  command_line.add_option("--objects", settings.objects, "1 | 2 | 3 objects, each carried by its own hand: beside the --shape the first\n"
                                                         "of box, cylinder, mug it is not, passing in front of and behind it; their\n"
                                                         "masks, poses and models go to masks/<shape>/, annotated_poses/<shape>/ and\n"
                                                         "model/<shape>/")
      ->capture_default_str()
      ->check(bt::examples::wholeIn(1, 3));
  command_line.add_flag("--labels", labels, "with --objects 2 | 3: one label image per frame, labels/<frame>.png (the k-th\n"
                                            "object labelled k, named in labels/objects.txt), instead of the folders of masks");
  command_line.add_option("--mask-error", mask_error, "none | dilate | erode | shift: the masks err from the true outline by\n"
                                                     "--mask-error-px, as a segmentation's do (ground truth unchanged)")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "dilate", "erode", "shift"}));
  command_line.add_option("--mask-error-px", settings.mask_error_px, "pixels the masks are grown, shrunk or moved right by")
      ->capture_default_str()
      ->check(bt::examples::wholeIn(1, 50));
  command_line.add_option("--seed", settings.seed, "random seed of textures and sensor noise")->capture_default_str()->check(bt::examples::wholeAtLeast(0));
  command_line.add_option("--layout", layout_name, "ycbineoat (rgb/%06d.png, depth in mm) | tum (rgb.txt, depth.txt: 30 Hz timestamps,\n"
                                                   "depth 4 ms after colour, in 1/5000 m)")
      ->capture_default_str()
      ->check(CLI::IsMember({"ycbineoat", "tum"}));
  command_line.parseOrExit(argc, argv);
  int width = 0, height = 0;
  char rest = 0;
  if (std::sscanf(resolution.c_str(), "%dx%d%c", &width, &height, &rest) != 2 || width < 64 || height < 64 || width > 8192 ||
      height > 8192)
    command_line.fail("--resolution " + resolution + ": expected WIDTHxHEIGHT in pixels, each from 64 to 8192 (e.g. 1280x720)");
  settings.image_size = cv::Size(width, height);
  const double f = focal > 0.0 ? focal : 600.0 * width / 640.0;
  settings.camera = bt::PinholeCamerad{f, f, 0.5 * (width - 1), 0.5 * (height - 1)};
  const std::map<std::string, bt::synth::Shape> shapes = {{"box", bt::synth::Shape::Box}, {"cylinder", bt::synth::Shape::Cylinder},
                                                          {"mug", bt::synth::Shape::Mug}, {"chair", bt::synth::Shape::Chair}};
  settings.shape = shapes.at(shape);
  settings.motion = motion == "orbit" ? bt::synth::Motion::CameraOrbit : bt::synth::Motion::HandHeld;
  if (sensor == "active_stereo") settings.sensor.depth_noise = bt::DepthNoise::activeStereo();
  else if (sensor == "time_of_flight") settings.sensor.depth_noise = bt::DepthNoise::timeOfFlight();
  if (no_noise) settings.sensor = bt::synth::SensorSettings::perfect();
  if (no_shadow) settings.sensor.shadow = false;
  const std::map<std::string, bt::synth::MaskError> mask_errors = {{"none", bt::synth::MaskError::None},
                                                                    {"dilate", bt::synth::MaskError::Dilated},
                                                                    {"erode", bt::synth::MaskError::Eroded},
                                                                    {"shift", bt::synth::MaskError::Shifted}};
  settings.mask_error = mask_errors.at(mask_error);
  if (!out_of_view.empty()) settings.hidden_start = out_of_view[0], settings.hidden_frames = out_of_view[1];
  const bt::io::Layout layout = layout_name == "tum" ? bt::io::Layout::Tum : bt::io::Layout::YcbInEoat;
  const bt::synth::MaskFiles mask_files = labels ? bt::synth::MaskFiles::LabelImages : bt::synth::MaskFiles::Folders;
  if (mask_files == bt::synth::MaskFiles::LabelImages && settings.objects == 1) command_line.fail("--labels needs --objects 2 or 3");
  try {
    const auto start = std::chrono::steady_clock::now();
    bt::synth::writeSyntheticSequence(out, settings, layout, mask_files);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("wrote %d frames to %s in %.1f s\n", settings.frames, out.c_str(), seconds);
  } catch (const std::exception& error) {
    std::cerr << "error: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
