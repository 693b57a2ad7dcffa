// Local features in the odometry and the loop closure (registration::FeatureFrontEnd with the
// features layer's OrbFrontEnd): frames 26-37 cm apart, beyond dense ICP's basin,
// are tracked from the matched features' motion; a loop the pose estimate no longer shows (drifted
// by 40 cm and 70 degrees) is found by appearance and verified. Synthetic 640x480 frames: at lower
// resolutions the world's smooth textures give too few corners.
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include "kartograf/features/orb_front_end.hpp"
#include "kartograf/mapping/loop_closure.hpp"
#include "kartograf/outputs/synthetic_dataset.hpp"
#include "kartograf/pipeline/map_pipeline.hpp"
#include "kartograf/registration/odometry.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "kartograf/synth/world.hpp"
#include "rgbd_test_sequence.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

const PinholeIntrinsics kKinect{640, 480, 525, 525, 319.5, 239.5};

std::shared_ptr<const features::OrbFrontEnd> orb() {
  features::OrbParams params;
  params.fast_threshold = 5;  // the synthetic world's textures are smooth
  return std::make_shared<const features::OrbFrontEnd>(params);
}

// Every 8th frame of the default tour along a furnished room: 37, 31 and 26 cm and 7-9 degrees
// apart. (The next steps turn by 20 degrees where the motion model predicts 7: ICP from that
// prediction is accepted 1-6 cm wrong, features or not; an open limit of the acceptance checks.)
const testing::RenderedSequence& wide_steps() {
  static const testing::RenderedSequence sequence = [] {
    const Trajectory tour = synth::robot_tour(testing::test_world(), 500);
    std::vector<Eigen::Isometry3d> poses;
    for (std::size_t i = 392; i <= 416; i += 8) poses.push_back(tour[i].pose);
    return testing::render_sequence(poses, kKinect);
  }();
  return sequence;
}

struct StepErrors {
  double worst_m = 0, worst_deg = 0;
  std::size_t from_features = 0, fallbacks = 0;
};

// The worst errors are those of the steps into frames first_step onwards.
StepErrors track(const testing::RenderedSequence& sequence,
                 std::shared_ptr<const features::OrbFrontEnd> front_end,
                 registration::OdometryParams params = {}, std::size_t first_step = 1) {
  params.depth_range.units_per_metre = testing::kSynthUnitsPerMetre;
  params.features = std::move(front_end);
  const compute::Context context = compute::Context::cpu();
  registration::RgbdOdometry odometry(context, sequence.camera, params);
  StepErrors errors;
  for (const auto& frame : sequence.frames) {
    const registration::OdometryFrame& tracked = odometry.track(frame.depth, &frame.color);
    errors.from_features += tracked.from_features;
    errors.fallbacks += tracked.fallback;
  }
  const auto& poses = odometry.poses();
  for (std::size_t i = std::max<std::size_t>(first_step, 1); i < poses.size(); ++i) {
    const Eigen::Isometry3d truth = sequence.truth[i - 1].inverse() * sequence.truth[i];
    const Eigen::Isometry3d error = truth.inverse() * (poses[i - 1].inverse() * poses[i]);
    errors.worst_m = std::max(errors.worst_m, error.translation().norm());
    errors.worst_deg = std::max(errors.worst_deg, se3::rotation_angle(error) / kDegree);
  }
  return errors;
}

TEST(FeatureTracking, OdometryFollowsStepsBeyondIcpsBasin) {
  const StepErrors with = track(wide_steps(), orb());
  EXPECT_GE(with.from_features, 1u);
  EXPECT_EQ(with.fallbacks, 0u);
  EXPECT_LT(with.worst_m, 0.01);  // measured: 4.3 mm, 0.12 degrees
  EXPECT_LT(with.worst_deg, 0.5);
  RecordProperty("worst_step_error_m", testing::scientific(with.worst_m));
  // Without features the same steps are lost or wrong.
  const StepErrors without = track(wide_steps(), nullptr);
  EXPECT_TRUE(without.fallbacks > 0 || without.worst_m > 0.05 || without.worst_deg > 3)
      << without.worst_m << " m, " << without.worst_deg << " deg";
}

// `count` frames of a survey (the demo's recipe; seed 1 unless `seed`) taken every 10th frame
// from `first`, with the tests' noise seeds or, `as_synth_writes`, those `kartograf synth` writes
// the frames with.
testing::RenderedSequence every_10th_survey_frame(std::size_t first, std::size_t count,
                                                  unsigned seed = 1, bool as_synth_writes = false) {
  const synth::World world = synth::make_building(seed);
  const std::vector<Eigen::Isometry3d> poses = testing::survey_poses(world, first, count, 10);
  if (!as_synth_writes) return testing::render_sequence(world, poses, kKinect);
  std::vector<std::uint64_t> noise_seeds;
  for (std::size_t i = 0; i < count; ++i) {
    noise_seeds.push_back(io::synthetic_frame_seed(seed, first + 10 * i));
  }
  return testing::render_sequence(world, poses, kKinect, noise_seeds);
}

// The start of the seed-1 survey taken every 10th frame: the robot sets off from rest at 20, 39
// and 58 cm per frame facing a wall over the floor, which leaves the forward slide free. The motion
// model (standing still) decides that slide and ICP agrees; the matched features see the step,
// and the images agree better with them.
const testing::RenderedSequence& survey_start() {
  static const testing::RenderedSequence sequence = every_10th_survey_frame(0, 4);
  return sequence;
}

TEST(FeatureTracking, ADegenerateStartIsMeasuredByTheFeaturesTheImagesAgreeWith) {
  const StepErrors with = track(survey_start(), orb());
  RecordProperty("worst_step_error_m", testing::scientific(with.worst_m));
  EXPECT_GE(with.from_features, 1u);
  EXPECT_LT(with.worst_m, 0.05);
  // Without the features, and without the scan along the free line (which finds the steps too:
  // 1.0 cm).
  registration::OdometryParams without_scan;
  without_scan.free_translation_scan = false;
  const StepErrors without = track(survey_start(), nullptr, without_scan);
  RecordProperty("worst_step_error_without_m", testing::scientific(without.worst_m));
  EXPECT_GT(without.worst_m, 0.15);
}

