// The synthetic renderer and sequence generator against analytic geometry.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <numeric>

#include "bundletrack/core/depth_filter.hpp"
#include "bundletrack/io/rgbd_sequence.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"
#include "temp_dir.hpp"

namespace fs = std::filesystem;

namespace bt = bundletrack;
namespace synth = bundletrack::synth;

namespace {

const bt::PinholeCamerad kCamera{600.0, 600.0, 319.5, 239.5};
const cv::Size kSize(640, 480);

synth::SensorSettings perfectSensor() { return synth::SensorSettings::perfect(); }

// Closest distance from p to triangle abc (Ericson, Real-Time Collision Detection, 5.1.5).
double pointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return (p - a).norm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return (p - b).norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return (p - c).norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * vb * denom + ac * vc * denom)).norm();
}

double distanceToMesh(const Eigen::Vector3d& p, const synth::TriangleMesh& mesh) {
  double best = std::numeric_limits<double>::max();
  for (const auto& [a, b, c] : mesh.triangles)
    best = std::min(best, pointTriangleDistance(p, mesh.positions[a], mesh.positions[b], mesh.positions[c]));
  return best;
}

}  // namespace

TEST_CASE("rendered depth of a plane equals the analytic depth, also after millimetre quantisation") {
  const cv::Mat texture = synth::noiseTexture(64, 3);
  const Eigen::Vector3d u_axis = Eigen::Vector3d(1.0, 0.2, 0.1).normalized();
  const Eigen::Vector3d v_axis = u_axis.cross(Eigen::Vector3d(0.1, -0.3, 1.0)).normalized();
  const Eigen::Vector3d origin(0.05, -0.02, 0.9);
  const synth::Renderer renderer(kCamera, kSize);
  const auto clean = renderer.render({{origin, u_axis, v_axis, 0.5, &texture, 0}}, {});
  cv::Mat depth, color;
  synth::applySensorModel(clean, kCamera, perfectSensor(), 1, depth, color);
  cv::Mat depth_mm;
  depth.convertTo(depth_mm, CV_16UC1, 1000.0);
  const Eigen::Vector3d n = u_axis.cross(v_axis);
  double worst_float = 0.0, worst_quantised = 0.0;
  int valid = 0;
  for (int v = 0; v < kSize.height; ++v) {
    for (int u = 0; u < kSize.width; ++u) {
      const Eigen::Vector3d ray = kCamera.unproject(u, v, 1.0);
      const double analytic = n.dot(origin) / n.dot(ray);  // ray . n z = origin . n
      if (analytic <= 0.2 || analytic >= 4.0) continue;
      ++valid;
      worst_float = std::max(worst_float, std::abs(depth.at<float>(v, u) - analytic));
      worst_quantised = std::max(worst_quantised, std::abs(depth_mm.at<uint16_t>(v, u) * 1e-3 - analytic));
    }
  }
  CHECK(valid > kSize.area() / 2);
  CHECK(worst_float < 1e-6 * 4.0);  // float storage of depths below 4 m
  CHECK(worst_quantised <= 0.5e-3 + 1e-6);  // half a millimetre: rounding to the written unit
}

TEST_CASE("rendered depth of a box equals ray-box intersection (slab method)") {
  const cv::Mat texture = synth::richTexture(256, 5);
  const Eigen::Vector3d size(0.10, 0.07, 0.16);
  const synth::TriangleMesh box = synth::makeBox(size);
  const bt::SE3d T_cam_box(bt::SO3d::exp(Eigen::Vector3d(0.4, -0.7, 0.3)), Eigen::Vector3d(0.03, -0.02, 0.6));
  const auto clean = synth::Renderer(kCamera, kSize).render({}, {{&box, &texture, T_cam_box, 7}});
  const bt::SE3d T_box_cam = T_cam_box.inverse();
  int both = 0, only_one = 0;
  double worst = 0.0;
  for (int v = 0; v < kSize.height; ++v) {
    for (int u = 0; u < kSize.width; ++u) {
      // Ray x(t) = t K^-1 [u v 1] in the camera, so t is the depth; slabs in the box frame.
      const Eigen::Vector3d origin = T_box_cam.translation();
      const Eigen::Vector3d dir = T_box_cam.rotation() * kCamera.unproject(u, v, 1.0);
      double t_near = -1e9, t_far = 1e9;
      for (int k = 0; k < 3; ++k) {
        const double t0 = (-0.5 * size[k] - origin[k]) / dir[k], t1 = (0.5 * size[k] - origin[k]) / dir[k];
        t_near = std::max(t_near, std::min(t0, t1));
        t_far = std::min(t_far, std::max(t0, t1));
      }
      const bool hit = t_near <= t_far && t_near > 0.0;
      const bool rendered = clean.label.at<int>(v, u) == 7;
      if (hit && rendered) {
        ++both;
        worst = std::max(worst, std::abs(clean.depth.at<float>(v, u) - t_near));
      } else if (hit != rendered) {
        ++only_one;
      }
    }
  }
  CHECK(both > 3000);
  CHECK(worst < 1e-6);
  // Only pixel centres lying exactly on the silhouette may disagree; none should in practice.
  CHECK(only_one <= both / 500);
}

