// TimedChoice (util/timed_choice.h): which of two ways it keeps, and when.
#include <gtest/gtest.h>

#include <vector>

#include "util/timed_choice.h"

namespace rtpg {
namespace {

// Pass 0 takes the first way and is not counted; passes 1-6 alternate first, second; after
// them the second way is kept only where its median time per unit is below the first's by the
// margin, and the choice stays.
TEST(TimedChoice, KeepsTheSecondWayOnlyWhereItIsFasterByItsMargin) {
  const auto run = [](double first_time, double second_time, int* passes_to_decide) {
    TimedChoice choice;
    std::vector<bool> taken;
    for (int pass = 0; !choice.decided() && pass < 20; ++pass) {
      const bool second = choice.next_takes_second();
      taken.push_back(second);
      // Pass 0 far slower (a cold cache), and one outlier each way that the median ignores.
      double t = second ? second_time : first_time;
      if (pass == 0) t *= 10.0;
      if (pass == 1 || pass == 2) t *= 3.0;
      choice.record(second, t * 1000.0, 1000.0);
    }
    *passes_to_decide = static_cast<int>(taken.size());
    const std::vector<bool> schedule = {false, false, true, false, true, false, true};
    EXPECT_EQ(taken, schedule);
    return choice.next_takes_second();
  };
  int passes = 0;
  EXPECT_TRUE(run(1.0, 0.90, &passes));
  EXPECT_EQ(passes, 1 + 2 * TimedChoice::kTrials);
  EXPECT_FALSE(run(1.0, 0.99, &passes));  // within the margin: the first way
  EXPECT_FALSE(run(1.0, 1.20, &passes));
  // A pass without work counts for neither way.
  TimedChoice idle;
  for (int pass = 0; pass < 20; ++pass) idle.record(idle.next_takes_second(), 1.0, 0.0);
  EXPECT_FALSE(idle.decided());
}

}  // namespace
}  // namespace rtpg