// The seed-1 survey every 10th frame, frames 790-830: the robot turns on the spot, 39 degrees per
// frame, facing plain walls over a tiled floor. At frame 810 the matched features agree on a
// wrong motion (the tiles repeat, the walls have no corners) and ICP from it is accepted 13 cm and
// 4.4 degrees off (fitness 0.17); ICP from the prediction (the last turn again) is right, and the
// images agree with it better (grey-level RMSE 2.2 against 15).
const testing::RenderedSequence& turn_on_the_spot() {
  static const testing::RenderedSequence sequence = every_10th_survey_frame(790, 5);
  return sequence;
}

TEST(FeatureTracking, ALargeMotionFollowsTheFeaturesOnlyWhereThePairAgreesBetter) {
  const StepErrors weighed = track(turn_on_the_spot(), orb());
  RecordProperty("worst_step_error_m", testing::scientific(weighed.worst_m));
  EXPECT_LT(weighed.worst_m, 0.02);  // measured 9.0 mm, 0.03 degrees
  EXPECT_LT(weighed.worst_deg, 0.5);
  registration::OdometryParams features_first;
  features_first.feature_arbitration_ratio = 1e-9;  // the images never side with the prediction
  const StepErrors misled = track(turn_on_the_spot(), orb(), features_first);
  RecordProperty("worst_step_error_features_first_m", testing::scientific(misled.worst_m));
  EXPECT_GT(misled.worst_m, 0.05);  // measured 13 cm, 4.4 degrees
}

// One behaviour of the odometry, switched off, on a stretch of a survey (seed 1 unless `seed`)
// taken every 10th frame from `first` (`count` frames): the worst step error from `first_step` on
// must be under `with_below_m` with it and over `without_above_m` without; where
// `without_above_deg` is set, the worst turn error too (a turn missed on the spot barely moves the
// camera).
struct Counterfactual {
  const char* name;
  std::size_t first, count, first_step;
  void (*switch_off)(registration::OdometryParams&);
  double with_below_m, without_above_m;
  unsigned seed = 1;  // of the survey
  double with_below_deg = 0, without_above_deg = 0;
  // The frames' noise as `kartograf synth` writes them, and the features of `kartograf slam
  // --features` (pipeline::map_orb_params).
  bool as_the_cli_runs = false;
};

