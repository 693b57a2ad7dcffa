// The ORB feature front end and place index (features/orb_front_end.hpp, orb_place_index.hpp) on
// real 7-Scenes frames with their ground-truth poses and on two rendered views of the synthetic
// building: the feature alignment against the true relative motion, places recognised by
// appearance, errors on bad input, and use from several threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <numbers>
#include <span>
#include <thread>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/features/orb_front_end.hpp"
#include "kartograf/features/orb_place_index.hpp"
#include "kartograf/formats/sequence.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "rgbd_test_sequence.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using features::OrbFrontEnd;
using features::OrbPlaceIndex;
using registration::FeatureDescription;

constexpr double kDegree = std::numbers::pi / 180.0;

const io::Sequence& kitchen() {
  static const auto sequence = io::open_seven_scenes(testing::data_dir() / "7scenes_redkitchen");
  return *sequence;
}

// 7-Scenes' colour images are not registered to depth: the colour camera's focal length is ~525
// against the depth camera's 585 (orb_front_end.hpp).
features::OrbParams kitchen_params() {
  features::OrbParams params;
  params.color_to_depth_focal = 525.0 / 585.0;
  return params;
}

std::shared_ptr<const FeatureDescription> describe_kitchen(const OrbFrontEnd& orb, std::size_t i) {
  const io::RgbdFrame frame = kitchen().frame(i);
  return orb.describe(frame.depth, frame.color, kitchen().intrinsics(),
                      kitchen().depth_units_per_metre());
}

// The true motion from frame a's camera to frame b's (the poses are camera-to-world).
Eigen::Isometry3d true_motion(std::size_t a, std::size_t b) {
  return kitchen().frame(b).pose->inverse() * *kitchen().frame(a).pose;
}

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

struct MotionError {
  double translation_m = 0;
  double rotation_deg = 0;
};

MotionError error_of(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  const Eigen::Isometry3d delta = truth.inverse() * estimate;
  return {delta.translation().norm(), Eigen::AngleAxisd(delta.linear()).angle() / kDegree};
}

// Pairs 25 frames (~0.8 s of hand-held motion, 4-30 cm and 2-13 degrees) apart across the
// recording. Measured (11 pairs): median error 1.5 cm / 0.86 deg, worst 5.5 cm / 2.6 deg
// (100 -> 125); bounds 3 cm / 1.5 deg on the median, 8 cm / 3.5 deg on the worst. The
// floor is the data's: 7-Scenes' colour is neither registered nor synchronised to depth, and the
// inliers' 3-D RMSE is 13-22 mm.
TEST(OrbFrontEnd, AlignsSevenScenesFramesAFewDozenApart) {
  const OrbFrontEnd orb(kitchen_params());
  std::vector<double> translation_errors, rotation_errors;
  for (std::size_t a = 0; a + 25 < 300; a += 25) {
    const std::size_t b = a + 25;
    SCOPED_TRACE(std::to_string(a) + " -> " + std::to_string(b));
    const auto source = describe_kitchen(orb, a), target = describe_kitchen(orb, b);
    const auto alignment = orb.align(*source, *target);
    ASSERT_TRUE(alignment.has_value());
    const Eigen::Isometry3d truth = true_motion(a, b);
    const MotionError e = error_of(alignment->source_to_target, truth);
    std::cout << "  7-Scenes " << a << " -> " << b << ": keypoints " << source->size() << " / "
              << target->size() << ", matches " << alignment->matches << ", inliers "
              << alignment->inliers << ", rmse " << alignment->inlier_rmse_m * 1000
              << " mm, true motion " << truth.translation().norm() * 100 << " cm "
              << Eigen::AngleAxisd(truth.linear()).angle() / kDegree << " deg, error "
              << e.translation_m * 100 << " cm " << e.rotation_deg << " deg\n";
    EXPECT_GE(alignment->inliers, 15u);
    EXPECT_LE(alignment->inliers, alignment->matches);
    translation_errors.push_back(e.translation_m);
    rotation_errors.push_back(e.rotation_deg);
  }
  EXPECT_LT(median(translation_errors), 0.03);
  EXPECT_LT(median(rotation_errors), 1.5);
  EXPECT_LT(*std::max_element(translation_errors.begin(), translation_errors.end()), 0.08);
  EXPECT_LT(*std::max_element(rotation_errors.begin(), rotation_errors.end()), 3.5);
}

