// Chooses between two ways of doing the same work whose relative speed depends on the scene and
// the machine, by timing them in turns (the path tracer's bounce rays listed or in groups:
// BounceRayOrder::automatic, render/path_tracer.h).
#pragma once

#include <vector>

namespace rtpg {

// Pass 0 warms the caches and is not counted; passes 1 to 2 * kTrials alternate the two ways;
// after that the second way is kept if its median time per unit of work is below the first's by
// at least kMargin, else the first.
class TimedChoice {
 public:
  static constexpr int kTrials = 3;
  static constexpr double kMargin = 0.03;

  // Whether the next pass takes the second way.
  bool next_takes_second() const;
  // A pass that took `second` (or the first way) and spent `time` (any unit) on `units` of
  // work.
  void record(bool second, double time, double units);
  bool decided() const { return decided_; }

 private:
  int passes_ = 0;
  bool decided_ = false, second_ = false;
  std::vector<double> first_times_, second_times_;  // time per unit
};

}  // namespace rtpg