const Counterfactual kCounterfactuals[] = {
    // Frames 860-1110: the robot drives at up to 0.67 m a frame, stops, turns on the spot, and
    // sets off again (0.11, 0.30, 0.50, 0.69 m a frame). At frame 1100 the prediction is still the
    // last step's 0.30 m; the truth, 0.50 m, was reached from another start at the best fitness
    // but refused: 0.38 m from the prediction, beyond the frame limits' 0.3 m. The limit now
    // reaches the largest step measured so far (0.8 mm against 0.39 m with the fixed limit).
    // Tracked from frame 700: from 860 the heading prior has not learned enough steps by frame
    // 1100 to start ICP on the turn's arc, and which of the other starts lands on the robot's
    // step there hung on fractions of a millimetre in the turns before (0.37 m off once those
    // turns were judged on what the frames share). The features' motion, kept over misfit
    // images (features_over_misfit_images), mends the step without the limit too, to 4.7 cm:
    // both are switched off.
    {"ARobotSettingOffIsNotRefusedForItsSpeed", 700, 42, 40,
     [](registration::OdometryParams& p) {
       p.corrections_up_to_largest_step = false;
       p.features_over_misfit_images = false;
     },
     0.01, 0.2},
    // Frames 200-270: the robot sets off from a turn on the spot and speeds up by up to 0.2 m a
    // frame to 0.87 m a frame, along a checkered floor towards a wall beyond the depth range,
    // which leaves the forward slide free. At frame 270 (0.98 m) the matched features and the
    // images take the floor two tiles over, a step of 0.26 m: a change of speed the robot cannot
    // have made, so the registration from the prediction wins (without the bound: 0.71 m off).
    {"AStepTheRobotCannotHaveMadeLosesToOneItCan", 200, 8, 7,
     [](registration::OdometryParams& p) { p.speed_change_margin = 0; }, 0.01, 0.5},
    // The same step: from the prediction (0.82 m) the images stay 0.11 m short; they fit only
    // within 2 cm of the truth. Scanned 1 cm apart over the lengths the robot can have made, they
    // fit best at its step.
    {"ARobotAtSpeedIsFoundAlongItsStep", 200, 8, 7,
     [](registration::OdometryParams& p) { p.step_scan = false; }, 0.01, 0.1},
    // Frames 0-50: the robot speeds up by 0.18 m a frame, facing a striped wall over a wooden
    // floor too far ahead to constrain the forward slide. The velocity model lags 0.18 m behind,
    // and the images, started there, stay; from the step changed as it last changed, or scanned
    // along the step, they find the robot's (into frame 30: 13 mm against 18 cm without both).
    // The scan along the free line finds it too (5 mm): off as well.
    {"ARobotSpeedingUpInADegenerateViewIsFollowed", 0, 6, 3,
     [](registration::OdometryParams& p) {
       p.acceleration_start = false;
       p.step_scan = false;
       p.free_translation_scan = false;
     },
     0.05, 0.15},
    // Frames 900-990: turning on the spot (39 degrees a frame) into frames 980 and 990, ICP from
    // the features' motion and from the prediction end within 5 cm and 2 degrees of each other,
    // the features' with a slide; the images fit the prediction's better. On these rendered frames
    // the steps are 6.4 mm off against 11.9 mm; on the tour's files (`kartograf synth`), 6 mm
    // against 3 cm at frame 980 (RMSE 2.5 against 7.9). The scan along the free line, which
    // also finds it (5.8 mm), is off as well.
    {"ATieWithTheFeaturesIsDecidedByTheImages", 900, 10, 8,
     [](registration::OdometryParams& p) {
       p.feature_ties_by_images = false;
       p.free_translation_scan = false;
     },
     0.009, 0.0105},
    // Seed 8's survey, frames 0-50: the robot speeds up by 0.18 m a frame along a corridor whose
    // floor pattern repeats about a step ahead; into frame 40 (0.73 m) the features take it for
    // standing still and the images agree better with that than with the acceleration start's
    // right step. The steps the images measured before (0.19, 0.37, 0.55 m) set the speed bound.
    {"ASpeedTheImagesMeasuredBoundsTheNextStep", 0, 6, 4,
     [](registration::OdometryParams& p) { p.speed_bound_learns_from_images = false; }, 0.05, 0.3,
     8},
    // Turns ICP took with a slide at its best fitness. Frames 900-980: the robot stops and turns
    // on the spot, 35-39 degrees a frame, with a 14 cm slide into 970. Frames 860-1100: it sets
    // off on a turn, 0.30 m and 12.5 degrees into 1090 from a predicted 0.11 m, with a 24 cm slide
    // sideways (tracked from frame 700, as above). From the turn found, on the spot and along the
    // heading's arc, ICP finds the robot's steps.
    // (The first one with the wide turns judged on what the frames share off as well: that rule
    // mends the stretch on its own, to 2.2 cm.)
    {"ATurnIsTriedAgainOnTheSpot", 900, 9, 7,
     [](registration::OdometryParams& p) {
       p.recheck_from_turn = false;
       p.overlap_turn_deg = 0;
     },
     0.02, 0.1},
    {"ASetOffOnATurnIsTriedAgainAlongTheHeading", 700, 41, 39,
     [](registration::OdometryParams& p) { p.recheck_from_turn = false; }, 0.02, 0.1},
    // Seed 4's survey, frames 250-330: the robot turns on the spot, 36-39 degrees a frame, over
    // the floor, which no turn about the vertical moves. Into frame 300 ICP from rest overlaps more
    // than from the right turn (fitness 0.46 against 0.29) and won at the best fitness; the
    // images fit the turn (grey-level RMSE 2.0 against 40), and decide. A turn missed on the spot
    // leaves the position right: the turn's error is checked.
    {"ATurnOnTheSpotIsNotTakenForRestAtABetterFitness", 250, 9, 5,
     [](registration::OdometryParams& p) { p.recheck_by_images = false; }, 0.02, 0, 4, 1, 10},
    // Seed 4's survey, frames 600-920 (from a shorter stretch the prediction is right): into
    // frame 920 the robot turns on the spot by 36 degrees where 22 were predicted; ICP from the
    // prediction finds the turn with a 52 cm slide (fitness 0.42, RMSE 9.5), from the turn on the
    // spot with none (0.36, RMSE 1.2). The prediction's answer had beaten the features', so the
    // other starts were not tried before.
    {"ATurnWithASlideLosesToTheTurnTheImagesFit", 600, 33, 31,
     [](registration::OdometryParams& p) {
       p.recheck_by_images = false;
       p.recheck_after_features = false;
     },
     0.02, 0.1, 4},
    // Seed 2's survey, frames 880-920: the robot turns on the spot, 37-39 degrees a frame. Into
    // frame 910 ICP slid along a wall (5.1 cm here, 5.8 cm on the tour's files): the whole frame
    // measures every direction (balanced eigenvalue ratio 0.058), but the part frame 900 sees is a
    // wall over the floor (0.0004), along which every point is a fixed point of ICP. Judged on
    // that part, the step is registered as a degenerate view's, its slide held by the motion
    // prior (0.4 mm).
    {"AWideTurnIsJudgedOnWhatTheFramesShare", 880, 5, 3,
     [](registration::OdometryParams& p) { p.overlap_turn_deg = 0; }, 0.02, 0.04, 2},
    // Seed 2's survey, frames 100-420 as `kartograf synth` writes them and with the map's
    // features (the case hangs on both, and on the steps before: from frame 200 on, or with the
    // other tests' frames, the tie does not arise): the robot speeds up along a corridor, 0.50,
    // 0.68 and 0.91 m a frame into frame 400, over a floor whose tiles repeat along the step, in
    // a view that leaves the forward slide free. ICP from the prediction finds the robot's step,
    // ICP from the features' motion a tile short (0.26 m); the images, refined at both, fit them
    // alike (grey-level RMSE 16.6 and 15.7) and the speed bound admits both. The features' was
    // taken on that tie, and the next step followed it (0.65 m short twice; 3.7 mm with the
    // prediction kept). The features' turn on its arc at the length changed as it last changed
    // mends it too (3.6 mm): off as well.
    {"AnImagesTieOnADriveKeepsThePrediction", 100, 33, 29,
     [](registration::OdometryParams& p) {
       p.prediction_keeps_image_ties = false;
       p.acceleration_on_the_arc = false;
     },
     0.05, 0.3, 2, 0, 0, true},
    // Seed 5's survey, frames 150-300 as `kartograf synth` writes them and with the map's
    // features: the robot stops and turns on the spot, 38.8 degrees a frame from frame 240 on.
    // Into frame 290 ICP from the prediction finds the turn, but at a fitness of 0.26, so the
    // other starts are tried: one turned 14.2 degrees and slid 0.31 m fitted more pairs (0.32),
    // since a smaller turn overlaps more, and was taken. A third of its points lie where frame 280
    // saw past them; weighed by that, the turn wins (4.0 mm and 0.08 degrees against 0.31 m and
    // 24.5 degrees). The steps from frame 250 count (frame 240: the next case). With every start
    // held on its overlap off as well: that rule alone mends frame 290 too (4.0 mm).
    {"AWideTurnIsNotShrunkForMoreOverlap", 150, 16, 10,
     [](registration::OdometryParams& p) {
       p.fitness_weighed_by_view = false;
       p.overlap_every_start = false;
     },
     0.02, 0.2, 5, 1, 10, true},
    // The same stretch into frame 240, where the turn on the spot speeds up from 25.7 to 38.8
    // degrees a frame: ICP from the prediction finds the turn 1.7 degrees short but slid 0.33 m
    // along a wall, and another start's 18.2 degrees and 0.55 m won; the part the two frames
    // share under the first answer is degenerate, under the winner's not, and only the winner
    // was judged on it. Each start's answer held on its own overlap, the prediction's, registered
    // again as a degenerate view, keeps the turn without the slide.
    {"AWideTurnIsHeldOnItsOverlapFromEveryStart", 150, 11, 9,
     [](registration::OdometryParams& p) { p.overlap_every_start = false; }, 0.02, 0.2, 5, 1, 10,
     true},
    // Seed 4's survey, frames 100-410 as `kartograf synth` writes them and with the map's
    // features (from frame 200 on the case does not arise): the robot turns on the spot, then
    // sets off on an arc (0.11, 0.30, 0.49, 0.69 m a frame, turning 4-19 degrees) and drives
    // 0.88 m straight into frame 400. The turn predicted on, ICP from the prediction settled 12.2
    // degrees and 0.23 m off at a fitness of 0.38, above recheck_fitness, so no other start was
    // tried, and the next step followed it. Checked against the other starts, the straight step
    // wins.
    {"ALargeMotionIsCheckedAgainstTheOtherStarts", 100, 32, 30,
     [](registration::OdometryParams& p) { p.recheck_large_motions = false; }, 0.05, 0.15, 4, 1, 5,
     true},
    // Seed 3's survey, frames 0-200 as `kartograf synth` writes them and with the map's features:
    // the robot turns on the spot, 36 degrees a frame, towards a striped wall. Into frame 190 ICP
    // from the prediction finds the turn at a fitness of 0.29 (a grey-level RMSE of 13.8 there,
    // 6.9 once refined; the refinement is refused for its spread, on the 500 pixels the frames
    // share) and rest wins at 0.495 (RMSE 22.0 however refined). Judged after their refinement,
    // the images decide for the turn. A turn on the spot: the turn's error is checked. Rest's
    // answer also contradicts the view (contradiction_weight), which mends the step alone (0.08
    // degrees without the refined images): both are switched off.
    {"ATurnIsJudgedByItsImagesAfterTheirRefinement", 0, 21, 18,
     [](registration::OdometryParams& p) {
       p.recheck_images_refined = false;
       p.contradiction_weight = 0;
     },
     0.05, 0, 3, 1, 10, true},
    // Seed 8's survey, frames 0-70 as `kartograf synth` writes them and with the map's features:
    // the robot drives at 0.84-0.89 m a frame over a tiled floor, in a degenerate view, and sets
    // off on a turn, 26 degrees and 0.72 m into frame 60. The features found the
    // turn with a step of 0.42 m half sideways, which the speed bound refused, and ICP from the
    // prediction went straight on. From the features' turn with the predicted step along its arc
    // the turn is found; the step's length, which the view leaves free, stays the prediction's
    // (17 cm long: the robot slowed down), so the turn's error is checked.
    {"TheFeaturesTurnIsTriedOnItsArc", 0, 8, 5,
     [](registration::OdometryParams& p) { p.features_turn_on_the_arc = false; }, 0.2, 0.2, 8, 1,
     10, true},
    // Seed 2's survey, frames 0-190 as `kartograf synth` writes them and with the map's
    // features: the robot sets off from a turn on the spot, speeding up by 0.19 m a frame in
    // views of the floor alone, and turns 10, 33 and 27 degrees at 0.73, 0.85 and 0.70 m into
    // frames 170-190, speeding up, then slowing down. The features find the turns with steps a
    // tile or more short (0.02 and 0.22 m into 170 and 190), which the speed bound refuses, and
    // their turns on the arc at the velocity model's length (0.54 m, then 0.54 and 0.86 m) fit
    // no images: 0.19-0.52 m off. At the length changed as it last changed, or as much the other
    // way, the images fit the robot's steps.
    {"TheFeaturesTurnOnItsArcSpeedsUpOrSlowsDown", 0, 20, 17,
     [](registration::OdometryParams& p) { p.acceleration_on_the_arc = false; }, 0.05, 0.15, 2, 0,
     0, true},
    // Seed 7's survey, frames 0-60 as `kartograf synth` writes them and with the map's features:
    // the robot drives straight, 0.19-0.78 m a frame, then turns 22 degrees on an arc into frame
    // 50 in a view that leaves the sideways slide free. ICP found the turn and kept the straight
    // step's slide, 11 cm sideways, and the heading prior had learned too few steps to start on
    // the arc; from the predicted step's heading on the turn's arc, the step is found.
    {"TheArcStartsFromThePredictionBeforeTheHeadingIsLearned", 0, 7, 5,
     [](registration::OdometryParams& p) { p.arc_start_from_the_prediction = false; }, 0.03, 0.08,
     7, 0, 0, true},
    // Seed 2's survey, frames 0-180 as `kartograf synth` writes them and with the map's
    // features: the robot turns on the spot through a full turn, sets off (0.01, 0.15, 0.35, 0.54,
    // 0.73 m a frame, every view floor only) and turns 33 degrees at 0.85 m into frame 180. The
    // features found the turn with a step 0.35 m sideways, which the images fitted best (the
    // floor's tiles); the heading prior had learned no step yet. A step more across the drive
    // than along it is left for the features' turn on its arc: 0.31 m off against 1.03 m. (The
    // step's length, which the view leaves free, stays the prediction's, short.)
    {"TheFeaturesStepAcrossTheDriveIsLeft", 0, 19, 17,
     [](registration::OdometryParams& p) { p.features_along_the_drive = false; }, 0.5, 0.9, 2, 0, 0,
     true},
    // Seed 5's survey, frames 330-380 as `kartograf synth` writes them and with the map's
    // features: the robot speeds up on an arc (9, 17 and 22 degrees a frame) and drives straight
    // through a doorway into frame 380, at 0.82 m, towards a striped wall. The features find
    // nothing; from the predicted turn the wall lands beside its own points and ICP pairs the
    // floor alone (fitness 0.36), which keeps the 22 degree turn. From the predicted step without
    // its turn, ICP finds the straight step (fitness 0.48). The step's length, which the view
    // leaves free, stays the prediction's (0.63 m), so the turn's error is checked.
    {"ATurnThatEndsInADegenerateViewIsTriedStraight", 330, 6, 5,
     [](registration::OdometryParams& p) { p.straight_start_on_silent_images = false; }, 0.3, 0, 5,
     1, 10, true},
    // Seed 10's survey, frames 890-930 as `kartograf synth` writes them and with the map's
    // features: the robot sets off from rest on a 12 degree arc and then drives straight, 0.72 m
    // into frame 930, through a doorway towards a wall beyond the depth's range, over a floor
    // whose grain runs along the motion. The features find nothing; ICP from the prediction keeps
    // its 6.3 degree turn, which no depth measures. From the predicted step without its turn the
    // straight step is found; its length, which the view leaves free, stays short (0.52 m), so
    // the turn's error is checked.
    {"ASmallTurnThatEndsInADegenerateViewIsTriedStraight", 890, 5, 4,
     [](registration::OdometryParams& p) { p.straight_start_on_silent_images = false; }, 0.3, 0, 10,
     2, 4, true},
    // Seed 6's survey, frames 210-250 as `kartograf synth` writes them and with the map's
    // features: the robot sets off from a turn, 0.49 m and 2 degrees into frame 250 where 0.30 m
    // and 11.4 degrees were predicted, in a degenerate view. ICP from the features' motion ends
    // 2.3 cm and 1.9 degrees off, from the prediction at its turn; neither's images were refined
    // (grey-level RMSE 23.9 and 16.5), and the ratio of those misfits had kept the prediction's.
    {"MisfitImagesLeaveTheFeaturesTheirMotion", 210, 5, 4,
     [](registration::OdometryParams& p) { p.features_over_misfit_images = false; }, 0.05, 0.15, 6,
     3, 6, true},
    // Seed 5's survey, frames 0-400 as `kartograf synth` writes them and with the map's
    // features: the robot comes out of a turn through a doorway and speeds up straight, 0.82,
    // 0.98 and 0.85 m into frames 380-400, towards a striped wall beyond the depth's range over a
    // wooden floor: only the floor's texture measures the forward slide. The velocity model held
    // the last step's 0.58 m three times (0.25-0.39 m short), the images' RMSE along the step
    // preferring the short steps. Scanned along the learned heading over every length the speed
    // bound admits, turned by up to 1.5 degrees, the images' robust disagreement finds them:
    // worst 9.6 cm (into frame 390, whose turn stays 0.8 degrees off) against 0.39 m without.
    {"ASpeedChangeInADegenerateViewIsMeasuredAlongTheHeading", 0, 41, 38,
     [](registration::OdometryParams& p) { p.heading_scan = false; }, 0.12, 0.3, 5, 0, 0, true},
    // Seed 8's survey, frames 400-720 as `kartograf synth` writes them and with the map's
    // features: the robot drives at 0.8 m a frame towards a striped wall and turns, 13.8 and 30
    // degrees into frames 710 and 720, in a degenerate view (the floor and the wall 3.3-4.4 m
    // ahead, where the depth is noisiest). The features found no motion; ICP from the prediction
    // kept 2.9 and 1.2 degrees (grey-level RMSE 14.4 and 10.7) and the scan along the heading, 1.5
    // degrees about them, found nothing. Scanned over turns up to 40 degrees, the images find
    // both: worst 2.0 cm and 0.28 degrees against 20 cm and 31.2 degrees without.
    {"ATurnWhileDrivingInADegenerateViewIsScannedWide", 400, 33, 31,
     [](registration::OdometryParams& p) { p.wide_turn_scan = false; }, 0.05, 0.15, 8, 1, 10, true},
    // Seed 3's survey, frames 0-80 as `kartograf synth` writes them and with the map's features:
    // the robot drives along a wall striped every 0.221 m, over the floor, into frames 70 and 80
    // (a degenerate view: the two leave the slide along the wall free). ICP and the scans
    // around the models' steps took the steps 10.8 and 22.1 cm off, a half and a whole period;
    // along the free line the images fit best at the truth once each basin's bottom is found.
    // The features' turn on its arc at the length changed as it last changed mends them too (8.2
    // mm): off as well.
    {"ASlideAlongARepeatedTextureIsScannedAlongTheFreeLine", 0, 9, 7,
     [](registration::OdometryParams& p) {
       p.free_translation_scan = false;
       p.acceleration_on_the_arc = false;
     },
     0.03, 0.1, 3, 0, 0, true},
};