TEST_CASE("the mask is exactly the set of pixels whose depth comes from the object") {
  synth::SyntheticSequenceSettings settings;
  settings.shape = synth::Shape::Mug;
  settings.occluder = true;
  settings.frames = 100;
  const synth::SyntheticScene scene(settings);
  const double frame = 47.0;  // the occluder (frames 30-70) covers part of the object here
  const auto with = scene.renderClean(frame, true), without = scene.renderClean(frame, false);
  const cv::Mat mask = scene.frame(int(frame)).mask;
  const cv::Mat changed = with.depth != without.depth;
  CHECK(cv::countNonZero(mask) > 1000);
  CHECK(cv::countNonZero(mask != changed) == 0);
  // The occluder does hide part of the object: its unoccluded silhouette is larger.
  const auto unoccluded = synth::SyntheticScene([&] {
                            auto s = settings;
                            s.occluder = false;
                            return s;
                          }())
                              .frame(int(frame))
                              .mask;
  CHECK(cv::countNonZero(unoccluded) > cv::countNonZero(mask) + 200);
}

TEST_CASE("depth noise presets follow their formulas: structured light (Kinect v1), active stereo (D435), time of flight (Azure Kinect)") {
  // By hand: 1.2 mm + 1.9 mm/m^2 (z - 0.4)^2, and z^2 0.08 px / (600 px 0.05 m) = z^2 2.667 mm/m^2.
  const bt::DepthNoise light = bt::DepthNoise::structuredLight(), stereo = bt::DepthNoise::activeStereo();
  const double f = 600.0;
  CHECK(light.sigma(0.5, f) == doctest::Approx(0.001219).epsilon(1e-9));
  CHECK(light.sigma(1.5, f) == doctest::Approx(0.003499).epsilon(1e-9));
  CHECK(light.sigma(3.0, f) == doctest::Approx(0.014044).epsilon(1e-9));
  CHECK(stereo.sigma(0.5, f) == doctest::Approx(0.25 * 0.08 / 30.0).epsilon(1e-9));
  CHECK(stereo.sigma(3.0, f) == doctest::Approx(0.024).epsilon(1e-9));
  // Disparity quantisation in 1/8 px over 7.5 cm: at 3 m neighbouring levels are z^2 / (8 f b) = 2.5 cm apart.
  CHECK(light.quantisationStep(3.0, f) == doctest::Approx(0.025).epsilon(1e-9));
  const double level = light.quantised(2.9871, f);
  CHECK(std::abs(std::remainder(f * 0.075 / level, 0.125)) < 1e-9);  // a whole number of 1/8 px
  CHECK(std::abs(level - 2.9871) <= 0.5 * light.quantisationStep(2.9871, f) * 1.01);
  CHECK(stereo.quantised(2.9871, f) == 2.9871);
  // Time of flight: linear up to the specified 17 mm at the end of the 3.86 m range.
  const bt::DepthNoise tof = bt::DepthNoise::timeOfFlight();
  CHECK(tof.sigma(3.86, f) == doctest::Approx(0.017).epsilon(1e-12));
  CHECK(tof.sigma(1.0, f) == doctest::Approx(0.017 / 3.86).epsilon(1e-12));
  // The spread adds the uniform rounding error: sqrt(sigma^2 + step^2 / 12).
  CHECK(light.spread(3.0, f) == doctest::Approx(std::hypot(0.014044, 0.025 / std::sqrt(12.0))).epsilon(1e-6));
  CHECK(stereo.spread(3.0, f) == stereo.sigma(3.0, f));
}

