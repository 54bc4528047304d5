#pragma once

#include <map>
#include <utility>
#include <vector>

#include "bundletrack/graph/keyframe.hpp"

namespace bundletrack {

/// Feature correspondences between keyframe pairs, built once (paper IV-D: "if C_ij has been
/// built ... it is reused") and forgotten with an evicted keyframe.
class CorrespondenceCache {
 public:
  /// The pair's correspondences; build(a, b) makes them the first time.
  template <typename Build>
  const std::vector<FeatureMatch>& get(const Keyframe& a, const Keyframe& b, Build&& build) {
    const auto key = std::make_pair(a.id, b.id);
    auto found = pairs_.find(key);
    if (found == pairs_.end()) found = pairs_.emplace(key, build(a, b)).first;
    return found->second;
  }

  void forget(int keyframe_id) {
    for (auto it = pairs_.begin(); it != pairs_.end();)
      it = it->first.first == keyframe_id || it->first.second == keyframe_id ? pairs_.erase(it) : std::next(it);
  }

  void clear() { pairs_.clear(); }

 private:
  std::map<std::pair<int, int>, std::vector<FeatureMatch>> pairs_;
};

}  // namespace bundletrack
