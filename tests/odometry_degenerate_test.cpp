// Degenerate views of other buildings than the default one: the stretches of the synthetic survey
// (the demo's recipe: `kartograf synth --survey --pitch 20 --seed N`) where the odometry used to
// fail (docs/user-guide.md). Seed 3, frames 918-940: a corridor of grey floor and two walls whose
// end is beyond the sensor's range, entered at 10 cm per frame (ICP's free answer, then the
// photometric refinement of the weak direction, turned 1.5 degrees per frame). Seed 5, frames
// 832-860: a wall, a shelf and the floor while the robot turns and slows down (holding the
// weak direction at the centroid instead of the camera moved it 4 cm sideways per frame); both
// with and without the photometric refinement, which must not be needed there. Seed 2, frames
// 140-170: a corridor entered while speeding up from 2 to 7 cm per frame, which only image
// intensity can measure (the motion model keeps the old speed). Seed 7, frames 860-880, and seed 4,
// frames 180-215: a turn that stops, and an arc into a view of a faint floor (the odometry's other
// starts and the motion model's step frame, without the images); seed 4, frames 190-221, that
// floor measured by the images' fine pass alone. Seed 4, frames 842-864, and seed 8,
// frames 674-698: the barely constrained directions measured by the images too. Seed 10, frames
// 263-300: an arc's onset (the motion model's arc). Seed 4, frames 120-160, and seed 7, frames
// 1210-1240: re-estimates after a degenerate stretch, confirmed or refused by the images; seed 4,
// frames 120-150: an images' correction beyond the re-estimate's limits that they do not fit.
// Rendered at 640x480 with the Kinect noise model, as the survey is.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/mapping/pose_graph.hpp"
#include "kartograf/registration/odometry.hpp"
#include "kartograf/registration/registration_check.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "kartograf/synth/world.hpp"
#include "rgbd_test_sequence.hpp"