TEST_CASE("the noise scale is the spread over structured light's at 1 m, never below 1") {
  // Reference by hand: sigma = 1.2 + 1.9 * 0.36 = 1.884 mm, step = 0.125 / (525 * 0.075) = 3.175 mm.
  const double reference = std::hypot(0.001884, 0.125 / (525.0 * 0.075) / std::sqrt(12.0));
  CHECK(bt::NoiseScale::referenceSpread() == doctest::Approx(reference).epsilon(1e-9));
  const bt::NoiseScale light(bt::DepthNoise::structuredLight(), 525.0);
  CHECK(light.unitDepth() == doctest::Approx(1.0).epsilon(1e-5));  // the reference itself
  CHECK(light.at(0.5) == 1.0);
  CHECK(light.at(3.0) == doctest::Approx(bt::DepthNoise::structuredLight().spread(3.0, 525.0) / reference).epsilon(1e-12));
  CHECK(light.widen(0.01f, 3.0f) == doctest::Approx(0.01 * light.at(3.0)).epsilon(1e-6));
  CHECK(light.widen(0.01f, 0.7f) == 0.01f);
  // Stereo with the D435's numbers: z^2 0.08 / (600 0.05) reaches the reference at 0.887 m.
  const bt::NoiseScale stereo(bt::DepthNoise::activeStereo(), 600.0);
  CHECK(stereo.unitDepth() == doctest::Approx(std::sqrt(reference * 600.0 * 0.05 / 0.08)).epsilon(1e-5));
  CHECK(stereo.at(2.0) == doctest::Approx(4.0 * 0.08 / 30.0 / reference).epsilon(1e-9));
  // The median of the readings decides; a pair's factor is the RMS of the two.
  CHECK(light.atMedian({0.5f, 3.0f, 3.0f}) == light.at(3.0f));
  CHECK(light.atMedian({}) == 1.0);
  CHECK(bt::NoiseScale::between(1.0, 7.0) == doctest::Approx(5.0));
}

TEST_CASE("the synthetic sensor's depth spreads as its preset's sigma(z) at 0.5, 1.5 and 3 m") {
  const cv::Mat texture = synth::noiseTexture(64, 3);
  for (const bt::DepthNoise& preset :
       {bt::DepthNoise::structuredLight(), bt::DepthNoise::activeStereo(), bt::DepthNoise::timeOfFlight()}) {
    for (const double z : {0.5, 1.5, 3.0}) {
      CAPTURE(preset.subpixel);
      CAPTURE(preset.linear);
      CAPTURE(z);
      const auto clean = synth::Renderer(kCamera, kSize).render(
          {{Eigen::Vector3d(0, 0, z), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 1.0, &texture, 0}}, {});
      synth::SensorSettings sensor = perfectSensor();
      sensor.depth_noise = preset;
      sensor.depth_noise.disparity_step = 0.0;  // the spread alone (quantisation is checked above)
      cv::Mat depth, color;
      synth::applySensorModel(clean, kCamera, sensor, 9, depth, color);
      cv::Scalar mean, stddev;
      cv::meanStdDev(depth - clean.depth, mean, stddev);
      const double sigma = sensor.depth_noise.sigma(z, kCamera.fx);
      // 307200 samples: the standard deviation's relative standard error is 1/sqrt(2n) = 0.13%.
      CHECK(stddev[0] == doctest::Approx(sigma).epsilon(0.01));
      CHECK(std::abs(mean[0]) < 5.0 * sigma / std::sqrt(double(kSize.area())));
    }
  }
}

