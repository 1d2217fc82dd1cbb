#include "util/timed_choice.h"

#include <algorithm>

namespace rtpg {

bool TimedChoice::next_takes_second() const {
  if (decided_) return second_;
  return passes_ > 0 && passes_ % 2 == 0;  // passes 2, 4, ...: the second way
}

void TimedChoice::record(bool second, double time, double units) {
  if (decided_) return;
  if (passes_++ > 0 && units > 0.0) (second ? second_times_ : first_times_).push_back(time / units);
  if (first_times_.size() < kTrials || second_times_.size() < kTrials) return;
  const auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  second_ = median(second_times_) < (1.0 - kMargin) * median(first_times_);
  decided_ = true;
}

}  // namespace rtpg