namespace kartograf {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

struct DegenerateStretch {
  std::uint64_t seed = 0;
  std::size_t first = 0;
  std::size_t count = 0;
  bool photometric = true;  // OdometryParams::photometric_refinement
  std::size_t stride = 1;   // every stride-th frame of the survey (10: a robot's 3 Hz camera)
};

std::string stretch_name(const DegenerateStretch& s) {
  return "seed" + std::to_string(s.seed) + "_frames" + std::to_string(s.first) +
         (s.photometric ? "" : "_geometry_only");
}

void PrintTo(const DegenerateStretch& s, std::ostream* out) {
  *out << stretch_name(s);
}

struct StepError {
  double metres = 0, degrees = 0;
};

struct TrackedStretch {
  std::size_t degenerate = 0;    // frames whose view leaves a direction free
  std::vector<StepError> steps;  // against the truth, one per step
  double ate = 0;
};

struct TrackedFrames {
  std::vector<registration::OdometryFrame> frames;
  std::vector<Eigen::Isometry3d> poses, truth;
  std::vector<registration::RelativePose> constraints;  // the pose graph's odometry edges
  // The error of frame `to`'s pose relative to frame `from`'s (metres, degrees).
  StepError error_between(std::size_t from, std::size_t to) const {
    const Eigen::Isometry3d error =
        (truth[from].inverse() * truth[to]).inverse() * (poses[from].inverse() * poses[to]);
    return {error.translation().norm(), se3::rotation_angle(error) / kDegree};
  }
  // The pose error of frame `index` relative to the stretch's first frame.
  StepError error_at(std::size_t index) const { return error_between(0, index); }
};

// The stretch rendered at 640x480 with the Kinect noise model and tracked with `params`.
TrackedFrames track_frames(const DegenerateStretch& stretch, registration::OdometryParams params) {
  const synth::World world = synth::make_building(stretch.seed);
  const PinholeIntrinsics kinect{640, 480, 525, 525, 319.5, 239.5};
  const testing::RenderedSequence sequence = testing::render_sequence(
      world, testing::survey_poses(world, stretch.first, stretch.count, stretch.stride), kinect);
  params.depth_range.units_per_metre = testing::kSynthUnitsPerMetre;
  params.photometric_refinement = stretch.photometric;
  registration::RgbdOdometry odometry(compute::Context::cpu(), sequence.camera, params);
  TrackedFrames tracked;
  for (const auto& frame : sequence.frames) {
    tracked.frames.push_back(odometry.track(frame.depth, &frame.color));
  }
  tracked.poses = odometry.poses();
  tracked.truth = sequence.truth;
  tracked.constraints = odometry.constraints();
  return tracked;
}

TrackedStretch stretch_of(const TrackedFrames& frames) {
  TrackedStretch tracked;
  for (const auto& frame : frames.frames) tracked.degenerate += frame.degenerate ? 1 : 0;
  for (std::size_t i = 1; i < frames.poses.size(); ++i)
    tracked.steps.push_back(frames.error_between(i - 1, i));
  tracked.ate = testing::ate_rmse(frames.poses, frames.truth);
  return tracked;
}

TrackedStretch track_stretch(const DegenerateStretch& stretch,
                             const registration::OdometryParams& params) {
  return stretch_of(track_frames(stretch, params));
}

class DegenerateViews : public ::testing::TestWithParam<DegenerateStretch> {};

TEST_P(DegenerateViews, EveryStepStaysWithinACentimetreAndAQuarterDegree) {
  const DegenerateStretch stretch = GetParam();
  const TrackedStretch tracked = track_stretch(stretch, {});
  // The stretch is what it is meant to be: mostly views that leave a direction free.
  EXPECT_GE(tracked.degenerate, stretch.count / 3);
  for (std::size_t i = 0; i < tracked.steps.size(); ++i) {
    EXPECT_LT(tracked.steps[i].metres, 0.01) << "frame " << stretch.first + i + 1;
    EXPECT_LT(tracked.steps[i].degrees, 0.25) << "frame " << stretch.first + i + 1;
  }
  EXPECT_LT(tracked.ate, 0.02);
}

INSTANTIATE_TEST_SUITE_P(Survey, DegenerateViews,
                         ::testing::Values(DegenerateStretch{3, 918, 22, true},
                                           DegenerateStretch{3, 918, 22, false},
                                           DegenerateStretch{5, 832, 28, true},
                                           DegenerateStretch{5, 832, 28, false},
                                           DegenerateStretch{2, 140, 30, true}),
                         [](const auto& info) { return stretch_name(info.param); });

// The largest error of a step (metres, degrees) when the stretch is tracked with `params`.
std::pair<double, double> worst_step(const DegenerateStretch& stretch,
                                     const registration::OdometryParams& params) {
  double metres = 0, degrees = 0;
  for (const StepError& step : track_stretch(stretch, params).steps) {
    metres = std::max(metres, step.metres);
    degrees = std::max(degrees, step.degrees);
  }
  return {metres, degrees};
}

// Seed 7, frames 860-880: the robot stops turning and drives on in a weakly constrained view
// (eigenvalue ratio 0.08); ICP from the predicted turn settled 9 cm off at frame 871 and was
// accepted. The registration moved 9.5 cm from the prediction, so it is run again from other
// starts: from the predicted step alone it fits better and is right.
TEST(DoubtfulRegistration, ATurnThatStopsIsFoundFromTheStepAlone) {
  const DegenerateStretch stretch{7, 860, 20, true};
  const auto [metres, degrees] = worst_step(stretch, {});
  EXPECT_LT(metres, 0.01);
  EXPECT_LT(degrees, 0.25);
  registration::OdometryParams no_recheck;
  no_recheck.recheck_correction_m = 1e3;
  EXPECT_GT(worst_step(stretch, no_recheck).first, 0.05);
}

// Held-out seed 29, every 10th frame from 800: a turn on the spot of 38.8 degrees a frame, from
// a wall into a corner over a bare floor (plain blue walls, a grey floor: the images measure
// nothing). At frame 850 ICP from the prediction found the turn at a fitness of 0.29 (the views
// share a third of their points), doubtful, so other starts were tried, and rest won with no
// turn at 0.55: the same floor overlaps whole, while 23 % of its points lie where the previous
// camera saw past them. Contradictions beyond 5 % count against the answer, each twice what an
// agreeing point counts for it (OdometryParams::contradiction_weight, contradiction_floor).
TEST(DoubtfulRegistration, AWideTurnIsNotShrunkWhereTheViewContradictsIt) {
  const DegenerateStretch stretch{29, 800, 8, true, 10};
  const auto [metres, degrees] = worst_step(stretch, {});
  RecordProperty("worst_step_m", std::to_string(metres));
  RecordProperty("worst_step_deg", std::to_string(degrees));
  EXPECT_LT(metres, 0.01);
  EXPECT_LT(degrees, 0.5);
  registration::OdometryParams by_fitness;
  by_fitness.contradiction_weight = 0;
  EXPECT_GT(worst_step(stretch, by_fitness).second, 20.0);
}

// Seed 4, frames 180-215: a robot driving an arc (2 degrees and 5 cm per frame, slowing down)
// into a view of one wall and the floor that leaves the slide along them free. Without the images
// (the floor's grain is faint; since the fine pass measures it alone, the test below, they do) the
// motion model decides it: keeping the step in the world frame drifted sideways by the step times
// the turn, 1.1-1.7 cm per frame; the adaptive model has learnt from the frames before that this
// camera's step turns with it.
TEST(DoubtfulRegistration, ARobotsArcIsPredictedInTheCameraFrame) {
  const DegenerateStretch stretch{4, 180, 36, false};
  const auto [adaptive, adaptive_degrees] = worst_step(stretch, {});
  registration::OdometryParams world;
  world.step_frame = registration::StepFrame::world;
  const double in_world = worst_step(stretch, world).first;
  RecordProperty("worst_step_adaptive_m", std::to_string(adaptive));
  RecordProperty("worst_step_world_m", std::to_string(in_world));
  EXPECT_LT(adaptive, 0.005);  // measured 1.9 mm, 16.9 in world
  EXPECT_LT(adaptive_degrees, 0.25);
  EXPECT_GT(in_world, adaptive + 0.003);
}

// Seed 4, frames 190-221: the robot drives towards a plain wall over a floor whose wood grain is
// faint, slowing down from 5 to 1 cm per frame. Three binomial passes (the refinement's coarse
// pass) leave fewer than 200 pixels of the grain above the gradient threshold (61 at frame 205),
// one pass over 700; the refinement used to give up with the coarse pass, so the motion model kept
// the old speed (steps up to 6.8 mm off, ATE 15 mm). The fine pass now measures it alone, under
// the same sigma gate. The first step, from rest, is left out: nothing predicts it.
TEST(PhotometricRefinement, AFloorTooFaintForTheCoarsePassIsMeasuredByTheFinePass) {
  const DegenerateStretch stretch{4, 190, 32, true};
  const TrackedFrames frames = track_frames(stretch, {});
  std::size_t degenerate = 0, measured = 0;
  for (const auto& frame : frames.frames) {
    degenerate += frame.degenerate ? 1 : 0;
    measured += frame.photometric ? 1 : 0;
  }
  EXPECT_GE(degenerate, 30u);
  EXPECT_GE(measured, degenerate * 9 / 10);  // measured 31 of 31 (1 before)
  const TrackedStretch tracked = stretch_of(frames);
  for (std::size_t i = 1; i < tracked.steps.size(); ++i) {
    EXPECT_LT(tracked.steps[i].metres, 0.003) << "frame " << stretch.first + i + 1;
  }
  EXPECT_LT(tracked.ate, 0.005);  // measured 2.2 mm (15.3 mm before)
}

// Held-out survey seed 24, frames 790-870: a floor-only drive (the far wall beyond the depth's
// range) speeding up from 4 to 6.6 cm a frame and slowing down again, over a carpet whose soft
// blotches stay under the gradient threshold: fewer than 200 pixels reach 4 grey levels, so the
// refinement measured nothing and the motion model kept the old speed (steps up to 3 cm short).
// The texture from 0.75 up to 4 grey levels measures those steps.
TEST(PhotometricRefinement, AFaintCarpetIsMeasuredBelowTheGradientThreshold) {
  const DegenerateStretch stretch{24, 790, 80, true};
  const TrackedStretch tracked = track_stretch(stretch, {});
  EXPECT_GE(tracked.degenerate, 40u);
  double worst = 0;
  for (std::size_t i = 0; i < tracked.steps.size(); ++i) {
    EXPECT_LT(tracked.steps[i].metres, 0.005) << "frame " << stretch.first + i + 1;
    EXPECT_LT(tracked.steps[i].degrees, 0.25) << "frame " << stretch.first + i + 1;
    worst = std::max(worst, tracked.steps[i].metres);
  }
  RecordProperty("worst_step_m", std::to_string(worst));
  registration::OdometryParams without;
  without.photometric.faint_min_gradient = 0;
  const double worst_without = worst_step(stretch, without).first;
  RecordProperty("worst_step_without_m", std::to_string(worst_without));
  EXPECT_GT(worst_without, 0.02);
}

// Held-out survey seed 11, frames 200-280: a floor-only drive over a faint carpet, speeding up
// from 6 to 11 cm a frame, through a doorway at frame 248. There the jambs, seen edge-on at the
// image's sides, misfit by tens of grey levels: the faint texture's answer moved the step 4 cm
// too far at an RMSE of 2.7-3.2 (a carpet fits at 0.4-0.7), and the RMSE gate
// (PhotometricParams::faint_max_rmse) refuses it.
TEST(PhotometricRefinement, AFaintTextureIsKeptOnlyWhereItFitsTheImages) {
  const DegenerateStretch stretch{11, 200, 80, true};
  registration::OdometryParams ungated;
  ungated.photometric.faint_max_rmse = 1e9;
  const double worst = worst_step(stretch, {}).first;
  const double worst_ungated = worst_step(stretch, ungated).first;
  RecordProperty("worst_step_m", std::to_string(worst));
  RecordProperty("worst_step_ungated_m", std::to_string(worst_ungated));
  EXPECT_LT(worst, 0.01);
  EXPECT_GT(worst_ungated, 0.02);
}

// Seed 10, frames 263-300: the robot drives straight, then starts an arc of 2.3 degrees a frame
// (frame 288) into a view of one wall and the floor (frames 289-297 degenerate; tracked without the
// images, which now measure them as well). ICP at the onset took the turn 0.1 degrees short and the
// step 4 mm sideways; kept in the camera frame, that sideways step was repeated on the degenerate
// frames after it (0.4 cm each). The arc model predicts the step from the turn and the direction of
// travel. Both without the heading prior, which since holds those sideways steps itself (the
// camera frame's worst step 0.2 mm with it).
TEST(DoubtfulRegistration, ASidewaysErrorAtAnArcsOnsetIsNotRepeated) {
  const DegenerateStretch onset{10, 263, 37, false};
  const auto worst_after_onset = [&](const registration::OdometryParams& params) {
    const TrackedStretch tracked = track_stretch(onset, params);
    double metres = 0;
    for (std::size_t i = 289 - onset.first - 1; i < tracked.steps.size(); ++i) {
      metres = std::max(metres, tracked.steps[i].metres);
    }
    return metres;
  };
  registration::OdometryParams adaptive_alone;
  adaptive_alone.heading_prior = false;
  // The motion prior's translations as they were: weaker (0.015, 2026-12-07) they keep the camera
  // frame's sideways steps within 2.8 mm themselves.
  adaptive_alone.motion_prior_translation = 0.03;
  registration::OdometryParams camera = adaptive_alone;
  camera.step_frame = registration::StepFrame::camera;
  const double adaptive = worst_after_onset(adaptive_alone);
  RecordProperty("worst_step_adaptive_m", std::to_string(adaptive));
  const double in_camera = worst_after_onset(camera);
  RecordProperty("worst_step_camera_m", std::to_string(in_camera));
  EXPECT_LT(adaptive, 0.0015);  // measured 1.0 mm, with the arc model chosen
  EXPECT_GT(in_camera, 0.003);
}

// Seed 4, frames 842-864: the robot drives towards a far wall past a cabinet, over a floor whose
// grain runs across the image. The slide with a turn about the far wall is free, and the turn
// and slide about the camera is barely constrained: the motion prior pulled ICP 0.2 degrees and
// 1 cm towards a wrong prediction in it, and refining the free direction alone moved the answer
// further off. The images now measure the barely constrained directions too (measured: worst
// step 6.3 mm, 42 mm with the free direction alone). Seed 8, frames 674-698: striped walls and a
// finely grained cabinet whose point-sampled texture does not move with the surface; there the
// images alone drew steps 11.5 cm off, and ICP's own information on what it measured holds them
// (11.2 mm, as before the change: 11.4 mm). Both failures were measured with the pixels beside
// depth edges in the images' fit; without them (PhotometricParams::mask_depth_edges) the free
// direction alone is 15 mm off on the first stretch, and on the second the images alone are 7.6
// mm off and the defaults 1.2 mm.
TEST(PhotometricRefinement, TheBarelyConstrainedDirectionsAreMeasuredHeldByTheGeometry) {
  const DegenerateStretch cabinet{4, 842, 22, true};
  const auto [metres, degrees] = worst_step(cabinet, {});
  EXPECT_LT(metres, 0.01);
  EXPECT_LT(degrees, 0.25);
  registration::OdometryParams free_only;
  free_only.photometric_direction_ratio = 0;  // the degenerate directions alone, as before
  free_only.photometric_geometry_weight = 0;
  // As measured before the arc model, which predicts this stretch's turn well enough that the
  // free direction alone stays within 7 mm.
  free_only.step_frame = registration::StepFrame::camera;
  free_only.photometric.mask_depth_edges = false;
  // The scan along the free line (2026-12-06) mends part of it (19 mm): off, as before it.
  free_only.free_translation_scan = false;
  // The motion prior's weaker translations (2026-12-07) pull less towards the wrong prediction
  // (14.8 mm): as they were.
  free_only.motion_prior_translation = 0.03;
  EXPECT_GT(worst_step(cabinet, free_only).first, 0.02);

  const DegenerateStretch stripes{8, 674, 24, true};
  EXPECT_LT(worst_step(stripes, {}).first, 0.015);
  registration::OdometryParams images_alone;
  images_alone.photometric_geometry_weight = 0;
  EXPECT_LT(worst_step(stripes, images_alone).first, 0.015);
  images_alone.photometric.mask_depth_edges = false;
  images_alone.motion_prior_translation = 0.03;  // as measured (at 0.015: 3.4 cm)
  EXPECT_GT(worst_step(stripes, images_alone).first, 0.05);
}

// A re-estimate after a degenerate stretch, from a view that is not degenerate, may correct what
// the stretch's free directions drifted, beyond the usual 3 cm and 2 degrees, when the images
// agree clearly better with it than with the chain. Seed 4, frames 145-153: a straight drive
// whose images on two frames turned the steps 0.05-0.08 degrees, which the motion model then
// repeated (2.4 degrees in all); the re-estimate at frame 155 against frame 145 corrects 2.1
// degrees. Those two turns came from the pixels beside a depth edge, now left out of the images'
// fit; they are kept here to drift the stretch as it drifted. Seed 7, frames 1230-1235: ICP
// against the anchor slid 6.7 cm along a weak direction while the chain was right; the images
// refuse it.
TEST(Reestimation, AfterADegenerateStretchTheImagesConfirmALargeCorrection) {
  const DegenerateStretch straight{4, 120, 40, true};
  const std::size_t frame = 155 - straight.first;
  registration::OdometryParams with_edges;
  with_edges.photometric.mask_depth_edges = false;
  // Judged on what frame 145 sees of it the re-estimate is degenerate; the images do not side
  // with the chain's answer there, so the first stands (OdometryParams::reestimate_on_overlap).
  with_edges.reestimate_on_overlap = true;
  const TrackedFrames confirmed = track_frames(straight, with_edges);
  ASSERT_TRUE(confirmed.frames[frame].reestimate.has_value());
  EXPECT_TRUE(confirmed.frames[frame].reestimate->accepted());
  EXPECT_GT(confirmed.frames[frame].reestimate->correction_deg, 1.0);
  const StepError corrected = confirmed.error_at(frame);
  registration::OdometryParams never_confirmed = with_edges;
  never_confirmed.feature_arbitration_ratio = 1e-9;  // the images never agree well enough
  const StepError uncorrected = track_frames(straight, never_confirmed).error_at(frame);
  RecordProperty("frame_155_error_deg", std::to_string(corrected.degrees));
  EXPECT_LT(corrected.degrees, 0.5 * uncorrected.degrees);
  EXPECT_LT(corrected.metres, uncorrected.metres);
}

// Seed 4, frames 120-150: a straight drive past a dark shelf, the view degenerate. At frame 150
// the re-estimate against frame 145 (18 cm back) was 1 cm from the chain by ICP, and the images
// moved it 3.7 cm and 1.1 degrees on, fitting what the step occluded (grey-level RMSE 25, then
// 15); the correction was spread over frames 146-150. A refinement beyond the re-estimate's
// correction limits (3 cm, 2 degrees) is now kept only where the images fit it (an RMSE within
// photometric_doubt_rmse, 10 grey levels). Both without the heading prior, which since keeps the
// images' correction small there itself (0.03 degrees with any fit).
TEST(Reestimation, AnImagesCorrectionBeyondTheLimitsNeedsTheImagesToFitIt) {
  const DegenerateStretch straight{4, 120, 31, true};
  const std::size_t frame = 150 - straight.first;
  registration::OdometryParams limits_alone;
  limits_alone.heading_prior = false;
  // The motion prior's translations as they were: weaker (0.015, 2026-12-07) they let ICP's own
  // answer stand against the images' (0.16 degrees with any fit).
  limits_alone.motion_prior_translation = 0.03;
  const StepError limited = track_frames(straight, limits_alone).error_at(frame);
  registration::OdometryParams any_fit = limits_alone;
  any_fit.photometric_doubt_rmse = 1e3;
  const StepError unlimited = track_frames(straight, any_fit).error_at(frame);
  RecordProperty("frame_150_error_deg", std::to_string(limited.degrees));
  RecordProperty("frame_150_error_deg_any_fit", std::to_string(unlimited.degrees));
  EXPECT_LT(limited.degrees, 0.2);    // measured 0.04 degrees, 0.6 mm
  EXPECT_GT(unlimited.degrees, 0.5);  // measured 1.25 degrees, 3.7 cm
}

// The re-estimate judged on what its anchor sees (OdometryParams::reestimate_on_overlap;
// FeatureTracking.AReestimateIsJudgedOnWhatItsAnchorSees) holds that slide too: the images'
// confirmation is checked without it, then that rule alone.
TEST(Reestimation, AfterADegenerateStretchTheImagesRefuseASlideAlongAWeakDirection) {
  const DegenerateStretch corridor{7, 1210, 30, true};
  const std::size_t frame = 1235 - corridor.first;
  registration::OdometryParams whole_view;
  whole_view.reestimate_on_overlap = false;
  const TrackedFrames refused = track_frames(corridor, whole_view);
  ASSERT_TRUE(refused.frames[frame].reestimate.has_value());
  EXPECT_EQ(refused.frames[frame].reestimate->verdict,
            registration::RegistrationVerdict::unconfirmed);
  EXPECT_GT(refused.frames[frame].reestimate->correction_m, 0.03);
  EXPECT_LT(refused.error_at(frame).metres, 0.005);
  registration::OdometryParams always_confirmed = whole_view;
  always_confirmed.feature_arbitration_ratio = 1e9;
  EXPECT_GT(track_frames(corridor, always_confirmed).error_at(frame).metres, 0.02);
  registration::OdometryParams on_overlap;
  on_overlap.reestimate_on_overlap = true;
  const TrackedFrames held = track_frames(corridor, on_overlap);
  EXPECT_TRUE(held.frames[frame].reestimate_degenerate_overlap);
  EXPECT_LT(held.error_at(frame).metres, 0.005);
}

// The stretch tracked with the default parameters but one switch, `switched_off`, false.
TrackedFrames track_frames_without(const DegenerateStretch& stretch,
                                   bool registration::OdometryParams::*switched_off) {
  registration::OdometryParams params;
  params.*switched_off = false;
  return track_frames(stretch, params);
}

// How many of the tracked frames `counts`.
template <typename Predicate>
std::size_t frames_where(const TrackedFrames& tracked, Predicate counts) {
  return static_cast<std::size_t>(
      std::count_if(tracked.frames.begin(), tracked.frames.end(), counts));
}

// Seed 8, frames 650-720: 25 frames down a room that measure every direction, then a wall ahead
// over the floor for the rest, where the robot turns and drives on. The slide along the wall is
// free to the geometry; the heading prior (a wheeled robot does not move sideways) holds it.
TEST(HeadingPriorOnTheSurvey, HoldsTheSlideAlongAWallAhead) {
  const DegenerateStretch wall_ahead{8, 650, 71, true};
  const TrackedFrames held = track_frames(wall_ahead, {});
  const TrackedFrames slid =
      track_frames_without(wall_ahead, &registration::OdometryParams::heading_prior);
  const std::size_t holding = frames_where(
      held, [](const registration::OdometryFrame& frame) { return frame.heading_sigma_m > 0; });
  const auto summed_step_error = [](const TrackedFrames& tracked) {
    double metres = 0;
    for (const StepError& step : stretch_of(tracked).steps) metres += step.metres;
    return metres;
  };
  RecordProperty("frames_held", std::to_string(holding));
  RecordProperty("step_error_sum_mm", std::to_string(1000 * summed_step_error(held)));
  RecordProperty("step_error_sum_mm_without", std::to_string(1000 * summed_step_error(slid)));
  EXPECT_GE(holding, 30u);  // measured 46: every degenerate frame
  // Measured 37.4 mm against 69.5 mm (ATE 2.9 against 3.9 mm).
  EXPECT_LT(summed_step_error(held), 0.65 * summed_step_error(slid));
  EXPECT_LT(stretch_of(held).ate, stretch_of(slid).ate);
}

// Held-out seed 16, frames 389-440: 22 frames down a room that measure every direction (the
// heading is learned), then 30 over the floor alone while the robot slows from 10.9 to 8.1 cm a
// frame. The weak directions' refinement, held by ICP's answer and the heading together, kept
// each step 2-5 mm longer than the truth; the images alone along the heading measure it
// (OdometryParams::photometric_travel_length).
//
// Found with the motion prior's translations at 0.03, whose pull towards the prediction the
// refinement's holds kept; weaker (0.015, 2026-12-07) less is left to mend (12.2 mm off at the
// last frame without the images' measurement, 4.6 with it): both as found, and the defaults
// within a centimetre.
TEST(HeadingPriorOnTheSurvey, TheImagesMeasureTheLengthOfASlowingStepOverAFloor) {
  const DegenerateStretch slowing{16, 389, 52, true};
  registration::OdometryParams as_found;
  as_found.motion_prior_translation = 0.03;
  const TrackedFrames measured = track_frames(slowing, as_found);
  as_found.photometric_travel_length = false;
  const TrackedFrames kept = track_frames(slowing, as_found);
  const std::size_t last = slowing.count - 1;
  const std::size_t degenerate = frames_where(
      measured, [](const registration::OdometryFrame& frame) { return frame.degenerate; });
  RecordProperty("degenerate_frames", std::to_string(degenerate));
  RecordProperty("last_frame_error_mm", std::to_string(1000 * measured.error_at(last).metres));
  RecordProperty("last_frame_error_mm_held", std::to_string(1000 * kept.error_at(last).metres));
  RecordProperty("ate_mm", std::to_string(1000 * stretch_of(measured).ate));
  RecordProperty("ate_mm_held", std::to_string(1000 * stretch_of(kept).ate));
  EXPECT_GE(degenerate, 25u);  // measured 29: frames 411-440
  // Measured 4.0 mm against 41.7 mm held (ATE 1.4 against 15.1 mm).
  EXPECT_LT(measured.error_at(last).metres, 0.01);
  EXPECT_LT(measured.error_at(last).metres, 0.25 * kept.error_at(last).metres);
  EXPECT_LT(stretch_of(measured).ate, stretch_of(kept).ate / 3);
  EXPECT_LT(track_frames(slowing, {}).error_at(last).metres, 0.01);
}

// Held-out seed 24, frames 1060-1105: the robot slows from 11 to 7 cm a frame towards a far
// wall over the floor, the view degenerate (the far wall's depth the only, weak, hold along the
// travel). With the motion prior's translations at 0.03 ICP's step was pulled a quarter of the
// way back to the motion model's prediction, which lags a robot that changes speed, and the
// images' refinement held it there: in the whole run the steps came out 2-5 mm long each.
// Started here (the heading and speed not yet learned) both are worse than in the run: measured
// 22.1 mm off at the last frame against 33.5 (ATE 10.3 against 14.8 mm).
TEST(HeadingPriorOnTheSurvey, AChangeOfSpeedIsNotPulledBackToThePrediction) {
  const DegenerateStretch slowing{24, 1060, 45, true};
  registration::OdometryParams former;
  former.motion_prior_translation = 0.03;
  const TrackedFrames weaker = track_frames(slowing, {});
  const TrackedFrames pulled = track_frames(slowing, former);
  const std::size_t last = slowing.count - 1;
  RecordProperty("last_frame_error_mm", std::to_string(1000 * weaker.error_at(last).metres));
  RecordProperty("last_frame_error_mm_former", std::to_string(1000 * pulled.error_at(last).metres));
  RecordProperty("ate_mm", std::to_string(1000 * stretch_of(weaker).ate));
  RecordProperty("ate_mm_former", std::to_string(1000 * stretch_of(pulled).ate));
  EXPECT_LT(weaker.error_at(last).metres, 0.8 * pulled.error_at(last).metres);
  EXPECT_LT(stretch_of(weaker).ate, 0.8 * stretch_of(pulled).ate);
}

// The tracked frames after a pose graph of their odometry edges and one loop closure from the
// first frame to the last whose measurement is `loop_error` off the truth (a loop's residual).
TrackedFrames closed_by_a_loop(TrackedFrames tracked, const Eigen::Isometry3d& loop_error) {
  mapping::PoseGraph graph;
  graph.poses = tracked.poses;
  for (const registration::RelativePose& edge : tracked.constraints)
    graph.edges.push_back({edge.from, edge.to, edge.motion, edge.information, false});
  const std::size_t last = tracked.poses.size() - 1;
  const Eigen::Isometry3d loop = tracked.truth.front().inverse() * tracked.truth[last] * loop_error;
  graph.edges.push_back(
      {0, last, loop, registration::prior_information(0.2 * kDegree, 0.005), true});
  mapping::optimize_pose_graph(graph, {.prune_chi2 = 0});
  tracked.poses = graph.poses;
  return tracked;
}

// The same slowing stretch: its 29 degenerate steps, measured by the images to a few tenths of a
// millimetre, enter the pose graph with the images' information in their free directions
// (OdometryParams::photometric_graph_sigma_factor). Closed by a loop 1 cm off along the travel,
// the graph spreads that error over the steps that measured less; without the images' share the
// free directions of the degenerate steps held only the fallback prior's 5 cm, and they took
// the whole centimetre (held-out seed 12's loops bent its degenerate stretches so).
//
// With the motion prior's translations as found (0.03): weaker (0.015, 2026-12-07) the steps
// themselves are nearer the truth and the images' share halves less (span error 3.8 mm with it,
// 6.8 mm without; as found 3.2 and 7.0).
TEST(HeadingPriorOnTheSurvey, ALoopDoesNotBendTheStepsTheImagesMeasured) {
  const DegenerateStretch slowing{16, 389, 52, true};
  registration::OdometryParams as_found;
  as_found.motion_prior_translation = 0.03;
  registration::OdometryParams without_images = as_found;
  without_images.photometric_graph_sigma_factor = 0;
  Eigen::Isometry3d loop_error = Eigen::Isometry3d::Identity();
  loop_error.translation() = Eigen::Vector3d(0, 0, 0.01);  // the camera looks along the travel
  const TrackedFrames held = closed_by_a_loop(track_frames(slowing, as_found), loop_error);
  const TrackedFrames bent = closed_by_a_loop(track_frames(slowing, without_images), loop_error);
  // The error the degenerate steps gather: from the frame before the first degenerate one to the
  // last degenerate one.
  const auto degenerate_span_error = [](const TrackedFrames& tracked) {
    std::optional<std::size_t> first;
    std::size_t last = 0;
    for (std::size_t i = 1; i < tracked.frames.size(); ++i) {
      if (!tracked.frames[i].degenerate) continue;
      if (!first) first = i - 1;
      last = i;
    }
    if (!first) ADD_FAILURE() << "the stretch has no degenerate frame";
    return first ? tracked.error_between(*first, last).metres : 0.0;
  };
  RecordProperty("degenerate_span_error_mm", std::to_string(1000 * degenerate_span_error(held)));
  RecordProperty("degenerate_span_error_mm_without",
                 std::to_string(1000 * degenerate_span_error(bent)));
  RecordProperty("ate_mm", std::to_string(1000 * stretch_of(held).ate));
  RecordProperty("ate_mm_without", std::to_string(1000 * stretch_of(bent).ate));
  EXPECT_LT(degenerate_span_error(held), 0.5 * degenerate_span_error(bent));
  EXPECT_LT(stretch_of(held).ate, 0.5 * stretch_of(bent).ate);
}

// Seed 2, frames 140-170, from a depth camera alone: the corridor entered while speeding up from
// 2 to 7 cm per frame. Without colour nothing measures the step along it and the motion model
// keeps the old speed (1-5 cm off per frame); with a wheeled robot's odometry as the motion prior
// (the true poses with every step 3 % too long, as a worn wheel's radius gives) the steps along
// the corridor are the prior's and every step stays within a centimetre.
// A wheeled robot's odometry of the camera poses `truth`: every step's length times `scale` (a
// wheel's radius off by scale - 1).
std::vector<Eigen::Isometry3d> wheel_poses(const std::vector<Eigen::Isometry3d>& truth,
                                           double scale) {
  std::vector<Eigen::Isometry3d> wheels{truth.front()};
  for (std::size_t i = 1; i < truth.size(); ++i) {
    Eigen::Isometry3d step = truth[i - 1].inverse() * truth[i];
    step.translation() *= scale;
    wheels.push_back(wheels.back() * step);
  }
  return wheels;
}

testing::RenderedSequence render_stretch(const DegenerateStretch& stretch) {
  const synth::World world = synth::make_building(stretch.seed);
  const PinholeIntrinsics kinect{640, 480, 525, 525, 319.5, 239.5};
  return testing::render_sequence(world, testing::survey_poses(world, stretch.first, stretch.count),
                                  kinect);
}

TEST(MotionPrior, AWheelOdometryGivesTheStepADepthCameraAloneCannotMeasure) {
  const DegenerateStretch stretch{2, 140, 30, false};
  const testing::RenderedSequence sequence = render_stretch(stretch);
  const std::vector<Eigen::Isometry3d> wheels = wheel_poses(sequence.truth, 1.03);
  registration::OdometryParams params;
  params.depth_range.units_per_metre = testing::kSynthUnitsPerMetre;
  const compute::Context cpu = compute::Context::cpu();
  const auto track = [&](bool with_prior) {
    registration::RgbdOdometry odometry(cpu, sequence.camera, params);
    TrackedFrames tracked;
    for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
      tracked.frames.push_back(odometry.track(
          sequence.frames[i].depth, nullptr, with_prior ? std::optional(wheels[i]) : std::nullopt));
      EXPECT_EQ(tracked.frames.back().from_motion_prior, with_prior && i > 0);
    }
    tracked.poses = odometry.poses();
    tracked.truth = sequence.truth;
    return stretch_of(tracked);
  };
  const TrackedStretch alone = track(false), with_wheels = track(true);
  EXPECT_GE(with_wheels.degenerate, stretch.count / 3);
  double worst_alone = 0;
  for (const StepError& step : alone.steps) worst_alone = std::max(worst_alone, step.metres);
  EXPECT_GT(worst_alone, 0.02);  // what the prior is for
  for (std::size_t i = 0; i < with_wheels.steps.size(); ++i) {
    EXPECT_LT(with_wheels.steps[i].metres, 0.01) << "frame " << stretch.first + i + 1;
    EXPECT_LT(with_wheels.steps[i].degrees, 0.25) << "frame " << stretch.first + i + 1;
  }
  EXPECT_LT(with_wheels.ate, alone.ate / 3);
  // A prior that is no rigid motion is an Error naming the frame.
  registration::RgbdOdometry odometry(cpu, sequence.camera, params);
  Eigen::Isometry3d sheared = Eigen::Isometry3d::Identity();
  sheared.linear()(0, 1) = 0.5;
  EXPECT_THROW(odometry.track(sequence.frames[0].depth, nullptr, sheared), Error);
}