class OdometryBehaviour : public ::testing::TestWithParam<Counterfactual> {};

TEST_P(OdometryBehaviour, MendsTheStepsThatAreWrongWithoutIt) {
  const Counterfactual& c = GetParam();
  const testing::RenderedSequence sequence =
      every_10th_survey_frame(c.first, c.count, c.seed, c.as_the_cli_runs);
  const auto features =
      c.as_the_cli_runs ? std::make_shared<const features::OrbFrontEnd>(pipeline::map_orb_params())
                        : orb();
  registration::OdometryParams without;
  c.switch_off(without);
  const StepErrors with = track(sequence, features, {}, c.first_step);
  const StepErrors without_it = track(sequence, features, without, c.first_step);
  RecordProperty("worst_step_error_m", testing::scientific(with.worst_m));
  RecordProperty("worst_step_error_without_m", testing::scientific(without_it.worst_m));
  EXPECT_LT(with.worst_m, c.with_below_m);
  EXPECT_GT(without_it.worst_m, c.without_above_m);
  if (c.without_above_deg > 0) {
    RecordProperty("worst_turn_error_deg", testing::scientific(with.worst_deg));
    RecordProperty("worst_turn_error_without_deg", testing::scientific(without_it.worst_deg));
    EXPECT_LT(with.worst_deg, c.with_below_deg);
    EXPECT_GT(without_it.worst_deg, c.without_above_deg);
  }
}