// The robot tour's furnished room (frame 410 of 500, as in slam_test), seen again from 30 cm back
// and turned 15 degrees, at 640x480. The synthetic world's procedural textures are smooth: with
// OpenCV's FAST threshold of 20, ORB finds 13-25 corners with depth per 320x240 view and 43-49 per
// 640x480 one, too few to agree on a motion; a threshold of 5 finds ~270-350 at 640x480, and
// measured the error is 1.6 cm / 0.41 deg (50 of 65 matches inliers; 2.6 cm / 0.66 deg with the
// same pairs in another order: a consensus of 50 noisy pairs).
TEST(OrbFrontEnd, AlignsTwoRenderedViewsOfTheSyntheticBuilding) {
  const Trajectory tour = synth::robot_tour(testing::test_world(), 500);
  const Eigen::Isometry3d first = tour[410].pose;
  Eigen::Isometry3d second = first;
  const Eigen::Vector3d forward = first.linear() * Eigen::Vector3d::UnitZ();
  second.translation() -= 0.3 * forward;
  second.linear() = Eigen::AngleAxisd(15 * kDegree, Eigen::Vector3d::UnitZ()) * first.linear();
  const testing::RenderedSequence views = testing::render_sequence(
      {first, second}, PinholeIntrinsics{640, 480, 525.0, 525.0, 319.5, 239.5});
  features::OrbParams params;
  params.fast_threshold = 5;
  const OrbFrontEnd orb(params);
  const auto a = orb.describe(views.frames[0].depth, views.frames[0].color, views.camera,
                              testing::kSynthUnitsPerMetre);
  const auto b = orb.describe(views.frames[1].depth, views.frames[1].color, views.camera,
                              testing::kSynthUnitsPerMetre);
  const auto alignment = orb.align(*a, *b);
  ASSERT_TRUE(alignment.has_value()) << "keypoints " << a->size() << " / " << b->size();
  const MotionError e = error_of(alignment->source_to_target, second.inverse() * first);
  std::cout << "  synthetic: keypoints " << a->size() << " / " << b->size() << ", matches "
            << alignment->matches << ", inliers " << alignment->inliers << ", error "
            << e.translation_m * 100 << " cm " << e.rotation_deg << " deg\n";
  EXPECT_LT(e.translation_m, 0.04);
  EXPECT_LT(e.rotation_deg, 1.5);
}

// Ten places 30 frames apart (frames 0, 30, ..., 270), ids = frame numbers.
struct KitchenPlaces {
  OrbFrontEnd orb{kitchen_params()};
  OrbPlaceIndex index;
  std::vector<std::shared_ptr<const FeatureDescription>> added;
  KitchenPlaces() {
    for (std::size_t frame = 0; frame < 300; frame += 30) {
      added.push_back(describe_kitchen(orb, frame));
      index.add(frame, *added.back());
    }
  }
};

const KitchenPlaces& kitchen_places() {
  static const KitchenPlaces places;
  return places;
}

TEST(OrbPlaceIndex, RecognisesTheNearestPlaceFirst) {
  const KitchenPlaces& places = kitchen_places();
  ASSERT_EQ(places.index.places(), 10u);
  for (const std::size_t query_frame : {95u, 184u, 262u}) {
    SCOPED_TRACE(query_frame);
    const auto query = describe_kitchen(places.orb, query_frame);
    const auto matches = places.index.query(*query, 1000, 5);
    ASSERT_FALSE(matches.empty());
    std::cout << "  place query " << query_frame << ":";
    for (const auto& m : matches) std::cout << " " << m.place << " (" << m.score << ")";
    std::cout << "\n";
    const std::size_t nearest = (query_frame + 15) / 30 * 30;
    EXPECT_EQ(matches.front().place, nearest);
    EXPECT_LE(matches.size(), 5u);
    for (std::size_t k = 1; k < matches.size(); ++k)
      EXPECT_GE(matches[k - 1].score, matches[k].score);
  }
}

// The votes of a query's reported matches among `places`, summed.
double votes_among(const std::vector<registration::PlaceMatch>& matches,
                   std::initializer_list<std::size_t> places) {
  double sum = 0;
  for (const auto& m : matches)
    if (std::find(places.begin(), places.end(), m.place) != places.end()) sum += m.score;
  return sum;
}