TEST_CASE("a triangulating sensor's shadow: what its second viewpoint cannot see beside a nearer surface") {
  // A step: the right half of the image at 1 m, the left half at 2 m. The second viewpoint (the
  // projector) sits 7.5 cm along +x; a pixel of the far half is hidden where the ray from there to
  // its point crosses z = 1 m within the near half (pixel centres from column 320 on).
  const double fx = kCamera.fx, cx = kCamera.cx, baseline = 0.075, near = 1.0, far = 2.0;
  cv::Mat depth(kSize, CV_32FC1, cv::Scalar(far));
  depth.colRange(320, kSize.width).setTo(near);
  const cv::Mat shadowed = synth::shadowedPixels(depth, fx, baseline);
  const double near_left = (320 - cx) * near / fx, near_right = (kSize.width - 1 - cx) * near / fx;
  int hidden = 0, wrong = 0;
  for (int u = 0; u < kSize.width; ++u) {
    const double z = depth.at<float>(0, u), x = (u - cx) * z / fx;
    const double x_at_near = baseline + (x - baseline) * near / z;  // where the ray from the projector crosses z = near
    const bool expected = z > near && x_at_near >= near_left && x_at_near <= near_right;
    hidden += expected;
    for (int v = 0; v < kSize.height; ++v) wrong += (shadowed.at<uchar>(v, u) != 0) != expected;
  }
  CHECK(wrong == 0);
  // The band is fx baseline (1 / near - 1 / far) = 22.5 px wide: columns 298-319.
  CHECK(hidden == 22);
  CHECK(cv::countNonZero(synth::shadowedPixels(depth, fx, 0.0)) == 0);
  // The sensor reads nothing there and everything else: structured light (a 7.5 cm baseline)
  // casts it, time of flight does not.
  synth::RenderBuffers clean{depth, cv::Mat(kSize, CV_32SC1, cv::Scalar(0)), cv::Mat(kSize, CV_32FC3, cv::Scalar::all(0.5)),
                             cv::Mat(kSize, CV_32FC3, cv::Scalar(0.0, 0.0, -1.0))};
  for (const bt::DepthNoise& preset : {bt::DepthNoise::structuredLight(), bt::DepthNoise::timeOfFlight()}) {
    synth::SensorSettings sensor = perfectSensor();
    sensor.depth_noise = preset;
    sensor.shadow = true;
    cv::Mat read, color;
    synth::applySensorModel(clean, kCamera, sensor, 3, read, color);
    const cv::Mat none = read == 0.0f;
    CHECK(cv::countNonZero(none) == (synth::triangulates(preset) ? hidden * kSize.height : 0));
    CHECK(cv::countNonZero(none & ~shadowed) == 0);
  }
  depth.setTo(near);
  CHECK(cv::countNonZero(synth::shadowedPixels(depth, fx, baseline)) == 0);  // a plane facing the camera: none
}

TEST_CASE("a time-of-flight camera's flying pixels: the sensor mixes the two surfaces at a depth edge, the depth filter takes nearly all off") {
  // A step: the right half at 1 m, the left half at 2 m; every edge pixel keeps its reading and
  // reads a mix of the two depths.
  const double near = 1.0, far = 2.0;
  cv::Mat depth(kSize, CV_32FC1, cv::Scalar(far));
  depth.colRange(320, kSize.width).setTo(near);
  synth::RenderBuffers clean{depth, cv::Mat(kSize, CV_32SC1, cv::Scalar(0)), cv::Mat(kSize, CV_32FC3, cv::Scalar::all(0.5)),
                             cv::Mat(kSize, CV_32FC3, cv::Scalar(0.0, 0.0, -1.0))};
  synth::SensorSettings sensor = perfectSensor();
  sensor.depth_noise = bt::DepthNoise::timeOfFlight();
  sensor.flying_pixels = 1.0;
  cv::Mat read, color;
  synth::applySensorModel(clean, kCamera, sensor, 5, read, color);
  // Readings more than 5 sigma (5 x 4.4 mm per metre) from their own surface.
  const auto off_surface = [&](const cv::Mat& reading, double& mean_mix) {
    int off = 0, edge = 0;
    mean_mix = 0.0;
    for (int v = 0; v < kSize.height; ++v)
      for (int u = 0; u < kSize.width; ++u) {
        const double z = reading.at<float>(v, u), truth = depth.at<float>(v, u);
        if (z <= 0.0) continue;
        off += std::abs(z - truth) > 5.0 * sensor.depth_noise.sigma(truth, kCamera.fx);
        if (u == 319 || u == 320) {
          mean_mix += (z - truth) / ((u == 319 ? near : far) - truth);
          ++edge;
        }
      }
    mean_mix /= std::max(edge, 1);
    return off;
  };
  double mix = 0.0;
  const int flying = off_surface(read, mix);
  MESSAGE("flying pixels read: " << flying << ", mean mix " << mix);
  // The two edge columns, 960 pixels, mixed by a uniform fraction (mean 1/2); a fraction within
  // 5 sigma of either end (2-4 % of the 1 m gap) stays on its surface.
  CHECK(flying > 850);
  CHECK(flying <= 960);
  CHECK(mix == doctest::Approx(0.5).epsilon(0.1));
  // The filter's erosion: a flying pixel differs from most of its neighbours, on either surface
  // and along the edge, by more than 3 sigma of two readings' difference. One whose neighbours
  // along the edge happen to read within that of it stays (two of its five in the edge columns
  // within 2.8 cm at 1.5 m: a few percent of them).
  const cv::Mat filtered = bt::filterDepth(read, bt::DepthFilterSettings(), bt::NoiseScale(sensor.depth_noise, kCamera.fx));
  const int kept = off_surface(filtered, mix);
  MESSAGE("flying pixels after the depth filter: " << kept);
  CHECK(kept <= 0.05 * flying);
  // Nor does it take the surfaces: all but the edge columns and a few beside them remain.
  CHECK(cv::countNonZero(filtered > 0.0f) >= (kSize.width - 6) * kSize.height);
}