INSTANTIATE_TEST_SUITE_P(FeatureTracking, OdometryBehaviour, ::testing::ValuesIn(kCounterfactuals),
                         [](const ::testing::TestParamInfo<Counterfactual>& info) {
                           return std::string(info.param.name);
                         });

// Seed 16's survey at 30 Hz, frames 770-800, as `kartograf synth` writes them: the robot drives
// towards a blank wall (frames 771-791 degenerate), then turns so that structure comes into view
// (frame 795: eigenvalue ratio 0.13). The re-estimate of frame 795 against frame 790 was judged
// on 795's whole view, but what 790 saw of it is the wall alone: ICP slid 2.6 cm along it from a
// chain right to 1 mm, within the re-estimate's limits. Judged on the part the anchor sees
// (OdometryParams::reestimate_on_overlap), the re-estimate is a degenerate view's: the chain and
// the images hold the slide, and the images side with that answer (RMSE 4.8 against 27.3).
TEST(FeatureTracking, AReestimateIsJudgedOnWhatItsAnchorSees) {
  const unsigned seed = 16;
  const std::size_t first = 770, count = 30, anchor = 20, frame = 25;
  const synth::World world = synth::make_building(seed);
  std::vector<std::uint64_t> noise_seeds;
  for (std::size_t i = 0; i < count; ++i) {
    noise_seeds.push_back(io::synthetic_frame_seed(seed, first + i));
  }
  const testing::RenderedSequence sequence = testing::render_sequence(
      world, testing::survey_poses(world, first, count), kKinect, noise_seeds);
  const auto slide = [&](bool on_overlap) {
    registration::OdometryParams params;
    params.depth_range.units_per_metre = testing::kSynthUnitsPerMetre;
    params.reestimate_on_overlap = on_overlap;
    registration::RgbdOdometry odometry(compute::Context::cpu(), sequence.camera, params);
    for (const auto& f : sequence.frames) odometry.track(f.depth, &f.color);
    EXPECT_EQ(odometry.frames()[frame].reestimate_degenerate_overlap, on_overlap);
    const auto& poses = odometry.poses();
    const Eigen::Isometry3d truth = sequence.truth[anchor].inverse() * sequence.truth[frame];
    return (truth.inverse() * (poses[anchor].inverse() * poses[frame])).translation().norm();
  };
  const double held = slide(true), slid = slide(false);
  RecordProperty("frames_790_795_error_m", testing::scientific(held));
  RecordProperty("frames_790_795_error_whole_view_m", testing::scientific(slid));
  EXPECT_LT(held, 0.005);  // measured 0.19 mm
  EXPECT_GT(slid, 0.015);  // measured 2.6 cm
}