// Keyframes follow each other closely where the camera moves: consecutive ones share most corners.
// A query of that place must not lose its votes to the ratio test against those neighbours (with
// every other place a rival, as before same_place_span, they cancel each other's votes): the four
// keyframes together collect at least what the place alone did.
TEST(OrbPlaceIndex, APlaceSeenByConsecutiveKeyframesKeepsItsVotes) {
  const KitchenPlaces& sparse = kitchen_places();
  const auto query = describe_kitchen(sparse.orb, 95);
  const double alone = votes_among(sparse.index.query(*query, 1000, 10), {90});
  const auto dense_votes = [&](std::size_t span) {
    features::OrbPlaceParams params;
    params.same_place_span = span;
    OrbPlaceIndex dense(params);
    for (std::size_t frame = 0; frame < 300; frame += 30) {
      dense.add(frame, *sparse.added[frame / 30]);
      if (frame != 90) continue;
      for (const std::size_t next : {92u, 94u, 97u})
        dense.add(next, *describe_kitchen(sparse.orb, next));
    }
    return votes_among(dense.query(*query, 1000, 10), {90, 92, 94, 97});
  };
  const double kept = dense_votes(features::OrbPlaceParams{}.same_place_span);
  const double cancelled = dense_votes(0);
  std::cout << "  place 90 alone: " << alone << " votes; seen from frames 90-97: " << kept
            << " (with every other place a rival: " << cancelled << ")\n";
  // Measured: 192 alone, 272 over the four keyframes (134 with every other place a rival).
  EXPECT_GE(kept, alone);
  EXPECT_GT(kept, 1.5 * cancelled);
}

TEST(OrbPlaceIndex, BeforeExcludesLaterPlaces) {
  const KitchenPlaces& places = kitchen_places();
  const auto query = describe_kitchen(places.orb, 95);
  const auto matches = places.index.query(*query, 90, 10);
  for (const auto& m : matches) EXPECT_LT(m.place, 90u);
  EXPECT_TRUE(places.index.query(*query, 0, 10).empty());
}

TEST(OrbPlaceIndex, IdsMustIncrease) {
  OrbPlaceIndex index;
  const auto features = kitchen_places().added[0];
  index.add(5, *features);
  EXPECT_ERROR_MENTIONS(index.add(5, *features), "place 5 added after place 5", "increase");
}

TEST(OrbFrontEnd, BadInputIsAnErrorNamingTheProblem) {
  const OrbFrontEnd orb;
  const PinholeIntrinsics camera = PinholeIntrinsics::kinect_7scenes();
  const DepthImage depth(640, 480, std::uint16_t{1000});
  EXPECT_ERROR_MENTIONS(orb.describe(depth, RgbImage(320, 240), camera, 1000.0), "colour image",
                        "320x240", "640x480");
  EXPECT_ERROR_MENTIONS(orb.describe(DepthImage(320, 240), RgbImage(320, 240), camera, 1000.0),
                        "depth image", "320x240", "camera", "640x480");
  EXPECT_ERROR_MENTIONS(orb.describe(depth, RgbImage(), camera, 1000.0), "colour image is empty");
  EXPECT_ERROR_MENTIONS(orb.describe(depth, RgbImage(640, 480), camera, 0.0), "units per metre");
  struct Foreign final : FeatureDescription {
    std::size_t size() const override { return 0; }
    std::size_t memory_bytes() const override { return 0; }
  };
  EXPECT_ERROR_MENTIONS(orb.align(Foreign{}, Foreign{}), "not described by an ORB front end");
  EXPECT_ERROR_MENTIONS(orb.serialize(Foreign{}), "not described by an ORB front end");
  features::OrbParams bad;
  bad.ratio = 1.5;
  EXPECT_ERROR_MENTIONS(OrbFrontEnd{bad}, "ratio");
}

TEST(OrbFrontEnd, ADescriptionReadBackFromBytesAlignsAsTheOriginal) {
  const OrbFrontEnd orb;
  const auto source = describe_kitchen(orb, 100), target = describe_kitchen(orb, 125);
  const std::vector<std::uint8_t> bytes = orb.serialize(*source);
  const auto copy = orb.deserialize(bytes);
  ASSERT_EQ(copy->size(), source->size());
  EXPECT_EQ(copy->memory_bytes(), source->memory_bytes());
  EXPECT_EQ(orb.serialize(*copy), bytes);
  const auto expected = orb.align(*source, *target), again = orb.align(*copy, *target);
  ASSERT_TRUE(expected.has_value() && again.has_value());
  EXPECT_TRUE(again->source_to_target.matrix() == expected->source_to_target.matrix());
  EXPECT_EQ(again->inliers, expected->inliers);
  const auto blank =
      orb.describe(DepthImage(640, 480, std::uint16_t{1500}), RgbImage(640, 480, Rgb8{90, 90, 90}),
                   PinholeIntrinsics::kinect_7scenes(), 1000.0);
  EXPECT_EQ(orb.deserialize(orb.serialize(*blank))->size(), 0u);
}

