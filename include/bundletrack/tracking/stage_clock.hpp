#pragma once

#include <utility>

#include "bundletrack/tracking/stopwatch.hpp"
#include "bundletrack/tracking/track_result.hpp"

namespace bundletrack {

/// A stage of the per-frame pipeline, as a field of StageTimings.
using Stage = double StageTimings::*;

/// Charges the time of one frame to the pipeline's stages: enter(stage) charges everything from
/// then on to `stage`, until the next enter(); measure(stage, f) charges f's time to `stage` and
/// returns to the stage it interrupted (matching and RANSAC run inside the coarse and graph stages).
class StageClock {
 public:
  void start(Stage stage) {
    timings_ = {};
    total_ = Stopwatch();
    lap_ = Stopwatch();
    stage_ = stage;
  }

  void enter(Stage stage) {
    charge();
    stage_ = stage;
  }

  template <typename F>
  decltype(auto) measure(Stage stage, F&& f) {
    struct Resume {
      StageClock& clock;
      Stage outer;
      ~Resume() { clock.enter(outer); }
    } resume{*this, stage_};
    enter(stage);
    return std::forward<F>(f)();
  }

  /// The frame's timings, total included.
  StageTimings stop() {
    charge();
    timings_.total = total_.lap();
    return timings_;
  }

 private:
  void charge() { timings_.*stage_ += lap_.lap(); }

  StageTimings timings_;
  Stopwatch total_, lap_;
  Stage stage_ = &StageTimings::mask;
};

}  // namespace bundletrack