// Seed 9's survey every 10th frame, frames 800-840: the robot drives at 0.8-0.9 m a frame, then
// turns by 17 and 20 degrees, over a checkered floor towards a plain wall with a bookcase and a
// cabinet; most views leave the forward slide free. From a prediction of rest the first step
// (0.81 m) is the features' to measure. With 1000 corners a frame they do not measure it (the
// tiles' corners repeat, and Lowe's ratio test keeps about a fifth of the matches), the step is
// taken for rest and the next two go wrong from there (0.87 m and 13 degrees, 0.68 m off); with
// the map's front end (pipeline::map_orb_params: 3000) every step is measured.
TEST(FeatureTracking, TheMapsFeatureBudgetMeasuresADriveOverATiledFloor) {
  const testing::RenderedSequence sequence = every_10th_survey_frame(800, 5, 9);
  const features::OrbParams map_params = pipeline::map_orb_params();
  features::OrbParams fewer = map_params;
  fewer.features_per_frame = 1000;
  const StepErrors with =
      track(sequence, std::make_shared<const features::OrbFrontEnd>(map_params));
  const StepErrors without = track(sequence, std::make_shared<const features::OrbFrontEnd>(fewer));
  RecordProperty("worst_step_error_m", testing::scientific(with.worst_m));
  RecordProperty("worst_step_error_1000_features_m", testing::scientific(without.worst_m));
  EXPECT_LT(with.worst_m, 0.02);  // measured 3.3 mm, 0.08 degrees
  EXPECT_LT(with.worst_deg, 0.5);
  EXPECT_GT(without.worst_m, 0.3);  // measured 0.87 m, 12.8 degrees
}

// Two views of one room 80 frames apart on the tour, the second seen again from nearby; the
// estimate of the second drifted 40 cm and 70 degrees (8 m of path: 0.4 m allowance).
struct RevisitedRoom {
  testing::RenderedSequence views;
  std::vector<Eigen::Isometry3d> drifted;
  geometry::DepthRange range;
};

const RevisitedRoom& revisited_room() {
  static const RevisitedRoom room = [] {
    const Trajectory tour = synth::robot_tour(testing::test_world(), 500);
    RevisitedRoom r{testing::render_sequence({tour[400].pose, tour[404].pose}, kKinect), {}, {}};
    r.drifted = r.views.truth;
    r.drifted[1] = r.drifted[1] * Eigen::Translation3d(0.3, 0, 0.25) *
                   Eigen::AngleAxisd(70 * kDegree, Eigen::Vector3d::UnitY());
    r.range.units_per_metre = testing::kSynthUnitsPerMetre;
    return r;
  }();
  return room;
}

TEST(FeatureTracking, LoopClosureFindsByAppearanceWhatTheDriftHides) {
  const testing::RenderedSequence& views = revisited_room().views;
  const geometry::DepthRange& range = revisited_room().range;
  mapping::LoopClosureParams params;
  params.min_frame_gap = 1;
  const compute::Context context = compute::Context::cpu();
  mapping::LoopClosureDetector detector(context, kKinect, range, params, orb());
  detector.add_keyframe(0, views.frames[0].depth, 0.0, &views.frames[0].color);
  detector.add_keyframe(1, views.frames[1].depth, 8.0, &views.frames[1].color);
  const std::vector<Eigen::Isometry3d>& poses = revisited_room().drifted;
  EXPECT_TRUE(detector.find_candidates(1, poses).empty());
  const std::vector<mapping::LoopCandidate> found = detector.find_appearance_candidates(1, poses);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_TRUE(found[0].by_appearance);
  EXPECT_GE(found[0].feature_inliers, 30u);
  const mapping::LoopClosure closure = detector.verify(found[0], poses);
  ASSERT_TRUE(closure.report.accepted());
  const Eigen::Isometry3d truth = views.truth[0].inverse() * views.truth[1];
  const Eigen::Isometry3d error = truth.inverse() * closure.constraint.motion;
  EXPECT_LT(error.translation().norm(), 0.01);
  EXPECT_LT(se3::rotation_angle(error), 0.5 * kDegree);
  // Frames 4 apart are no loop, unless the query was lost: then it is relocalised against them.
  mapping::LoopClosureParams sixty = params;
  sixty.min_frame_gap = 60;
  mapping::LoopClosureDetector relocaliser(context, kKinect, range, sixty, orb());
  relocaliser.add_keyframe(0, views.frames[0].depth, 0.0, &views.frames[0].color);
  relocaliser.add_keyframe(4, views.frames[1].depth, 8.0, &views.frames[1].color);
  std::vector<Eigen::Isometry3d> by_frame(5, poses[0]);
  by_frame[4] = poses[1];
  EXPECT_TRUE(relocaliser.find_appearance_candidates(1, by_frame).empty());
  EXPECT_EQ(relocaliser.find_appearance_candidates(1, by_frame, true).size(), 1u);
  // Without a feature front end there is no appearance candidate.
  mapping::LoopClosureDetector blind(context, kKinect, range, params);
  blind.add_keyframe(0, views.frames[0].depth, 0.0, &views.frames[0].color);
  blind.add_keyframe(1, views.frames[1].depth, 8.0, &views.frames[1].color);
  EXPECT_TRUE(blind.find_appearance_candidates(1, poses).empty());
}