TEST(OrbFrontEnd, BytesThatAreNotADescriptionAreAnError) {
  const OrbFrontEnd orb;
  std::vector<std::uint8_t> bytes = orb.serialize(*describe_kitchen(orb, 100));
  const std::span<const std::uint8_t> all(bytes);
  EXPECT_ERROR_MENTIONS(orb.deserialize(all.first(2)), "truncated");
  EXPECT_ERROR_MENTIONS(orb.deserialize(all.first(all.size() - 1)), "length");
  std::vector<std::uint8_t> longer = bytes;
  longer.push_back(0);
  EXPECT_ERROR_MENTIONS(orb.deserialize(longer), "length");
  std::vector<std::uint8_t> nan_point = bytes;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // The first point's x, after the tag, the count and the descriptors.
  const std::size_t count = orb.deserialize(bytes)->size();
  std::memcpy(nan_point.data() + 12 + 32 * count, &nan, sizeof nan);
  EXPECT_ERROR_MENTIONS(orb.deserialize(nan_point), "non-finite");
  bytes[0] ^= 0xff;
  EXPECT_ERROR_MENTIONS(orb.deserialize(bytes), "not an ORB description");
}

TEST(OrbFrontEnd, BlankImagesGiveNoAlignment) {
  // No texture, no corners: nothing to match, and align() says so instead of guessing.
  const OrbFrontEnd orb;
  const PinholeIntrinsics camera = PinholeIntrinsics::kinect_7scenes();
  const auto blank = orb.describe(DepthImage(640, 480, std::uint16_t{1500}),
                                  RgbImage(640, 480, Rgb8{90, 90, 90}), camera, 1000.0);
  EXPECT_EQ(blank->size(), 0u);
  EXPECT_FALSE(orb.align(*blank, *blank).has_value());
  const auto textured = describe_kitchen(orb, 0);
  EXPECT_FALSE(orb.align(*blank, *textured).has_value());
  EXPECT_TRUE(kitchen_places().index.query(*blank, 1000, 5).empty());
}

TEST(OrbFrontEnd, SharedAcrossThreadsGivesTheSameAnswers) {
  const OrbFrontEnd orb;
  const auto source = describe_kitchen(orb, 100), target = describe_kitchen(orb, 125);
  const auto expected = orb.align(*source, *target);
  ASSERT_TRUE(expected.has_value());
  const io::RgbdFrame frame = kitchen().frame(100);
  std::vector<Eigen::Matrix4d> aligned(4);
  std::vector<std::size_t> sizes(4);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      sizes[t] = orb.describe(frame.depth, frame.color, kitchen().intrinsics(), 1000.0)->size();
      aligned[t] = orb.align(*source, *target)->source_to_target.matrix();
    });
  for (auto& thread : threads) thread.join();
  for (std::size_t t = 0; t < 4; ++t) {
    EXPECT_EQ(sizes[t], source->size());
    EXPECT_TRUE(aligned[t] == expected->source_to_target.matrix());
  }
}

// Not a check: describe() and align() per 640x480 frame, printed (run with
// OPENCV_FOR_THREADS_NUM=1 for one thread).
TEST(OrbFrontEnd, TimingOnSevenScenes) {
  const OrbFrontEnd orb(kitchen_params());
  std::vector<io::RgbdFrame> frames;
  for (std::size_t i = 0; i < 10; ++i) frames.push_back(kitchen().frame(100 + 5 * i));
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  std::vector<std::shared_ptr<const FeatureDescription>> described;
  for (const auto& f : frames)
    described.push_back(orb.describe(f.depth, f.color, kitchen().intrinsics(), 1000.0));
  const auto t1 = Clock::now();
  std::size_t inliers = 0, matches = 0;
  for (std::size_t i = 1; i < described.size(); ++i)
    if (const auto a = orb.align(*described[i - 1], *described[i])) {
      inliers += a->inliers;
      matches += a->matches;
    }
  const auto t2 = Clock::now();
  const double describe_ms = std::chrono::duration<double, std::milli>(t1 - t0).count() / 10;
  const double align_ms = std::chrono::duration<double, std::milli>(t2 - t1).count() / 9;
  std::cout << "  describe " << describe_ms << " ms/frame, align " << align_ms
            << " ms/pair (5 frames apart: " << matches / 9 << " matches, " << inliers / 9
            << " inliers on average)\n";
  RecordProperty("describe_ms", std::to_string(describe_ms));
  RecordProperty("align_ms", std::to_string(align_ms));
}

}  // namespace
}  // namespace kartograf