TEST_CASE("the synthetic distance option places the camera that far from the object, hand-held and orbiting") {
  for (const auto motion : {synth::Motion::HandHeld, synth::Motion::CameraOrbit}) {
    for (const double distance : {0.5, 3.0}) {
      CAPTURE(int(motion));
      CAPTURE(distance);
      synth::SyntheticSequenceSettings settings;
      settings.frames = 1;
      settings.motion = motion;
      settings.distance = distance;
      const synth::SyntheticScene scene(settings);
      // Frame 0: the hand-held object sits at the centre of its motion (no drift yet).
      CHECK(scene.T_cam_obj(0).translation().norm() == doctest::Approx(distance).epsilon(1e-12));
      // The object is in view, at that depth: the median masked depth lies within its size.
      const synth::SyntheticFrame f = scene.frame(0);
      std::vector<float> depths;
      for (int v = 0; v < f.depth.rows; ++v)
        for (int u = 0; u < f.depth.cols; ++u)
          if (f.mask.at<uchar>(v, u) && f.depth.at<float>(v, u) > 0.0f) depths.push_back(f.depth.at<float>(v, u));
      REQUIRE(depths.size() > 50);
      std::nth_element(depths.begin(), depths.begin() + std::ptrdiff_t(depths.size() / 2), depths.end());
      CHECK(std::abs(depths[depths.size() / 2] - distance) < 0.12);
    }
  }
}

TEST_CASE("the synthetic size option scales the object to the bounding-box diagonal asked for") {
  const auto diagonal = [](const synth::TriangleMesh& mesh) {
    Eigen::AlignedBox3d bounds;
    for (const auto& p : mesh.positions) bounds.extend(p);
    return Eigen::Vector3d(bounds.diagonal());
  };
  for (const auto shape : {synth::Shape::Box, synth::Shape::Cylinder, synth::Shape::Mug, synth::Shape::Chair}) {
    CAPTURE(int(shape));
    synth::SyntheticSequenceSettings settings;
    settings.frames = 1;
    settings.shape = shape;
    const Eigen::Vector3d own = diagonal(synth::SyntheticScene(settings).objectMesh());
    MESSAGE("shape " << int(shape) << ": own diagonal " << own.norm() << " m");
    settings.size = 0.7;
    const Eigen::Vector3d scaled = diagonal(synth::SyntheticScene(settings).objectMesh());
    CHECK(scaled.norm() == doctest::Approx(0.7).epsilon(1e-12));
    CHECK((scaled / scaled.norm() - own / own.norm()).norm() < 1e-12);  // the same proportions
  }
}