// Where the views measure every direction (seed 1, frames 226-250: down a room at 3-8 cm a frame)
// the registration overrides a prior whose steps are 30 % too long, and each frame records by how
// much (the wheels' slip made visible); a prior that agrees with the truth is recorded as agreeing.
TEST(MotionPrior, EachFrameRecordsHowFarItsStepIsFromThePriors) {
  const DegenerateStretch room{1, 226, 25, false};
  const testing::RenderedSequence sequence = render_stretch(room);
  registration::OdometryParams params;
  params.depth_range.units_per_metre = testing::kSynthUnitsPerMetre;
  const compute::Context cpu = compute::Context::cpu();
  // The median over the frames of the difference, and of the true step's length.
  const auto median_difference = [&](double scale) {
    const std::vector<Eigen::Isometry3d> wheels = wheel_poses(sequence.truth, scale);
    registration::RgbdOdometry odometry(cpu, sequence.camera, params);
    std::vector<double> differences, steps;
    for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
      const registration::OdometryFrame& frame =
          odometry.track(sequence.frames[i].depth, nullptr, wheels[i]);
      if (i == 0) continue;
      EXPECT_FALSE(frame.degenerate) << "frame " << room.first + i;
      differences.push_back(frame.prior_difference_m);
      steps.push_back(
          (sequence.truth[i].translation() - sequence.truth[i - 1].translation()).norm());
    }
    std::sort(differences.begin(), differences.end());
    std::sort(steps.begin(), steps.end());
    return std::pair(differences[differences.size() / 2], steps[steps.size() / 2]);
  };
  const auto [agreeing, step] = median_difference(1.0);
  const auto [slipping, same_step] = median_difference(1.3);
  RecordProperty("median_step_mm", std::to_string(1000 * step));
  RecordProperty("median_difference_mm_agreeing", std::to_string(1000 * agreeing));
  RecordProperty("median_difference_mm_slipping", std::to_string(1000 * slipping));
  EXPECT_LT(agreeing, 0.001);
  EXPECT_GT(slipping, 0.2 * step);  // 30 % of the step, less what ICP keeps of the prior
  EXPECT_LT(slipping, 0.4 * step);
}

}  // namespace
}  // namespace kartograf
