// The redraw limit on a made-up clock: never more than 30 frames a second however often the UI
// thread asks and whatever changes; 10 a second when only the live values move; the first frame
// at once; a change is drawn within one frame period.
#include <gtest/gtest.h>

#include "ui/frame_pacer.hpp"

namespace bellows::ui {
namespace {

// Asks every `step_s` for `seconds`; `revision_of(i)` and `active` describe the console.
template <typename Revision>
int frames(double seconds, double step_s, bool active, Revision revision_of) {
  FramePacer pacer;
  int drawn = 0;
  const int asks = static_cast<int>(seconds / step_s);
  for (int i = 0; i < asks; ++i) drawn += pacer.should_draw(100.0 + i * step_s, revision_of(i), active);
  return drawn;
}

TEST(UiFramePacer, AtMostThirtyFramesASecond) {
  // Trials running and a change at every ask (every millisecond): 30 a second at most.
  const int busy = frames(10.0, 0.001, true, [](int i) { return static_cast<std::uint64_t>(i); });
  EXPECT_LE(busy, 10 * 30 + 1);
  EXPECT_GE(busy, 10 * 29);  // and it does keep up
  // Keys typed ahead every 0.1 ms: still no more.
  EXPECT_LE(frames(1.0, 0.0001, false, [](int i) { return static_cast<std::uint64_t>(i); }), 31);
}

TEST(UiFramePacer, TenFramesASecondWhenOnlyLiveValuesMove) {
  const int idle = frames(10.0, 0.001, false, [](int) { return std::uint64_t{7}; });
  EXPECT_LE(idle, 10 * 10 + 1);
  EXPECT_GE(idle, 10 * 9);
}

TEST(UiFramePacer, TheFirstFrameAtOnceAndAChangeWithinAFramePeriod) {
  FramePacer pacer;
  EXPECT_TRUE(pacer.should_draw(5.0, 0, false));
  EXPECT_FALSE(pacer.should_draw(5.01, 1, false));  // too soon after the last frame
  EXPECT_TRUE(pacer.should_draw(5.0 + FramePacer::kFramePeriodS + 1e-9, 1, false));
  EXPECT_FALSE(pacer.should_draw(5.05, 1, false));  // nothing new, idle
}

}  // namespace
}  // namespace bellows::ui