TEST_CASE("the chair: legs, seat and back within its 0.36 x 0.36 x 0.66 m bounds, seen with gaps at 2.5 m") {
  const synth::TriangleMesh chair = synth::makeChair();
  Eigen::AlignedBox3d bounds;
  for (const auto& p : chair.positions) bounds.extend(p);
  CHECK((bounds.diagonal() - Eigen::Vector3d(0.36, 0.36, 0.66)).norm() < 1e-12);
  CHECK(bounds.center().norm() < 1e-12);
  CHECK(chair.positions.size() == 6 * 24);  // six boxes
  synth::SyntheticSequenceSettings settings;
  settings.frames = 1;
  settings.shape = synth::Shape::Chair;
  settings.motion = synth::Motion::CameraOrbit;
  settings.distance = 2.5;
  const synth::SyntheticFrame f = synth::SyntheticScene(settings).frame(0);
  const int area = cv::countNonZero(f.mask);
  const cv::Rect box = cv::boundingRect(f.mask);
  MESSAGE("chair at 2.5 m: " << area << " mask pixels in a " << box.width << " x " << box.height << " box");
  CHECK(area > 1000);
  CHECK(area < 0.8 * box.area());  // between the legs and under the seat the background shows
}

TEST_CASE("masked sensor depth unprojected with the ground-truth pose lies on the object surface") {
  for (const auto shape : {synth::Shape::Box, synth::Shape::Cylinder, synth::Shape::Mug}) {
    synth::SyntheticSequenceSettings settings;
    settings.shape = shape;
    const synth::SyntheticScene scene(settings);
    const synth::SyntheticFrame frame = scene.frame(37);
    const bt::SE3d T_obj_cam = frame.T_cam_obj.inverse();
    double sum = 0.0, depth_sum = 0.0;
    int count = 0;
    for (int v = 0; v < kSize.height; v += 2) {
      for (int u = 0; u < kSize.width; u += 2) {
        const float z = frame.depth.at<float>(v, u);
        if (!frame.mask.at<uchar>(v, u) || z <= 0.0f) continue;
        sum += distanceToMesh(T_obj_cam * kCamera.unproject(u, v, z), scene.objectMesh());
        depth_sum += z;
        ++count;
      }
    }
    REQUIRE(count > 300);
    const double mean_distance = sum / count,
                 sigma = settings.sensor.depth_noise.sigma(depth_sum / count, kCamera.fx);
    MESSAGE("shape " << int(shape) << ": mean distance " << 1e3 * mean_distance << " mm, sigma(z) " << 1e3 * sigma
                     << " mm over " << count << " points");
    // A Gaussian's mean absolute value is 0.8 sigma; disparity quantisation adds a little and the
    // distance to the surface is at most the error along the ray.
    CHECK(mean_distance < sigma);
  }
}

TEST_CASE("a written synthetic sequence reads back with its ground truth, deterministically") {
  TempDir dir("synth");
  synth::SyntheticSequenceSettings settings;
  settings.frames = 4;
  settings.model_points = 500;
  synth::writeSyntheticSequence(dir.path() / "a", settings);
  synth::writeSyntheticSequence(dir.path() / "b", settings);
  const bt::io::RgbdSequence a(dir.path() / "a"), b(dir.path() / "b");
  REQUIRE(a.size() == 4);
  CHECK(a.camera().fx == kCamera.fx);
  CHECK(a.modelPoints().size() == 500);
  const synth::SyntheticScene scene(settings);
  for (std::size_t i = 0; i < a.size(); ++i) {
    CHECK((a.groundTruthPose(i).matrix() - scene.T_cam_obj(double(i)).matrix()).norm() < 1e-8);
    CHECK(cv::norm(a.rawDepth(i), b.rawDepth(i), cv::NORM_INF) == 0.0);
    CHECK(cv::norm(a.frame(i).color, b.frame(i).color, cv::NORM_INF) == 0.0);
  }
  settings.seed = 2;
  synth::writeSyntheticSequence(dir.path() / "c", settings);
  CHECK(cv::norm(a.rawDepth(1), bt::io::RgbdSequence(dir.path() / "c").rawDepth(1), cv::NORM_INF) > 0.0);
  // Written again, shorter, over the first: the earlier sequence's last frames are gone.
  settings.frames = 2;
  synth::writeSyntheticSequence(dir.path() / "a", settings);
  const bt::io::RgbdSequence again(dir.path() / "a");
  CHECK(again.size() == 2);
  CHECK(std::distance(std::filesystem::directory_iterator(dir.path() / "a" / "masks"), {}) == 2);
  CHECK(cv::norm(again.rawDepth(1), bt::io::RgbdSequence(dir.path() / "c").rawDepth(1), cv::NORM_INF) == 0.0);
}

