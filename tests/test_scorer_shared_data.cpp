// The scorer against an independent implementation on a real sequence: brute-force ADD-S and the
// YCB-Video toolbox's VOCap written out literally (array form).
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <random>

#include "bundletrack/eval/sequence_score.hpp"
#include "bundletrack/io/rgbd_sequence.hpp"
#include "shared_data.hpp"

namespace bt = bundletrack;

namespace {

double vocapLiteral(std::vector<double> errors) {
  const std::size_t n = errors.size();
  std::sort(errors.begin(), errors.end());
  std::vector<double> rec, prec;
  for (std::size_t k = 0; k < n; ++k)
    if (errors[k] <= 0.1) rec.push_back(errors[k]), prec.push_back(double(k + 1) / double(n));
  if (rec.empty()) return 0.0;
  std::vector<double> mrec = {0.0}, mpre = {0.0};
  mrec.insert(mrec.end(), rec.begin(), rec.end());
  mrec.push_back(0.1);
  mpre.insert(mpre.end(), prec.begin(), prec.end());
  mpre.push_back(prec.back());
  for (std::size_t i = 1; i < mpre.size(); ++i) mpre[i] = std::max(mpre[i], mpre[i - 1]);
  double ap = 0.0;
  for (std::size_t i = 1; i < mrec.size(); ++i)
    if (mrec[i] != mrec[i - 1]) ap += (mrec[i] - mrec[i - 1]) * mpre[i];
  return ap * 10.0 * 100.0;
}

}  // namespace

TEST_CASE("scorer agrees with brute force ADD-S and a literal VOCap on a shared sequence") {
  const auto dir = sharedDataDir() / "7scenes_objects" / "magazines_1";
  if (!std::filesystem::is_directory(dir)) {
    MESSAGE("SKIPPED: " << dir << " is absent");
    return;
  }
  const bt::io::RgbdSequence sequence(dir);
  std::vector<Eigen::Vector3f> model = sequence.modelPoints();
  model.resize(std::min<std::size_t>(model.size(), 1500));  // keeps the brute force to seconds
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<bt::SE3d> truth, estimate;
  std::vector<double> add, adds;
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    truth.push_back(sequence.groundTruthPose(i));
    // Errors growing over the sequence, so the curve spans the 0-10 cm range.
    const double scale = 0.001 + 0.0008 * double(i);
    bt::SE3d::Tangent d;
    for (int k = 0; k < 6; ++k) d[k] = noise(rng) * (k < 3 ? scale : 0.5 * scale / 0.1);
    estimate.push_back(truth.back() * bt::SE3d::exp(d));
    double sum_add = 0.0, sum_adds = 0.0;
    for (const auto& x : model) {
      const Eigen::Vector3d a = truth.back() * x.cast<double>();
      sum_add += (a - estimate.back() * x.cast<double>()).norm();
      double best = 1e300;
      for (const auto& y : model) best = std::min(best, (a - estimate.back() * y.cast<double>()).norm());
      sum_adds += best;
    }
    add.push_back(sum_add / double(model.size()));
    adds.push_back(sum_adds / double(model.size()));
  }
  const bt::SequenceScore score = bt::scoreSequence(model, truth, estimate);
  MESSAGE("ADD AUC " << score.add_auc << " (independent " << vocapLiteral(add) << "), ADD-S AUC " << score.adds_auc
                     << " (independent " << vocapLiteral(adds) << ")");
  CHECK(vocapLiteral(add) > 5.0);
  CHECK(vocapLiteral(add) < 95.0);  // the errors do span the curve
  CHECK(std::abs(score.add_auc - vocapLiteral(add)) < 0.01);
  CHECK(std::abs(score.adds_auc - vocapLiteral(adds)) < 0.01);
}
