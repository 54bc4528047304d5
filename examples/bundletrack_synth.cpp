// bundletrack_synth --out DIR [options]
// Renders a synthetic RGB-D sequence with exact ground truth in the YCBInEOAT or TUM RGB-D layout.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>

#include "bundletrack/synth/synthetic_sequence.hpp"

namespace bt = bundletrack;

namespace {

const char* const kUsage = R"(usage: bundletrack_synth --out DIR [options]
  --frames N         number of frames (300)
  --shape S          box | cylinder | mug | chair (0.83 m: legs, seat and back; use with --distance) (box)
  --size S           the object's bounding-box diagonal in metres (the shape scaled; default its
                     own: box 0.20, cylinder 0.15, mug 0.17, chair 0.83)
  --textureless      one flat colour instead of the printed texture
  --motion M         handheld (static camera, object turned up to 180 deg) | orbit (camera orbits) (handheld)
  --speed X          motion speed scale; 1 turns the object by at most 1.9 deg per frame (1)
  --distance D       metres from the camera to the object (hand-held: the centre of its motion;
                     orbit: at the start); default the motion's own, 0.73 m / about 0.7 m
  --occluder         an arm passes in front of the object around the middle frame
  --out-of-view S N  from frame S the object is carried out of view for N frames, then comes back
                     where its motion has taken it (its masks are empty meanwhile)
  --motion-blur N    average the colour over N instants of the exposure (1 = off)
  --sensor S         depth noise of structured_light (Kinect v1, Asus Xtion) | active_stereo
                     (RealSense D4xx) | time_of_flight (Azure Kinect) (structured_light;
                     bundletrack::DepthNoise)
  --no-noise         perfect sensor: no depth noise, quantisation, dropouts or colour noise
  --objects N        1 | 2 | 3 objects, each carried by its own hand: beside the --shape the first
                     of box, cylinder, mug it is not, passing in front of and behind it; their
                     masks, poses and models go to masks/<shape>/, annotated_poses/<shape>/ and
                     model/<shape>/ (1)
  --labels           with --objects 2 | 3: one label image per frame, labels/<frame>.png (the k-th
                     object labelled k, named in labels/objects.txt), instead of the folders of masks
  --seed N           random seed of textures and sensor noise (1)
  --layout L         ycbineoat (rgb/%06d.png, depth in mm) | tum (rgb.txt, depth.txt: 30 Hz timestamps,
                     depth 4 ms after colour, in 1/5000 m) (ycbineoat)
)";

[[noreturn]] void fail(const std::string& message) {
  std::cerr << "error: " << message << "\n" << kUsage;
  std::exit(2);
}

double number(const std::string& option, const char* text) {
  try {
    std::size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == std::string(text).size()) return value;
  } catch (const std::exception&) {
  }
  fail(option + " expects a number, got '" + text + "'");
}

}  // namespace

int main(int argc, char** argv) {
  bt::synth::SyntheticSequenceSettings settings;
  bt::io::Layout layout = bt::io::Layout::YcbInEoat;
  bt::synth::MaskFiles mask_files = bt::synth::MaskFiles::Folders;
  std::string out;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&]() -> const char* {
      if (i + 1 >= argc) fail(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--out") {
      out = value();
    } else if (arg == "--frames") {
      settings.frames = int(number(arg, value()));
    } else if (arg == "--shape") {
      const std::string shape = value();
      if (shape == "box") settings.shape = bt::synth::Shape::Box;
      else if (shape == "cylinder") settings.shape = bt::synth::Shape::Cylinder;
      else if (shape == "mug") settings.shape = bt::synth::Shape::Mug;
      else if (shape == "chair") settings.shape = bt::synth::Shape::Chair;
      else fail("unknown shape '" + shape + "'");
    } else if (arg == "--size") {
      settings.size = number(arg, value());
      if (!(settings.size > 0.0)) fail("--size must be positive");
    } else if (arg == "--textureless") {
      settings.textureless = true;
    } else if (arg == "--motion") {
      const std::string motion = value();
      if (motion == "handheld") settings.motion = bt::synth::Motion::HandHeld;
      else if (motion == "orbit") settings.motion = bt::synth::Motion::CameraOrbit;
      else fail("unknown motion '" + motion + "'");
    } else if (arg == "--speed") {
      settings.speed = number(arg, value());
    } else if (arg == "--distance") {
      settings.distance = number(arg, value());
      if (!(settings.distance > 0.0)) fail("--distance must be positive");
    } else if (arg == "--occluder") {
      settings.occluder = true;
    } else if (arg == "--out-of-view") {
      settings.hidden_start = int(number(arg, value()));
      settings.hidden_frames = int(number(arg, value()));
      if (settings.hidden_start < 1 || settings.hidden_frames < 1)
        fail("--out-of-view needs a start frame >= 1 and a frame count >= 1");
    } else if (arg == "--motion-blur") {
      settings.motion_blur_samples = int(number(arg, value()));
    } else if (arg == "--sensor") {
      const std::string sensor = value();
      if (sensor == "structured_light") settings.sensor.depth_noise = bt::DepthNoise::structuredLight();
      else if (sensor == "active_stereo") settings.sensor.depth_noise = bt::DepthNoise::activeStereo();
      else if (sensor == "time_of_flight") settings.sensor.depth_noise = bt::DepthNoise::timeOfFlight();
      else fail("unknown sensor '" + sensor + "' (structured_light | active_stereo | time_of_flight)");
    } else if (arg == "--no-noise") {
      settings.sensor = bt::synth::SensorSettings::perfect();
    } else if (arg == "--objects") {
      const double objects = number(arg, value());
      if (objects != 1.0 && objects != 2.0 && objects != 3.0) fail("--objects must be 1, 2 or 3");
      settings.objects = int(objects);
    } else if (arg == "--labels") {
      mask_files = bt::synth::MaskFiles::LabelImages;
    } else if (arg == "--seed") {
      settings.seed = unsigned(number(arg, value()));
    } else if (arg == "--layout") {
      const std::string name = value();
      if (name == "ycbineoat") layout = bt::io::Layout::YcbInEoat;
      else if (name == "tum") layout = bt::io::Layout::Tum;
      else fail("unknown layout '" + name + "' (ycbineoat | tum)");
    } else if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return 0;
    } else {
      fail("unknown option '" + arg + "'");
    }
  }
  if (out.empty()) fail("--out is required");
  if (mask_files == bt::synth::MaskFiles::LabelImages && settings.objects == 1) fail("--labels needs --objects 2 or 3");
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