TEST_CASE("the TUM RGB-D layout: timestamps associated, depth in 1/5000 m, the same frames as YCBInEOAT") {
  TempDir dir("tum");
  synth::SyntheticSequenceSettings settings;
  settings.frames = 5;
  settings.model_points = 200;
  synth::writeSyntheticSequence(dir.path() / "ycb", settings);
  synth::writeSyntheticSequence(dir.path() / "tum", settings, bt::io::Layout::Tum);
  const bt::io::RgbdSequence ycb(dir.path() / "ycb"), tum(dir.path() / "tum");
  REQUIRE(tum.size() == 5);
  CHECK(tum.frameNames()[1] == "1305031102.033333");  // the colour image's timestamp
  CHECK(tum.depthScale() == doctest::Approx(0.0002));
  CHECK(tum.depthPath(1).filename() == "1305031102.037333.png");  // depth 4 ms later
  const synth::SyntheticScene scene(settings);
  for (std::size_t i = 0; i < tum.size(); ++i) {
    CHECK((tum.groundTruthPose(i).matrix() - scene.T_cam_obj(double(i)).matrix()).norm() < 1e-8);
    const bt::RawFrame a = ycb.read(i), b = tum.read(i);
    CHECK(cv::norm(a.color, b.color, cv::NORM_INF) == 0.0);
    CHECK(cv::norm(a.mask, b.mask, cv::NORM_INF) == 0.0);
    // Both are the renderer's depth rounded: to 1 mm and to 0.2 mm.
    const cv::Mat exact = scene.frame(int(i)).depth;
    CHECK(cv::norm(b.depth, exact, cv::NORM_INF) <= 0.0001 + 1e-6);
    CHECK(cv::norm(a.depth, b.depth, cv::NORM_INF) <= 0.0006 + 1e-6);
  }
  // Forced to YCBInEOAT, the folder's depth images are looked for by the colour images' names.
  bt::io::SequenceSettings by_name;
  by_name.layout = bt::io::Layout::YcbInEoat;
  CHECK_THROWS_WITH_AS(bt::io::RgbdSequence(dir.path() / "tum", by_name),
                       doctest::Contains("depth/1305031102.000000.png: file not found"), bt::InputError);
}

TEST_CASE("TUM lists: comments skipped, nearest depth within the window, each depth image used once") {
  TempDir dir("tumlists");
  const fs::path root = dir.path();
  {
    std::ofstream(root / "rgb.txt") << "# colour\n1.00 rgb/a.png\n\n1.10 rgb/b.png  # trailing comment\n"
                                    << "1.50 rgb/c.png\n1.125 rgb/b2.png\n";
    std::ofstream(root / "depth.txt") << "# depth\n1.005 depth/x.png\n1.11 depth/y.png\n2.0 depth/z.png\n";
  }
  const bt::io::FrameFiles frames = bt::io::tumFrames(root, 0.02);
  // Sorted by time: a (1.00), b (1.10), b2 (1.125), c (1.50).
  REQUIRE(frames.names == std::vector<std::string>{"a", "b", "b2", "c"});
  CHECK(frames.depth[0] == root / "depth/x.png");
  // y (1.11) is within 20 ms of b (10 ms) and b2 (15 ms): the nearest pair takes it, b2 has none.
  CHECK(frames.depth[1] == root / "depth/y.png");
  CHECK(frames.depth[2].empty());
  CHECK(frames.depth[3].empty());  // nothing within 20 ms of 1.50
  CHECK(frames.missing_depth[3].find("within 20 ms") != std::string::npos);
  CHECK(frames.depth_unit == doctest::Approx(0.0002));
  std::ofstream(root / "depth.txt") << "1.0 depth/x.png\nnot-a-time depth/y.png\n";
  CHECK_THROWS_WITH_AS(bt::io::tumFrames(root, 0.02), doctest::Contains("line 2: 'not-a-time' is not a timestamp"),
                       bt::InputError);
  std::ofstream(root / "depth.txt") << "1.0\n";
  CHECK_THROWS_WITH_AS(bt::io::tumFrames(root, 0.02), doctest::Contains("line 1: a timestamp without a file"),
                       bt::InputError);
}
