// Uses the installed package: a pose, a camera and an in-memory frame from the headers, and a
// tracker built at run time by bundletrack::runtime.
#include <bundletrack/core/rgbd_frame.hpp>
#include <bundletrack/core/se3.hpp>
#include <bundletrack/runtime/make_tracker.hpp>

#include <cstdio>

int main() {
  namespace bt = bundletrack;
  const bt::SE3d T_cam_obj(bt::SO3d::exp(Eigen::Vector3d(0.1, 0.2, 0.3)), Eigen::Vector3d(0.0, 0.0, 0.7));
  const bt::PinholeCameraf camera{500.0f, 500.0f, 31.5f, 23.5f};
  const cv::Mat depth(48, 64, CV_32FC1, cv::Scalar(0.7f));
  cv::Mat mask(48, 64, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(20, 14, 24, 20)).setTo(255);
  const bt::RgbdFrame frame = bt::makeFrame("0", cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(0)), depth, mask, camera);
  const double round_trip = (bt::SE3d::exp(T_cam_obj.log()).matrix() - T_cam_obj.matrix()).norm();
  const cv::Vec3f n = frame.normals.at<cv::Vec3f>(24, 32);
  const auto tracker = bt::makeTracker(bt::Config(), camera);
  const bt::TrackResult first = tracker->initialize(frame, T_cam_obj);
  const bool started = first.status == bt::TrackStatus::Tracked && tracker->keyframeCount() == 1 &&
                       (first.T_cam_obj.matrix() - T_cam_obj.matrix()).norm() == 0.0;
  std::printf("round trip %.3g, normal z %.3f, tracker started: %s\n", round_trip, n[2], started ? "yes" : "no");
  return round_trip < 1e-12 && n[2] < -0.999f && started ? 0 : 1;
}