// The same room with the estimate 3 m farther off than the drift allowance (0.5 m + 5 % of 8 m):
// the features' motion is a look-alike's unless as many inliers as decisive_feature_inliers agree.
TEST(FeatureTracking, AnAppearanceLoopBeyondTheDriftNeedsDecisiveFeatures) {
  const testing::RenderedSequence& views = revisited_room().views;
  std::vector<Eigen::Isometry3d> poses = revisited_room().drifted;
  poses[1] = Eigen::Translation3d(3, 0, 0) * poses[1];
  const auto candidates = [&](std::size_t decisive) {
    mapping::LoopClosureParams params;
    params.min_frame_gap = 1;
    params.decisive_feature_inliers = decisive;
    mapping::LoopClosureDetector detector(compute::Context::cpu(), kKinect, revisited_room().range,
                                          params, orb());
    detector.add_keyframe(0, views.frames[0].depth, 0.0, &views.frames[0].color);
    detector.add_keyframe(1, views.frames[1].depth, 8.0, &views.frames[1].color);
    return detector.find_appearance_candidates(1, poses);
  };
  const auto beyond_any = candidates(std::numeric_limits<std::size_t>::max());
  EXPECT_TRUE(beyond_any.empty());
  const auto believed = candidates(30);
  ASSERT_EQ(believed.size(), 1u);
  const std::size_t inliers = believed[0].feature_inliers;
  std::cout << "  the room seen again, 3 m beyond the allowance: " << inliers << " inliers\n";
  EXPECT_EQ(candidates(inliers).size(), 1u);
  EXPECT_TRUE(candidates(inliers + 1).empty());
}

// Keyframes whose depth, samples and features all went to the temporary files (no memory for
// them) give the same candidates and the same loop as keyframes kept in memory.
TEST(FeatureTracking, KeyframesReadBackFromDiskFindTheSameLoops) {
  const testing::RenderedSequence& views = revisited_room().views;
  const geometry::DepthRange& range = revisited_room().range;
  mapping::LoopClosureParams in_memory;
  in_memory.min_frame_gap = 1;
  mapping::LoopClosureParams on_disk = in_memory;
  on_disk.keyframe_depth_memory = 0;
  on_disk.keyframe_feature_memory = 0;
  const compute::Context context = compute::Context::cpu();
  mapping::LoopClosureDetector kept(context, kKinect, range, in_memory, orb());
  mapping::LoopClosureDetector spilled(context, kKinect, range, on_disk, orb());
  for (mapping::LoopClosureDetector* detector : {&kept, &spilled}) {
    detector->add_keyframe(0, views.frames[0].depth, 0.0, &views.frames[0].color);
    detector->add_keyframe(1, views.frames[1].depth, 8.0, &views.frames[1].color);
  }
  EXPECT_EQ(kept.keyframe_bytes_on_disk(), 0u);
  EXPECT_GT(kept.keyframe_bytes_in_memory(), 2 * 640 * 480u);
  EXPECT_EQ(spilled.keyframe_bytes_in_memory(), 0u);
  EXPECT_GT(spilled.keyframe_bytes_on_disk(), 2 * 640 * 480u);
  const std::vector<Eigen::Isometry3d>& poses = revisited_room().drifted;
  const auto expected = kept.find_appearance_candidates(1, poses);
  const auto found = spilled.find_appearance_candidates(1, poses);
  ASSERT_EQ(expected.size(), 1u);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].feature_inliers, expected[0].feature_inliers);
  EXPECT_EQ(found[0].overlap, expected[0].overlap);
  EXPECT_TRUE(found[0].feature_motion.matrix() == expected[0].feature_motion.matrix());
  EXPECT_EQ(spilled.view_overlap(1, 0, found[0].feature_motion, 0.1),
            kept.view_overlap(1, 0, found[0].feature_motion, 0.1));
  const mapping::LoopClosure a = kept.verify(expected[0], poses);
  const mapping::LoopClosure b = spilled.verify(found[0], poses);
  ASSERT_TRUE(b.report.accepted());
  EXPECT_TRUE(b.constraint.motion.matrix() == a.constraint.motion.matrix());
}

// Two views of the tour 4 frames apart (and a third from elsewhere) whose estimate is `offset` off
// (by default 25 cm: a loop candidate by pose whose correction exceeds the 10 cm a loop may move
// without drift).
struct LoopCorrection {
  testing::RenderedSequence views;
  geometry::DepthRange range;
  mapping::LoopClosureParams params;
  std::vector<Eigen::Isometry3d> poses;
  mapping::LoopCandidate candidate;
};

LoopCorrection loop_correction(const Eigen::Vector3d& offset = {0.2, 0.15, 0}) {
  const Trajectory tour = synth::robot_tour(testing::test_world(), 500);
  LoopCorrection loop;
  loop.views = testing::render_sequence({tour[400].pose, tour[404].pose, tour[100].pose}, kKinect);
  loop.range.units_per_metre = testing::kSynthUnitsPerMetre;
  loop.params.min_frame_gap = 1;
  loop.params.min_correction_m = 0.1;
  loop.poses = {loop.views.truth[0], Eigen::Translation3d(offset) * loop.views.truth[1]};
  loop.candidate.query = 1;
  loop.candidate.query_frame = 1;
  loop.candidate.drift_allowance_m = 0.5;
  return loop;
}

