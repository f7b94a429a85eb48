#include "detect/person_tracker.h"

#include <gtest/gtest.h>

#include "common/error.h"

namespace m2d {
namespace {

// A detection whose box spans [x0, x1] x [y0, y1] with this score.
DetectedPerson Person(double x0, double y0, double x1, double y1,
                      double score = 0.5) {
  DetectedPerson person;
  person.box = Box{x0, y0, x1, y1};
  person.score = score;
  return person;
}

// The last box: a 40 x 80 px person (diagonal 89.4 px) at (100..140, 100..180).
const Box kLast{100, 100, 140, 180};

TEST(ChoosePerson, FirstSightingTakesTheBestScoringOrTheNthFromTheLeft) {
  // MultiPose lists people best first.
  const std::vector<DetectedPerson> people = {Person(300, 0, 340, 80, 0.9),
                                              Person(10, 0, 50, 80, 0.6),
                                              Person(150, 0, 190, 80, 0.4)};
  PersonTrackerOptions options;
  EXPECT_EQ(ChoosePerson(people, std::nullopt, options)->box.x0_px, 300);
  options.choice = PersonChoice::kIndex;
  options.person_index = 1;  // second from the left
  EXPECT_EQ(ChoosePerson(people, std::nullopt, options)->box.x0_px, 150);
  options.person_index = 3;  // only three people
  EXPECT_FALSE(ChoosePerson(people, std::nullopt, options));
}

TEST(ChoosePerson, LargestIgnoresWhereThePersonWas) {
  PersonTrackerOptions options;
  options.choice = PersonChoice::kLargest;
  const std::vector<DetectedPerson> people = {Person(100, 100, 140, 180),
                                              Person(500, 0, 600, 200)};
  EXPECT_EQ(ChoosePerson(people, kLast, options)->box.x0_px, 500);
}

TEST(ChoosePerson, ReacquiresTheDetectionOverlappingTheLastBoxMost) {
  PersonTrackerOptions options;
  // A passer-by overlaps a little (IoU 0.14), the person a lot (IoU 0.6);
  // the list order (score) must not matter.
  const std::vector<DetectedPerson> people = {Person(130, 100, 170, 180, 0.9),
                                              Person(110, 100, 150, 180, 0.3)};
  EXPECT_EQ(ChoosePerson(people, kLast, options)->box.x0_px, 110);
}

TEST(ChoosePerson, WithoutOverlapTakesTheNearestCentreWithinOneDiagonal) {
  PersonTrackerOptions options;
  // Both disjoint from the last box; centres 60 px and 200 px from its
  // centre (120, 140): the near one is within one diagonal (89.4 px).
  const std::vector<DetectedPerson> people = {Person(300, 100, 340, 180, 0.9),
                                              Person(160, 100, 200, 180, 0.3)};
  const std::optional<DetectedPerson> chosen =
      ChoosePerson(people, kLast, options);
  ASSERT_TRUE(chosen);
  EXPECT_EQ(chosen->box.x0_px, 160);
}

TEST(ChoosePerson, RefusesADetectionTooFarFromWhereThePersonWasLost) {
  PersonTrackerOptions options;
  // 100 px away (> 89.4 px) and disjoint: someone else.
  const std::vector<DetectedPerson> people = {Person(200, 100, 240, 180)};
  EXPECT_FALSE(ChoosePerson(people, kLast, options));
  options.reacquire_max_centre_diagonals = 1.5;  // a looser rule takes them
  EXPECT_TRUE(ChoosePerson(people, kLast, options));
  EXPECT_FALSE(ChoosePerson({}, kLast, options));
}

TEST(ChoosePerson, ASmallOverlapBelowTheIouLimitNeedsTheDistanceRule) {
  PersonTrackerOptions options;
  options.reacquire_max_centre_diagonals = 0.1;  // distance rule off here
  // Overlap 5 x 80 px: IoU 400 / 6000 = 0.067 < 0.1.
  const std::vector<DetectedPerson> slight = {Person(135, 100, 175, 180)};
  EXPECT_FALSE(ChoosePerson(slight, kLast, options));
  options.reacquire_min_iou = 0.05;
  EXPECT_TRUE(ChoosePerson(slight, kLast, options));
}

TEST(PersonTrackerOptions, ValidateNamesTheBadSetting) {
  PersonTrackerOptions options;
  options.region_scale = 0.5;
  EXPECT_THROW(options.Validate(), ConfigError);
  options = PersonTrackerOptions();
  options.person_index = -1;
  EXPECT_THROW(options.Validate(), ConfigError);
}

}  // namespace
}  // namespace m2d
