#pragma once

#include <algorithm>
#include <deque>
#include <limits>
#include <vector>

#include "bundletrack/graph/keyframe.hpp"

namespace bundletrack {

/// The keyframe memory pool (paper IV-C, IV-E) with bounded size. The first keyframe (frame 0)
/// never leaves: it has no drift and anchors the graph.
class KeyframePool {
 public:
  explicit KeyframePool(std::size_t capacity) : capacity_(std::max<std::size_t>(capacity, 2)) {}

  std::size_t size() const { return keyframes_.size(); }
  bool empty() const { return keyframes_.empty(); }
  Keyframe& operator[](std::size_t k) { return keyframes_[k]; }
  const Keyframe& operator[](std::size_t k) const { return keyframes_[k]; }

  /// Paper IV-E: a frame is a novel view when its rotation is more than min_rotation (radians)
  /// from every keyframe's.
  bool isNovelView(const SO3d& rotation, double min_rotation) const {
    return std::all_of(keyframes_.begin(), keyframes_.end(), [&](const Keyframe& k) {
      return rotationGeodesic(k.T_cam_obj.rotation(), rotation) > min_rotation;
    });
  }

  /// Adds a keyframe; when full, first evicts the most redundant one other than frame 0: the one
  /// whose nearest neighbour in rotation is nearest. Returns the id evicted, or -1.
  int add(Keyframe keyframe) {
    int evicted = -1;
    if (keyframes_.size() == capacity_) {
      std::size_t worst = 1;
      double smallest = std::numeric_limits<double>::infinity();
      for (std::size_t a = 1; a < keyframes_.size(); ++a) {
        for (std::size_t c = 0; c < keyframes_.size(); ++c) {
          if (c == a) continue;
          const double d = rotationGeodesic(keyframes_[a].T_cam_obj.rotation(), keyframes_[c].T_cam_obj.rotation());
          if (d < smallest) smallest = d, worst = a;
        }
      }
      evicted = keyframes_[worst].id;
      keyframes_.erase(keyframes_.begin() + std::ptrdiff_t(worst));
    }
    keyframes_.push_back(std::move(keyframe));
    return evicted;
  }

  /// Paper IV-C, greedy: start from frame 0; repeatedly add the keyframe with the smallest sum of
  /// rotation geodesics to the current frame's rotation and to every keyframe chosen so far, until
  /// `count` are chosen. Returns pool indices, frame 0 first.
  std::vector<std::size_t> select(const SO3d& current, std::size_t count) const {
    std::vector<std::size_t> chosen;
    if (keyframes_.empty() || count == 0) return chosen;
    chosen.push_back(0);
    std::vector<double> score(keyframes_.size());
    for (std::size_t k = 0; k < keyframes_.size(); ++k)
      score[k] = rotationGeodesic(keyframes_[k].T_cam_obj.rotation(), current) +
                 rotationGeodesic(keyframes_[k].T_cam_obj.rotation(), keyframes_[0].T_cam_obj.rotation());
    std::vector<bool> taken(keyframes_.size(), false);
    taken[0] = true;
    while (chosen.size() < std::min(count, keyframes_.size())) {
      std::size_t best = 0;
      double best_score = std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < keyframes_.size(); ++k)
        if (!taken[k] && score[k] < best_score) best_score = score[k], best = k;
      taken[best] = true;
      chosen.push_back(best);
      for (std::size_t k = 0; k < keyframes_.size(); ++k)  // sums grow by the distance to the new member
        score[k] += rotationGeodesic(keyframes_[k].T_cam_obj.rotation(), keyframes_[best].T_cam_obj.rotation());
    }
    return chosen;
  }

 private:
  std::size_t capacity_;
  std::deque<Keyframe> keyframes_;
};

}  // namespace bundletrack