// A loop found by pose whose ICP corrects the estimate by more than a loop may move without drift
// (here 25 cm against 10 cm) must be seen by the features too: with matching views it is; with
// the match's colour from elsewhere (features that see another place) it is unconfirmed; without
// a feature front end it stands on ICP alone.
TEST(FeatureTracking, ALargeLoopCorrectionNeedsTheFeaturesToAgree) {
  const LoopCorrection loop = loop_correction();
  const auto& [views, range, params, poses, candidate] = loop;
  const compute::Context context = compute::Context::cpu();
  const auto verdict = [&](std::shared_ptr<const features::OrbFrontEnd> front_end,
                           const RgbImage& match_color) {
    mapping::LoopClosureDetector detector(context, kKinect, range, params, front_end);
    detector.add_keyframe(0, views.frames[0].depth, 0.0, &match_color);
    detector.add_keyframe(1, views.frames[1].depth, 8.0, &views.frames[1].color);
    const mapping::LoopClosure closure = detector.verify(candidate, poses);
    EXPECT_GT(closure.report.correction_m, params.min_correction_m);
    return closure.report.verdict;
  };
  using registration::RegistrationVerdict;
  EXPECT_EQ(verdict(orb(), views.frames[0].color), RegistrationVerdict::accepted);
  EXPECT_EQ(verdict(orb(), views.frames[2].color), RegistrationVerdict::unconfirmed);
  EXPECT_EQ(verdict(nullptr, views.frames[2].color), RegistrationVerdict::accepted);
}

// A chain covariance of `metres` in translation (1 mm and about 0.06 degrees in rotation).
mapping::LoopClosureDetector::ExpectedUncertainty chain_sigma(double metres) {
  return [metres](const mapping::LoopCandidate&) {
    se3::Matrix6d covariance = se3::Matrix6d::Identity() * 1e-6;
    covariance.bottomRightCorner<3, 3>() *= metres * metres / 1e-6;
    return covariance;
  };
}

// A detector holding the loop's two keyframes, the match's image plain (nothing to match: the
// features are silent).
std::unique_ptr<mapping::LoopClosureDetector> silent_detector(const compute::Context& context,
                                                              const LoopCorrection& loop) {
  auto detector = std::make_unique<mapping::LoopClosureDetector>(context, kKinect, loop.range,
                                                                 loop.params, orb());
  const RgbImage plain(loop.views.frames[0].color.width(), loop.views.frames[0].color.height(),
                       Rgb8{128, 128, 128});
  detector->add_keyframe(0, loop.views.frames[0].depth, 0.0, &plain);
  detector->add_keyframe(1, loop.views.frames[1].depth, 8.0, &loop.views.frames[1].color);
  return detector;
}

// Where the features are silent a large correction stands on the odometry's uncertainty instead:
// accepted when the chain between the keyframes could have drifted that far (a 25 cm correction
// under 30 cm of chain sigma), unconfirmed when it could not (2 cm), and unconfirmed when the
// caller gives no uncertainty.
TEST(FeatureTracking, WhereTheFeaturesAreSilentTheOdometrysUncertaintyDecides) {
  const LoopCorrection loop = loop_correction();
  const compute::Context context = compute::Context::cpu();
  const auto detector = silent_detector(context, loop);
  const mapping::LoopClosure drifted =
      detector->verify(loop.candidate, loop.poses, chain_sigma(0.3));
  EXPECT_GT(drifted.report.correction_m, loop.params.min_correction_m);
  EXPECT_EQ(drifted.confirmation, mapping::FeatureConfirmation::silent);
  EXPECT_EQ(drifted.report.verdict, registration::RegistrationVerdict::accepted);
  EXPECT_GT(drifted.correction_chi2, 0.0);
  EXPECT_LT(drifted.correction_chi2, loop.params.max_correction_chi2);
  const mapping::LoopClosure tight =
      detector->verify(loop.candidate, loop.poses, chain_sigma(0.02));
  EXPECT_EQ(tight.report.verdict, registration::RegistrationVerdict::unconfirmed);
  EXPECT_GT(tight.correction_chi2, loop.params.max_correction_chi2);
  const mapping::LoopClosure unknown = detector->verify(loop.candidate, loop.poses);
  EXPECT_EQ(unknown.report.verdict, registration::RegistrationVerdict::unconfirmed);
  EXPECT_LT(unknown.correction_chi2, 0.0);
}

// A correction within the drift allowance's floor (5 cm, under min_correction_m's 0.2 m) is
// confirmed too where the query kept every direction and its weakest is under twice
// weak_direction_ratio (ICP may have slid along it): with silent features it must be one the chain
// could have drifted by (unconfirmed under 5 mm of chain sigma). With the weakest direction
// stronger than that, ICP's answer stands. On held-out survey seed 32 ICP slid 4-11 cm along plain
// walls (ratio 0.054-0.068) between views of a robot turning on the spot, where the chain was 4 mm
// off, and those loops bent the graph by 8 cm.
TEST(FeatureTracking, ASmallCorrectionAlongABarelyConstrainedDirectionIsConfirmed) {
  LoopCorrection loop = loop_correction({0.04, 0.03, 0});
  loop.params.min_correction_m = mapping::LoopClosureParams{}.min_correction_m;
  const compute::Context context = compute::Context::cpu();
  const double ratio =
      silent_detector(context, loop)->verify(loop.candidate, loop.poses).report.eigenvalue_ratio;
  ASSERT_GT(ratio, 0.0);
  const auto verify_with_weak_ratio = [&](double weak) {
    loop.params.weak_direction_ratio = weak;
    return silent_detector(context, loop)->verify(loop.candidate, loop.poses, chain_sigma(0.005));
  };
  const mapping::LoopClosure barely = verify_with_weak_ratio(0.6 * ratio);
  EXPECT_EQ(barely.free_directions, 0u);
  EXPECT_GT(barely.report.correction_m, 0.03);
  EXPECT_LT(barely.report.correction_m, loop.params.min_correction_m);
  EXPECT_EQ(barely.confirmation, mapping::FeatureConfirmation::silent);
  EXPECT_EQ(barely.report.verdict, registration::RegistrationVerdict::unconfirmed);
  EXPECT_GT(barely.correction_chi2, loop.params.max_correction_chi2);
  const mapping::LoopClosure constrained = verify_with_weak_ratio(0.4 * ratio);
  EXPECT_EQ(constrained.confirmation, mapping::FeatureConfirmation::not_asked);
  EXPECT_EQ(constrained.report.verdict, registration::RegistrationVerdict::accepted);
}

}  // namespace
}  // namespace kartograf
