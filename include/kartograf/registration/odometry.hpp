#pragma once
// Frame-to-frame RGB-D odometry (docs/methods.md M3 steps 1-4, 6) with the M3 paper's drift
// reduction, degeneracy handling, motion-model fallbacks and keyframe selection.
//
// Each new frame n becomes a FramePyramid and is registered by the ICP engine against frame n-1,
// starting from the motion model's prediction, on pyramid levels from the first one at most
// icp_width wide (320x240 of 640x480), never the full resolution, and coarser: the full-resolution
// 4-neighbour normals of Kinect-class depth are mostly noise, and starting at 320x240 was both more
// accurate (0.45 vs 1.5-2.4 mm per frame on the synthetic tour, the same on 7-Scenes) and three
// times faster. Pairs are weighted by depth noise (depth_weighted_finder.hpp).
//
// Every result is judged (registration_check.hpp) with the degeneracy of the frame's own geometry
// (geometric_information.hpp, from the first pyramid level at most information_width wide):
//   - degenerate (a wall and the floor, a corridor without ends): ICP solves with the motion model
//     as a prior about the camera (motion_prior), which decides the weak directions, and image
//     intensity measures them where it can (photometric_refinement, when certain enough);
//   - doubtful (rejected for too few pairs, RMSE or an implausible jump; moved far from the
//     prediction; little overlap): ICP runs again from other starts (rest, the predicted turn or
//     step alone, the prediction turned about the vertical axis, the matched local features'
//     motion when features are given) and the accepted one that fits best is kept; when all are
//     rejected, the frame takes the motion model's prediction and is flagged as a fallback (its
//     pose-graph edge gets only the weak prior information).
//
// Drift reduction (the paper's "iterative estimation every 5 images"): every k-th frame is
// registered again against an anchor, starting from the chained estimate T_a^-1 T_n. The paper's
// anchor is frame n-k; here a re-estimated frame stays the anchor while the next re-estimate is
// within AnchorPolicy's bounds of it (a hand-held camera that lingers is then registered against
// one frame, not chained). When the re-estimate is accepted it replaces frame n's pose, and the
// correction is spread over frames n-k+1..n-1 in proportion to their position (so the trajectory
// has no jump); chaining then continues from the corrected pose. Every registration is kept as a
// RelativePose, so a pose graph (mapping/) can use both the frame-to-frame and the anchor
// measurements. Only two earlier frames are registered against (the previous one and the anchor),
// so the odometry holds at most three frame pyramids with the current one, whatever k.
//
// Information of an edge: InformationModel applied to the geometric information, plus the weak
// prior of an unmeasured step (fallback_sigma_*) so that no direction is entirely free.
//
// Keyframes: frame 0, then any frame that moved more than KeyframePolicy's distance or angle from
// the last keyframe, or is max_interval frames after it, or is a fallback. SLAM uses them as
// loop-closure nodes.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/se3.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/registration/color_gate.hpp"
#include "kartograf/registration/colour_registration.hpp"
#include "kartograf/registration/depth_noise_gate.hpp"
#include "kartograf/registration/depth_weighted_finder.hpp"
#include "kartograf/registration/feature_front_end.hpp"
#include "kartograf/registration/geometric_information.hpp"
#include "kartograf/registration/heading_prior.hpp"
#include "kartograf/registration/icp.hpp"
#include "kartograf/registration/photometric_refinement.hpp"
#include "kartograf/registration/registration_check.hpp"
#include "kartograf/registration/rgbd_frame.hpp"
#include "kartograf/registration/speed_bound.hpp"

namespace kartograf::registration {

enum class OdometryMethod {
  point_to_point,  // the M3 paper's metric (Arun's closed form), closest point in a 3x3 window
  point_to_plane,  // Gauss-Newton on plane distances
  color,           // point-to-plane on pairs that pass the M3 paper's HSI colour gate
  // The M1 paper's planar ICP: the frame's planes (segmentation/plane_extraction.hpp), N points
  // drawn on each (plane_sampling.hpp), point-to-plane ICP on those with k-d tree pairs and the
  // planes' normals. Needs colour on the depth camera's pixel grid (the planes grow in Lab).
  planar,
};

// The ICP parameters of each method; levels[0] runs on the pyramid level of
// OdometryParams::icp_width.
IcpParams odometry_icp_params(OdometryMethod method);
// The methods by the names the CLI and the Python package use: p2p, p2plane, color, planar.
// Throws Error naming `what` and the name otherwise.
OdometryMethod parse_odometry_method(std::string_view name, std::string_view what);

enum class MotionModel { still, velocity, acceleration };

// The frame in which the motion model keeps the camera centre's step. world: a camera that pans
// while its carrier walks straight (hand-held); camera: a camera fixed to a robot that drives
// arcs, whose step turns with it; arc: the last step's length along the direction of travel
// learnt on well-constrained frames (camera frame), turned by half the predicted turn (a wheeled
// robot's chord, the camera over the turning axis), so that a wrong sideways step is not
// repeated; adaptive: whichever of the three predicted the recent well-constrained frames better
// (decides the free directions of degenerate frames, so a wrong choice drifts sideways by the
// step times the turn per frame).
enum class StepFrame { world, camera, arc, adaptive };
std::string_view to_string(StepFrame frame);

struct KeyframePolicy {
  double min_translation = 0.15;  // metres from the last keyframe
  double min_rotation_deg = 10;
  int max_interval = 30;  // frames
};

// The anchor of the re-estimates: held while the next re-estimate stays within these bounds of it,
// so that a camera that lingers or sweeps back and forth is registered against one frame instead
// of chaining a new registration error every k frames. All 0: the anchor is frame n-k, the M3
// paper's rule. On 7-Scenes and SUN3D (the real sets; 0.2-0.8 m tried, docs/slam.md) 0.3-0.5 m
// gave the lowest drift; registration errors grow with the baseline beyond that.
struct AnchorPolicy {
  double max_translation = 0.4;  // metres from the anchor
  double max_rotation_deg = 25;
  int max_interval = 100;  // frames
};

struct OdometryParams {
  OdometryMethod method = OdometryMethod::point_to_plane;
  IcpParams icp = odometry_icp_params(OdometryMethod::point_to_plane);  // keep it the method's
  // ICP's levels[0] runs on the first pyramid level at most icp_width wide and at least
  // min_icp_level: full-resolution normals are noise at any resolution (synthetic tour at
  // 320x240: 60 mm ATE over 60 frames starting at 320x240, 3 mm starting at 160x120).
  int icp_width = 320;
  int min_icp_level = 1;
  int information_width = 80;          // the geometric information's level (80x60 of 640x480)
  ColorGateParams color_gate;          // OdometryMethod::color
  std::size_t points_per_plane = 200;  // OdometryMethod::planar: the M1 paper's N
  // Degenerate frames with colour: measure the weak directions by image intensity
  // (photometric_refinement.hpp) instead of taking the prediction.
  bool photometric_refinement = true;
  PhotometricParams photometric;
  // The directions it measures: balanced eigenvalue below this x the largest, about the centroid
  // (geometric_information.hpp's weak_directions), so the degenerate ones and those the geometry
  // barely constrains. The motion prior pulls the latter toward the prediction as well: on survey
  // seed 4 ICP's answer was 0.2 degrees and 1 cm off in them, the degenerate direction alone could
  // not be refined to the truth, and the refinement of that one direction moved 1.6 cm away
  // from it instead. Only the degenerate ones must be measured by the images (the sigma gate);
  // the others stay held to ICP's answer by what ICP measured (photometric_geometry_weight).
  double photometric_direction_ratio = 0.2;
  // ICP's answer as the refinement's prior: the geometric information of the frame's points (the
  // information_width level) without its degenerate directions (which came from the motion
  // model), with the inlier RMSE as their noise, times this per point, against the images' pixels
  // at PhotometricParams::intensity_sigma (0: the images alone). Without it the stripes and fine
  // grain of the synthetic surveys' textures (aliased by the renderer's point sampling) drew the
  // refined directions 11 cm off on seed 8.
  double photometric_geometry_weight = 10;
  // Degenerate steps from the frame before that the heading prior held (heading_prior), where
  // the geometry leaves the direction of travel free (its translation information along it at
  // most photometric_direction_ratio x the largest, as over a floor alone): after the weak
  // directions' refinement the step's length along the direction of travel is measured once
  // more, by the images alone. That refinement holds the barely constrained directions to ICP's
  // answer and the slide to the heading, and together they held the length near the
  // prediction's: on held-out survey seed 16, frames 421-437 (the robot slowing over a bare
  // floor), the images' own minimum along the heading lay 0.5-6 mm shorter, as did the truth
  // (0.7-6.7 mm), where the refinement had moved 0.1-0.9 mm. Not on large steps (beyond
  // feature_seed_m or feature_seed_deg, where other starts and the features are weighed): on
  // the surveys taken every 10th frame it moved steps of 0.5-1 m by 0.5-1.5 cm, as often away
  // from the truth as towards it.
  bool photometric_travel_length = true;
  // ...kept only where the images fit the measured step: a grey-level RMSE (the refinement's
  // pixels, after it) of at most this. Where they do not (survey seed 5, frames 815-829: a wall
  // and a shelf ahead at an angle, RMSE 1.5-3.3), their minimum along the one direction took up
  // what the others left and lay 2-5 mm off, where the refinement with its holds was within 1-2
  // mm. Set on seed 5's frames (the synthetic camera's noise is about 1 grey level): over its
  // whole run, of the steps it moved by more than 0.5 mm, those at RMSE 1.5 or more
  // came out more than 0.5 mm worse in 35 of 46 (better in 1), those below better in 6 of 17
  // (worse in 3).
  double photometric_travel_max_rmse = 1.5;
  // Degenerate frames: ICP solves with the motion model as a prior (geometric_information.hpp's
  // motion_prior_information), diagonal about the camera, this many times the mean direction's
  // information: it decides the directions the geometry leaves free and barely moves the others
  // (0: off; ICP runs free and its weak directions are replaced by the prediction's about the
  // centroid afterwards, which moved the camera 4 cm sideways per frame when a turn began on the
  // survey of seed 5). 0.03 is the degeneracy threshold's ratio: no stronger than the weakest
  // direction that still counts as constrained. This is the rotations' strength, and the
  // translations' on a frame whose predicted step is large (beyond feature_seed_m or
  // feature_seed_deg: a sequence taken sparsely) or whose step ICP starts from a large motion (the
  // features' at the sequence's start, before the motion model knows the speed), where ICP's
  // answer in a barely constrained direction is more often a neighbouring basin's than a
  // measurement (with 0.01 everywhere, tried 2026-12-07, the surveys taken every 10th frame lost
  // a 0.8 m step at a corridor's start, seed 8's).
  double motion_prior = 0.03;
  // ...and the camera translations' on the other frames: half as strong. The largest eigenvalue is
  // 2-3 times the mean, so at 0.03 the prior pulled a direction just over the threshold a quarter
  // of the way to the prediction, and a robot speeding up or slowing down towards a far wall
  // (held-out survey seed 24, frames 1010-1100: steps of 2-11 cm, the far wall's depth the only
  // hold along the travel) lagged the truth by 2-5 mm a step, 3 cm in ten frames. The rotations
  // keep 0.03: the lag is along the travel, and with the rotations at 0.015 too held-out seed 35
  // slid sideways at its start (SLAM ATE 1.35 cm; 0.68 with them kept). At 0.01 the images'
  // refinement found a basin 3 degrees off on seed 3's corridor (the DegenerateViews test, frame
  // 924), whatever the rotations' (docs/slam.md, "The motion prior's strength").
  double motion_prior_translation = 0.015;
  // Degenerate steps from the frame before: the step's component across the direction of travel
  // is held at zero with the spread learned from the well-constrained steps
  // (heading_prior.hpp), against ICP's information, before the images measure the weak
  // directions, and in the step's pose-graph information along the directions the geometry left
  // free. A wheeled robot's camera moves along its heading, so the slide along a wall ahead is
  // known; a hand-held camera's steps stray across any heading by millimetres, too far for it to
  // matter. Survey seeds 1-10 (2026-12-01): odometry ATE mean 1.39 -> 1.14 cm, SLAM 0.63 -> 0.57
  // cm, no seed above 1 cm; 7-Scenes and SUN3D the same (no degenerate frames).
  bool heading_prior = true;
  // A step from the frame before that turns more than this (degrees) is judged again on the part
  // of the frame that the frame before sees under the step found (geometric_information.hpp's
  // overlapping_points): where that part leaves a direction free, the step is registered again as
  // a degenerate view's (motion prior, images, heading prior), though the whole frame measured
  // every direction. At a wide turn only part of the view is shared, and ICP's pairs there can
  // slide along a wall: on the surveys taken every 10th frame, turns on the spot of 38.8 degrees
  // (seed 2, frame 91: the whole frame's balanced eigenvalue ratio 0.059, the shared part's
  // 0.0004) ended 3-24 cm along the wall from starts 1.7-9 degrees short of the turn, every point
  // of that valley a fixed point of ICP. The first answer stays where the images side with it
  // (better_start's test), and what the motion model and the bounds learn stays with the whole
  // frame's geometry. 15 is where the features are tried (feature_seed_deg): frames 30 Hz apart
  // never turn that far, so they are judged as before. 0: off.
  double overlap_turn_deg = 15;
  bool depth_weighting = true;  // weight pairs by depth noise
  DepthWeightParams depth_weights;
  // ICP's finest pair gate (icp.levels[0].max_distance) widens to `sigmas` times the depth noise
  // at each frame's median depth where that is wider (depth_noise_gate.hpp), on views that are
  // not degenerate: SUN3D's study room, 3.4 m deep, SLAM ATE 2.19 -> 1.83 cm. Rooms seen from
  // 1-2.5 m (7-Scenes, the synthetic surveys' frames but a few) keep the fixed gate. sigmas 0:
  // the fixed gate.
  DepthNoiseGateParams depth_noise_gate;
  // Deep views (those whose gate the depth noise widened, above) with colour registered to depth
  // (colour_registration.hpp): the images measure all six directions of each registration, held
  // to ICP's answer by its geometric information (its inlier RMSE as the noise) times this per
  // point, against the pixels at PhotometricParams::intensity_sigma. At 3.4 m a structured-light
  // camera's depth noise (1.8 cm) leaves a small turn and a sideways slide hard to tell apart;
  // the image edges are as sharp as nearby. SUN3D's study room: SLAM ATE 1.80 -> 1.25 cm (at its
  // 10 measured poses 1.76 -> 1.33). Chosen there: weights 2 / 3 / 5 / 10 gave 1.24 / 1.23 /
  // 1.25 / 1.61 cm. 7-Scenes (not registered, never deep) and the synthetic surveys' few deep
  // frames are as before within 0.02 cm (docs/slam.md, "Deep views measured with the images").
  // 0: off.
  double photometric_deep_weight = 3;
  ColourRegistrationParams colour_registration;
  geometry::DepthRange depth_range;
  // The paper's k: re-estimate every k-th frame against the anchor (frame n-k when the anchor
  // policy's bounds are 0; 0: off).
  int reestimate_interval = 5;
  AnchorPolicy anchor;
  // The prediction (initial guess, and the weak directions of degenerate frames): still: the
  // identity; velocity: the last turn (camera frame) and the last step of the camera centre
  // (world frame); acceleration: that step changed as it changed from the one before.
  MotionModel motion_model = MotionModel::velocity;
  StepFrame step_frame = StepFrame::adaptive;
  // Frame-to-frame acceptance; the correction is relative to the initial guess.
  RegistrationLimits frame_limits{200, 0.1, 0.02, false, 0.3, 20};
  // The frame-to-frame correction may reach the largest step measured on a well-constrained
  // frame so far, where that is beyond frame_limits': a robot can set off from rest to its speed,
  // or stop, within one frame of a sequence taken sparsely (the survey every 10th frame: 0.5 m
  // from rest, found at the best fitness but refused at 0.3 m). Frames 30 Hz apart never step
  // that far, so they keep frame_limits.
  bool corrections_up_to_largest_step = true;
  // Re-estimation acceptance; the correction is relative to the chained estimate. After a
  // fallback, and after degenerate frames since the anchor when the re-estimate's own view is not
  // degenerate, corrections up to frame_limits' are allowed; in the second case one beyond these
  // limits must be confirmed by the images: a grey-level RMSE at the re-estimate below
  // feature_arbitration_ratio times that at the chained estimate (else `unconfirmed`).
  RegistrationLimits reestimate_limits{200, 0.1, 0.02, false, 0.03, 2};
  // An accepted re-estimate's correction, spread over the frames since the last one, rewrites
  // their steps' RelativePose motions too, so the pose graph gets the chain as the odometry keeps
  // it (each step with its own information) beside the re-estimate's edge. With the steps as
  // first measured, the graph weighed each against the re-estimate by informations that those
  // steps overstated: a degenerate step 1.8 cm off sideways at sigma 0.9 mm (held-out survey
  // seed 35, frame 37) outweighed the re-estimate that had corrected it, and the graph was worse
  // than the odometry (SLAM ATE 1.32 against 0.80 cm; on the 320x240 hand-held sequence 1.73
  // against 0.90 cm). False: the steps as measured.
  bool steps_follow_reestimates = true;
  InformationModel information;
  // The prior of an unmeasured step (fallbacks) and the floor of every edge's information.
  double fallback_sigma_m = 0.05;
  double fallback_sigma_deg = 5;
  // A degenerate step whose free directions the images measured enters the pose graph with the
  // images' standard deviation (PhotometricResult::sigma_m of the weak directions' refinement)
  // times this along those directions; without it only the fallback prior held them there, and
  // loops bent exactly the stretches the images had measured (held-out survey seed 12: SLAM
  // error 1.5-2.2 cm over frames 400-800 where the odometry's was 0.4-1.0). The factor widens
  // a bound that counts every textured pixel as an independent measurement. 0: off.
  double photometric_graph_sigma_factor = 3;
  KeyframePolicy keyframes;
  // A registration that was rejected, moved more than recheck_correction_m from the prediction
  // (typical corrections are a few millimetres) or has a fitness under recheck_fitness is checked
  // against ICP from rest, from the predicted turn alone, from its step alone, from the predicted
  // motion turned about the camera's vertical axis by each of recheck_turns_deg, and from the
  // features; the accepted one the pair agrees with best is kept (recheck_by_images below;
  // OdometryFrame::retried or from_features say which).
  double recheck_correction_m = 0.03;
  double recheck_fitness = 0.3;
  std::vector<double> recheck_turns_deg = {-40, -20, 20, 40};
  // Then ICP also starts from the best one's turn, on the spot and with the best one's step length
  // along the heading on that turn's arc (arc_start_from_the_prediction below): ICP measures a turn
  // better than the slide it trades it for. Found on the survey every 10th frame: a turn on the
  // spot taken with a 14 cm slide, and a robot setting off on a turn 24 cm sideways, both at a good
  // fitness.
  bool recheck_from_turn = true;
  // Before the heading prior is ready (its first 20 steps), the arc's start takes its heading from
  // the predicted step, as the features' turn does (features_turn_on_the_arc). Found on survey
  // seed 7 every 10th frame: the robot drives straight for 4 frames, then turns 22 degrees on an
  // arc in a degenerate view; ICP found the turn but kept the straight step's slide, 11 cm
  // sideways (SLAM 2.13 -> 1.40 cm). False: the arc's start waits for the heading prior.
  bool arc_start_from_the_prediction = true;
  // Among those starts, two answers more than the arbitration distance apart
  // (feature_arbitration_m, feature_arbitration_deg) are told apart first by a step the robot can
  // have (on a degenerate view: the speed bound), then by the images where they are decisive: a
  // grey-level RMSE of at most photometric_doubt_rmse and below recheck_images_ratio times the
  // other's. The fitness decides the rest. It is the overlap, and it favours the smaller motion
  // where the geometry leaves a direction free: the survey every 10th frame, seed 4, frame 30 (a
  // turn on the spot of 38.8 degrees over the floor, taken as rest at a fitness of 0.46, RMSE 40,
  // against the turn's 0.29, RMSE 2.0; four frames running) and frame 92 (the turn taken with a 52
  // cm slide at 0.42, RMSE 9.5, against 0.36, RMSE 1.2). At large baselines the images fit nowhere
  // (RMSE 9-20 at every start) and differ by less than that ratio.
  bool recheck_by_images = true;
  double recheck_images_ratio = 0.5;
  // There, an answer's images are judged at the better of the answer itself and the photometric
  // refinement's motion from it, kept or not: a wide turn leaves the images few pixels in common
  // (about 500 of 4800), and their refinement is refused for its spread (max_sigma_m) although
  // the images fit there. Seed 3's survey every 10th frame, frame 19: a turn on the spot of 35.9
  // degrees towards a striped wall; ICP from the prediction found it at a fitness of 0.29, RMSE
  // 13.8 (6.9 refined), and rest won at 0.495, RMSE 22.0, whose images no refinement improves.
  bool recheck_images_refined = true;
  // The fitness that decides the rest (here, and between the features' and the prediction's
  // registrations on a view the geometry constrains: agrees_better) is weighed by the share of the
  // answer's points that agree with the other frame's view rather than lie where that camera saw
  // past them to a surface behind (view_relations, on the geometric information's pyramid
  // level): a contradiction no right motion makes, while a wrong one that shrinks a wide turn
  // overlaps more. Seed 5's survey every 10th frame, frame 29: a turn on the spot of 38.8
  // degrees, as at the four frames before, found from the prediction at a fitness of 0.26 with
  // every point agreeing, lost to another start's 14.2 degrees and 0.31 m sideways at 0.32 with a
  // third of its points seen past. False: the fitness alone.
  bool fitness_weighed_by_view = true;
  // And the contradictions beyond what a right motion shows (contradiction_floor of the points
  // that agree or contradict: noise and edges, 0-3 % on the surveys every 10th frame) count
  // against the answer, each contradiction_weight times what an agreeing point counts for it:
  // fitness x (agreeing - weight x excess) / (agreeing + contradicting). The fitness counts pairs
  // among all the points, so an answer that shrinks a wide turn pairs more (the same floor
  // overlaps whole) while the view it lands in contradicts it. Held-out survey seed 29 every 10th
  // frame, frame 85: a turn on the spot of 38.8 degrees into a corner over a bare floor, found
  // from the prediction at a fitness of 0.29 with 0.1 % of its points contradicting, lost to
  // rest's no turn at 0.55 with 23 % (weighed 0.29 against 0.42; now 0.29 against 0.23). The
  // floor keeps near ties to the fitness (seed 5, frame 104: a straight step at 0.47 with 3 %
  // against a 9.6 degree turn at 0.43 with none), and an answer that puts nearly all its points
  // out of view contradicts nothing, so the contradictions do not decide alone (seed 1, frame
  // 109: the right step at 0.70 with 8 % against a 22 degree turn at 0.14 with none). Weight 0:
  // the agreeing share alone.
  double contradiction_weight = 2;
  double contradiction_floor = 0.05;
  // Among a doubtful registration's starts, each answer turning more than overlap_turn_deg whose
  // shared part with the previous frame is degenerate is registered again from its own start as
  // a degenerate view before the answers are compared (overlap_turn_deg's rule, which otherwise
  // sees only the winner). Seed 5's survey every 10th frame, frame 24: ICP from the prediction
  // had the turn 1.7 degrees off but slid 0.33 m along a wall; another start's 18.2 degrees and
  // 0.55 m won, and its own shared part was not degenerate. False: the winner only.
  bool overlap_every_start = true;
  // A re-estimate whose own view is constrained is judged on the part of it the anchor sees too,
  // and registered again as a degenerate view where that part is degenerate; that answer is kept
  // where the images side with it (survey seed 16, frames 790 -> 795: the anchor saw a blank
  // wall, the re-estimate slid 2.6 cm along it from a chain right to 1 mm). False: judged on the
  // whole view only.
  bool reestimate_on_overlap = true;
  // A doubtful registration from the prediction that beat the features' (attempted on a large
  // predicted motion) is checked against the other starts too.
  bool recheck_after_features = true;
  // On a view the geometry constrains, ICP from the prediction of a large motion (over
  // feature_seed_m or feature_seed_deg) is checked against the other starts even where it is not
  // doubtful. Seed 4's survey every 10th frame, frame 40: the robot ends a turn and drives 0.88 m
  // straight; the turn predicted on, ICP from the prediction settled 12.2 degrees and 0.23 m off
  // at a fitness of 0.38, over recheck_fitness, and no other start was tried. (Before every start
  // was held on its overlap, other starts took turns on the spot with a slide along a wall.)
  bool recheck_large_motions = true;
  // On a degenerate view, ICP from the features' motion of a large predicted motion is weighed
  // (agrees_better) against ICP from the features' turn with the predicted step's length along
  // the heading on that turn's arc: features matched on a floor's tiles or a wall's stripes have
  // the turn (far corners, many of them) but may have the step a tile or two over, which the
  // geometry cannot correct. Seed 8's survey every 10th frame, frame 6: the robot sets off on a
  // 26 degree turn at 0.72 m a frame. The features found the turn with a 0.42 m step half
  // sideways, which the speed bound refused, and ICP from the prediction went straight on (28
  // degrees off); from the features' turn on its arc, 0.2 degrees off.
  bool features_turn_on_the_arc = true;
  // Before the heading prior is ready, the features' step is not weighed against that start where
  // it points more across the direction of travel on its arc (the last step's, with half the
  // turn undone) than along it: a robot drives along its heading, and where the features matched
  // a floor's tiles the images fit their step as well (features_turn_on_the_arc's arbitration).
  // Survey seed 2 every 10th frame, frame 180: the robot sets off from a turn on the spot, every
  // view floor only, and turns 33 degrees at 0.85 m a frame; the features found the turn with a
  // step 0.35 m sideways, and the images fitted it best (grey-level RMSE 15 against 24-30 along
  // that direction): 1.03 m off, 0.31 m from the features' turn on its arc (odometry 54.1 -> 30.4
  // cm, SLAM 28.7 -> 16.3 cm). Only steps longer than feature_arbitration_m are judged.
  bool features_along_the_drive = true;
  // Local features (optional; the features layer's OrbFrontEnd): the current and the previous
  // frame's features are matched, and ICP starts from their motion, when the motion model
  // predicts more than feature_seed_m or feature_seed_deg (beyond the coarsest ICP gate; ICP from
  // the prediction is run too and kept where the pair agrees better with it, as below: features
  // matched on a repeated texture are accepted a tile over), and as one of the other starts of a
  // doubtful registration. Otherwise they cost nothing but a copy of each frame's images. Not
  // for degenerate frames in general: features matched a few centimetres off, worse than the
  // motion model (survey seed 2: 8.5 cm ATE against 2.8).
  // But on a degenerate frame with colour whose weak directions the images did not measure
  // (photometric refinement not kept, or kept with a grey-level RMSE above
  // photometric_doubt_rmse: a step beyond its basin that moved a few millimetres downhill, as
  // where the robot sets off from rest), ICP from the features' motion is also run, and taken
  // when it differs from the prediction's registration by more than feature_arbitration_m or
  // _deg and its images agree better: a grey-level RMSE (after the photometric refinement of both)
  // below feature_arbitration_ratio times the other's (a robot setting off from rest facing a wall,
  // which the motion model takes for standing still).
  std::shared_ptr<const FeatureFrontEnd> features;
  double feature_seed_m = 0.25;
  double feature_seed_deg = 15;
  double feature_arbitration_m = 0.05;
  double feature_arbitration_deg = 2;
  double feature_arbitration_ratio = 0.9;
  // Where the two registrations of a large predicted motion (from the features and from the
  // prediction) end within feature_arbitration_m and _deg of each other on a degenerate view, they
  // differ along the free directions, which only the images measure: the prediction's is kept
  // where its images were refined to a grey-level RMSE below feature_arbitration_ratio times the
  // features'. False: the features' always, as before 2026-12-01 (the survey every 10th frame,
  // frame 980: a turn on the spot taken with the features' 3 cm slide, RMSE 7.9 against 2.5).
  bool feature_ties_by_images = true;
  // Where both registrations of a large predicted motion were refined by the images and end
  // apart, but neither the speed bound nor the images tell them apart (RMSEs within
  // feature_arbitration_ratio of each other), the prediction's is kept: features matched on a
  // degenerate view's repeated pattern fit the images as well as the truth does. False: the
  // features' (the survey of seed 2 every 10th frame, frame 40: a drive at 0.91 m a frame taken
  // for 0.26 m, a floor tile over, at RMSE 15.7 against 16.6).
  bool prediction_keeps_image_ties = true;
  // Where the two registrations of a large predicted motion end apart on a degenerate view, the
  // speed bound does not tell them apart, and neither's images were refined nor fit within
  // photometric_doubt_rmse, the features' is kept: the images' RMSEs then compare two misfits,
  // and the features measured their motion where the prediction only carried the last one on.
  // Found on survey seed 6 every 10th frame, frame 25: the robot sets off from a turn (0.49 m and
  // 2.0 degrees; predicted 0.30 m and 11.4). The features found 0.49 m and 3.9 degrees (RMSE
  // 23.9), the prediction's registration stayed at its turn (16.5) and won on the ratio: 19.6 cm
  // and 9.3 degrees off. Seed 10's tour, frame 25, the same (19.5 cm, 6.7 degrees). False: the
  // images' ratio decides there too.
  bool features_over_misfit_images = true;
  // Grey levels; the synthetic camera's noise is about 1. Also: a photometric refinement whose
  // answer lies beyond the registration's correction limits (frame_limits, reestimate_limits) is
  // kept only at an RMSE within this (docs/slam.md, "An images' correction beyond the limits").
  double photometric_doubt_rmse = 10;
  // Two registrations of a degenerate view that disagree (above): one whose step length lies
  // beyond what the robot's drive can change in the frames since the geometry last measured its
  // speed (this many times the largest change of step length between two consecutive
  // well-constrained frames, once one over feature_arbitration_m was seen; speed_bound.hpp) loses
  // to one within it. Found on the survey taken every 10th frame (frame 27: the features and the
  // images took a checkered floor two tiles over, a step of 0.26 m where the robot, at 0.87 m a
  // frame, made 0.98 m). 0: off.
  double speed_change_margin = 2;
  // The bound also learns from the steps of degenerate views the images measured (photometric):
  // where a sparse sequence starts in a degenerate view (seed 8's survey every 10th frame: frames
  // 1-3), the features' "standing still" on a floor repeating a step ahead otherwise wins at frame
  // 4. False: from well-constrained frames only.
  bool speed_bound_learns_from_images = true;
  // A degenerate view while the robot speeds up or slows down (the last step changed its length or
  // direction by more than feature_arbitration_m): the velocity model lags by that change, and a
  // floor or wall pattern can hold the images at its lag. ICP is also run from the step changed as
  // it last changed (MotionModel::acceleration), and taken where the pair agrees better with it
  // (agrees_better). Frames 30 Hz apart never change by that much.
  bool acceleration_start = true;
  // The same where the features' turn is tried on its arc (features_turn_on_the_arc): that start
  // takes the velocity model's length, which lags a robot speeding up into a turn. ICP also runs
  // from the turn on its arc at the length changed as it last changed, and as much the other way
  // (slowing down), each taken where the images were refined there (photometric) to a grey-level
  // RMSE under acceleration_on_the_arc_ratio times the chosen answer's and the pair agrees better
  // with it (agrees_better). Survey seed 2 every 10th frame, frames 170-190: the robot speeds up
  // into a turn, then slows down, over a tiled floor; the features' turns at the velocity model's
  // length were 0.19-0.52 m off, at the changed lengths 0-3 cm.
  bool acceleration_on_the_arc = true;
  // Chosen between the right steps' ratios on the tours of survey seeds 2, 4, 8 and 13 (0.32-0.67)
  // and a wrong one's on seed 17 (0.81: a view whose images fit nowhere, 22 against 27).
  double acceleration_on_the_arc_ratio = 0.75;
  // A degenerate view whose images the registration left doubtful (not refined, or refined to
  // a grey-level RMSE above photometric_doubt_rmse) while the robot moves fast: the images' fit
  // along the step is narrow (1-2 cm) and has other minima (a floor pattern a tile over), so no
  // start but one near the truth finds it. The grey-level RMSE (intensity_rmse) is evaluated at
  // step lengths 1 cm apart along the registration's own step, over the lengths around the
  // velocity and acceleration models' steps by their difference, within speed_change_margin's
  // bound once it is set, where that range is wider than feature_arbitration_m; ICP starts from
  // the best, kept where the pair agrees better with it (agrees_better). Over the bound's whole
  // range (metres wide after long degenerate stretches) the images took wrong minima.
  bool step_scan = true;
  // The same scan for a robot, once the heading prior is ready (a camera that moves along a
  // learned heading): the candidates lie along the direction of travel (not the registration's
  // own step, which a wrong turn or a slide sets askew), over every length the speed bound admits
  // once it is set (else the models' range, as above), each also turned by up to 1.5 degrees
  // about the learned turning axis in 0.15-degree steps (a 0.3-degree error in the turn moves a
  // floor texture 3 m away by pixels, outside the images' basin), lengths 2 cm apart; they are
  // compared by the images' robust disagreement (intensity_disagreement), in which the true
  // length stood out where the RMSE did not. ICP starts from the best, kept where it is accepted
  // and its disagreement is below feature_arbitration_ratio times the registration's. Also run
  // on the step finally chosen (from any start) and on the straight start below, which then starts
  // along the heading rather than on the predicted turn's arc. Found on the synthetic surveys
  // every 10th frame: a robot speeding up or slowing down by 0.1-0.2 m a frame on a degenerate
  // view (seed 5, into frames 380-400: steps of 0.82-0.98 m taken for 0.58).
  bool heading_scan = true;
  // Where that scan found nothing while the robot drives a large step (beyond feature_seed_m)
  // and the registration's images misfit (a grey-level RMSE above photometric_doubt_rmse), the
  // turn is scanned too: turns up to 40 degrees either side of the registration's (the other
  // starts' widest), 1 degree apart, each with the lengths above along its arc, compared on a
  // quarter of the samples (twice the pixel step); the scan above then runs around the best.
  // Survey seed 8 every 10th frame, into frames 710 and 720: the robot turned 13.8 and 30
  // degrees while driving 0.8 m a frame towards a striped wall 3.3-4.4 m ahead (a degenerate
  // view, the depth at its noisiest); ICP kept 2.9 and 1.2 degrees and the features found no
  // motion, while the images' disagreement over turns and lengths (along the true direction)
  // was lowest within 0.2 degrees and 1 cm of both. Not on a turn on the spot: there a smaller
  // turn keeps more of the frame in view, and the pixels off the image, counted at the cap, made
  // a 7.6 degree turn look better than the true 38.8 (survey seed 4 every 10th frame, frame
  // 1170).
  bool wide_turn_scan = true;
  // A degenerate view's answer, however it was found (the prediction, the features, the scans
  // above), whose images misfit (a grey-level RMSE above free_translation_scan_rmse), is checked
  // against the images along the translations its geometry leaves free (free_translations under
  // 0.1 of the largest; for a robot, once the heading prior knows the turning axis, only those
  // off that axis, levelled), where it leaves one: the answer shifted
  // up to 0.5 m along it, 1 cm apart, with its own turn, compared by the images' disagreement over
  // the pixels every shift keeps in view (PhotometricParams::unseen_at_cap false). The basins
  // there are about as narrow as the spacing, so a shift's disagreement says little about its
  // basin's bottom: ICP starts from the four best shifts at least 4.5 cm apart and from the
  // answer, each first moved to the bottom of its basin (basin_bottom), and the best result is
  // kept where it is accepted and disagrees less than feature_arbitration_ratio times the answer
  // and 0.75 times the shifts' median (a basin, not a slope of pixels leaving the view). The
  // scans above search around the motion models' and the features' steps; features matched a
  // repeated texture a period over, or a change of speed beyond the models, leave the truth
  // outside them (survey seed 3 every 10th frame, tour steps 7 and 8: 11 and 22 cm along its
  // walls striped every 0.221 m). Over a floor alone (two free directions) the scan found wrong
  // minima (seed 2's tour every 10th frame 14 -> 76 cm): it is not run there.
  bool free_translation_scan = true;
  // Three times the synthetic camera's grey-level noise (about 1): the answers the images fit
  // need no scan, which costs five registrations (on the 30 Hz survey of seed 4, whose view is
  // degenerate in 544 of 1340 frames, the odometry's time 25 -> 30 ms a frame; 40 ms scanning
  // every degenerate answer, with the tours every 10th frame a little worse: SLAM ATE summed
  // over seeds 1-10 49.9 against 48.1 cm).
  double free_translation_scan_rmse = 3.0;
  // A degenerate view whose images the registration left doubtful and whose features found no
  // motion, while the prediction is large (beyond feature_seed_m or feature_seed_deg, where the
  // features are tried) and turns more than feature_arbitration_deg (a start apart from the
  // prediction's, as the arbitration tells answers apart): ICP is also run from the
  // predicted step without its turn, kept where better_start prefers it (the speed bound, then
  // decisive images, then the fitness weighed by the view). A turn can end within one frame of a
  // sparse sequence; from the predicted turn the wall ahead lands beside its own points, ICP
  // pairs the floor alone, which no turn about the vertical moves, and the turn stays. Found on
  // survey seed 5 every 10th frame, frame 38: a 22 degree turn that ended as the robot drove
  // through a doorway, kept at a fitness of 0.36 (0.48 from the straight start, 0.07 degrees
  // off). The same on seed 10's, frame 93: the robot stopped turning (6.3 degrees the step
  // before) and sped up straight towards a wall beyond the depth's range over a floor whose grain
  // runs along the motion; the kept 6 degree turn set the next two frames wrong (from 15 degrees
  // until 2026-12-04, which that turn was under). Frames 30 Hz apart never make such a step (with
  // any turn over 2 degrees it had run on 3 of survey 5's 1319 frames and moved the odometry).
  bool straight_start_on_silent_images = true;
};

// A measured (or, for fallbacks, predicted) motion between two frames, for a pose graph:
// motion = T_from^-1 T_to, information for the right perturbation of that motion.
struct RelativePose {
  std::size_t from = 0;
  std::size_t to = 0;
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  se3::Matrix6d information = se3::Matrix6d::Identity();
  bool fallback = false;  // predicted by the motion model, not measured
};

// Everything the odometry decided about one frame.
struct OdometryFrame {
  std::size_t index = 0;
  // Against frame index-1 (frame 0: none). When a registration from another start than the
  // prediction fitted better (OdometryParams::recheck_*), this is that one; `retried` says so.
  std::optional<RegistrationReport> previous;
  bool retried = false;
  // The accepted registration started from the matched features' motion (OdometryParams::features).
  bool from_features = false;
  bool fallback = false;  // every attempt rejected: the pose comes from the motion model
  // Against the anchor (every k-th frame; frame index-k under the paper's rule).
  std::optional<RegistrationReport> reestimate;
  std::size_t reestimate_anchor = 0;  // the frame it was registered against
  // The frame's geometry leaves some direction free: weak directions came from the prediction,
  // or from image intensity when `photometric`.
  bool degenerate = false;
  // Degenerate only in the part of the frame the frame before sees (a wide turn;
  // OdometryParams::overlap_turn_deg); eigenvalue_ratio is then that part's.
  bool degenerate_overlap = false;
  // The re-estimate was registered again as a degenerate view: the part of this frame its anchor
  // sees leaves directions free (OdometryParams::reestimate_on_overlap).
  bool reestimate_degenerate_overlap = false;
  bool photometric = false;
  // A deep view whose registration the images measured with the geometry
  // (OdometryParams::photometric_deep_weight).
  bool deep_photometric = false;
  // Whether the colour is registered to the depth, as judged up to this frame
  // (colour_registration.hpp), and the edge contrast it was judged on (0: no colour yet).
  ColourRegistration colour_registration = ColourRegistration::undecided;
  double colour_edge_contrast = 0;
  // The step's slide across the robot's heading was held by the heading prior
  // (OdometryParams::heading_prior) with this spread (metres; 0: it did not hold it).
  double heading_sigma_m = 0;
  // The step came from ICP started at the step changed as it last changed
  // (OdometryParams::acceleration_start).
  bool accelerated = false;
  // Two registrations disagreed and one was refused for a change of speed beyond the robot's
  // (OdometryParams::speed_change_margin).
  bool speed_bounded = false;
  // The step came from ICP started at the step length whose images fit best
  // (OdometryParams::step_scan).
  bool scanned = false;
  double eigenvalue_ratio = 0;  // of the frame's geometric information
  // The frame the prediction kept the camera centre's step in (OdometryParams::step_frame).
  StepFrame step_frame = StepFrame::world;
  bool keyframe = false;
  // The prediction was the motion prior's (this frame and the one before had one).
  bool from_motion_prior = false;
  // Where from_motion_prior: how far the step the registration took (before any re-estimate) is
  // from the prior's, in translation (m) and rotation (degrees). Large: the wheels slipped, the
  // prior's mount or clock is off, or the registration went wrong.
  double prior_difference_m = 0, prior_difference_deg = 0;
  double seconds = 0;  // processing time of track() (no file I/O)
};

class RgbdOdometry {
 public:
  // Throws Error on invalid intrinsics, depth range or parameters.
  RgbdOdometry(const compute::Context& context, const PinholeIntrinsics& camera,
               OdometryParams params = {});
  ~RgbdOdometry();
  RgbdOdometry(RgbdOdometry&&) noexcept;
  RgbdOdometry& operator=(RgbdOdometry&&) noexcept;

  // Registers the next frame (depth in params.depth_range's units; colour on the depth camera's
  // pixel grid, required by OdometryMethod::color and ::planar). Returns its report; poses()
  // grows by one. Throws Error when the method needs colour and there is none. motion_prior: the
  // camera-to-world pose another sensor gives this frame (RgbdImages::motion_prior); where this
  // frame and the one before both have one, their relative motion is the prediction (the start
  // of ICP and what a degenerate view's free directions take) instead of the motion model's.
  // Throws Error on a prior that is not a finite rigid motion.
  const OdometryFrame& track(const DepthImage& depth, const RgbImage* color = nullptr,
                             const std::optional<Eigen::Isometry3d>& motion_prior = std::nullopt);

  std::size_t frame_count() const { return poses_.size(); }
  // Camera-to-world; frame 0 is the identity. A re-estimate updates the last k poses.
  const std::vector<Eigen::Isometry3d>& poses() const { return poses_; }
  const std::vector<OdometryFrame>& frames() const { return frames_; }
  const std::vector<RelativePose>& constraints() const { return constraints_; }
  const std::vector<std::size_t>& keyframes() const { return keyframes_; }
  const OdometryParams& params() const { return params_; }
  // Frame pyramids held: the current frame, the previous one and the anchor of the next
  // re-estimate (at most 3, whatever reestimate_interval and the anchor policy).
  std::size_t kept_pyramids() const { return ring_.size(); }
  // The last tracked frame's pyramid: the levels ICP and the geometric information read, with
  // normals from the finest of them on (a tracker that registers the same frame elsewhere reads
  // it instead of building its own). Throws Error before the first frame.
  const FramePyramid& latest_pyramid() const;

 private:
  struct Attempt {
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();  // after degeneracy handling
    double inlier_rmse = 0;
    bool photometric = false;  // weak directions measured by intensity
    // Grey-level RMSE of the images at the motion (degenerate frames with colour; 0: not measured).
    double photometric_rmse = 0;
    RegistrationReport report;
    // The heading prior's information on the step (zero where it did not hold it), its spread.
    se3::Matrix6d across_heading = se3::Matrix6d::Zero();
    double heading_sigma_m = 0;
    bool accelerated = false;  // OdometryFrame::accelerated
    bool scanned = false;      // OdometryFrame::scanned
    // Grey-level RMSE of the images at the motion against the target (or after its refinement,
    // where lower: recheck_images_refined), computed once when a doubtful registration's starts
    // are compared (images_rmse_at; < 0: not yet; 0: no images).
    double start_rmse = -1;
    // Grey-level RMSE after the photometric refinement from the motion, kept or not (0: not run).
    double refined_rmse = 0;
    // The images' standard deviation of the weak directions' refinement where it was kept (m).
    double photometric_sigma_m = 0;
    bool deep_photometric = false;  // OdometryFrame::deep_photometric
  };
  // Registers the current frame against an earlier one.
  Attempt register_frames(std::size_t target, const Eigen::Isometry3d& initial,
                          const RegistrationLimits& limits);
  se3::Matrix6d information_of(const Attempt& attempt) const;
  // OdometryParams::photometric_graph_sigma_factor: the images' share of information_of.
  se3::Matrix6d images_information(const Attempt& attempt,
                                   std::span<const se3::Vector6d> free_directions) const;
  // OdometryParams::photometric_deep_weight on an accepted registration of a deep view that is
  // not degenerate (no change to any other attempt).
  void measure_deep_view(Attempt& attempt, std::size_t current, std::size_t target,
                         const Eigen::Isometry3d& initial, const RegistrationLimits& limits) const;
  // OdometryParams::heading_prior on a degenerate step from the frame before.
  void hold_across_heading(Attempt& attempt, const MotionPriorStrength& prior) const;
  // OdometryParams::photometric_travel_length on an attempt whose weak directions the images
  // refined, from `initial`.
  void measure_travel_length(Attempt& attempt, const Eigen::Isometry3d& initial,
                             const RegistrationLimits& limits, const PhotometricFrame& source,
                             const PhotometricFrame& target) const;
  void track_previous(OdometryFrame& frame);
  // The registration against the previous frame, from the prediction, rest or the features.
  Attempt attempt_previous(const Eigen::Isometry3d& predicted, OdometryFrame& frame);
  // attempt_previous before the chosen step's length is measured along the heading.
  Attempt chosen_previous(const Eigen::Isometry3d& predicted, OdometryFrame& frame);
  // OdometryParams::acceleration_start: `attempt` (from `predicted`) or ICP from the step changed
  // as it last changed, whichever the pair agrees better with.
  Attempt accelerating_if_better(StepFrame step_frame, const Eigen::Isometry3d& predicted,
                                 Attempt attempt);
  // OdometryParams::straight_start_on_silent_images: `attempt` (from `predicted`) or ICP from the
  // predicted step without its turn, whichever better_start prefers.
  Attempt straight_if_better(std::size_t previous, const Eigen::Isometry3d& predicted,
                             Attempt attempt, OdometryFrame& frame);
  // A degenerate view whose images did not measure, or fit far apart.
  bool images_left_open(const Attempt& attempt) const;
  // OdometryParams::step_scan: ICP from the step length along the attempt's direction whose images
  // fit best, over the lengths the robot can have stepped, where the pair agrees better with it
  // (scanned set); none where that range is narrow or it does not.
  std::optional<Attempt> scan_step_lengths(StepFrame step_frame, const Eigen::Isometry3d& predicted,
                                           const Attempt& attempt);
  // OdometryParams::heading_scan: whether it applies to the frame being tracked.
  bool scans_along_heading() const;
  // OdometryParams::heading_scan: ICP from the step along the heading whose images disagree least,
  // where it disagrees clearly less than `attempt` (scanned set); none otherwise.
  std::optional<Attempt> scan_along_heading(StepFrame step_frame,
                                            const Eigen::Isometry3d& predicted,
                                            const Attempt& attempt);
  // The lengths scan_along_heading tries: the speed bound's once it is set, else
  // plausible_step_lengths.
  std::pair<double, double> drive_step_lengths(StepFrame step_frame,
                                               const Eigen::Isometry3d& predicted) const;
  // scan_along_heading's candidates around `centre`: ICP from the one whose images disagree
  // least, where it disagrees clearly less than `attempt`.
  std::optional<Attempt> scan_around(const Eigen::Isometry3d& centre, const HeadingStepGrid& grid,
                                     const Attempt& attempt);
  // OdometryParams::free_translation_scan: ICP from the shifts of `attempt` along the free
  // translations whose images disagree least, the best where it disagrees clearly less than
  // `attempt` (scanned set); none otherwise.
  std::optional<Attempt> scan_free_translations(const Attempt& attempt);
  // The translations the current geometry leaves free (camera frame, unit), levelled for a robot.
  std::vector<Eigen::Vector3d> free_translations_now() const;
  // `start` shifted along `direction`, within `reach`, to where the images (over the pixels every
  // shift sees) disagree least, 2 mm apart.
  Eigen::Isometry3d basin_bottom(const Eigen::Isometry3d& start, const Eigen::Vector3d& direction,
                                 double reach) const;
  // OdometryParams::wide_turn_scan: the step among `grid`'s turned up to 40 degrees whose images
  // disagree least (none where the rule does not apply).
  std::optional<Eigen::Isometry3d> widest_turn_fit(const Eigen::Isometry3d& predicted,
                                                   const HeadingStepGrid& grid,
                                                   const Attempt& attempt) const;
  // The images' intensity_disagreement of the current frame against `target` at each motion,
  // sampled every `pixel_step` pixels (PhotometricParams::unseen_at_cap as given).
  std::vector<double> images_disagreement(std::size_t target,
                                          std::span<const Eigen::Isometry3d> motions,
                                          int pixel_step, bool unseen_at_cap = true) const;
  // The range of step lengths scanned: around the velocity and acceleration models' steps by
  // their difference, within the speed bound once it is set.
  std::pair<double, double> plausible_step_lengths(StepFrame step_frame,
                                                   const Eigen::Isometry3d& predicted) const;
  // The step's length by the velocity model (`predicted`) and by the acceleration model.
  struct ModelStepLengths {
    double velocity = 0, accelerated = 0;
  };
  ModelStepLengths model_step_lengths(StepFrame step_frame,
                                      const Eigen::Isometry3d& predicted) const;
  // A registration worth checking from other starts (OdometryParams::recheck_*).
  bool is_doubtful(const Attempt& attempt) const;
  std::vector<Eigen::Isometry3d> other_starts(const Eigen::Isometry3d& predicted) const;
  // Starts at `motion`'s turn: with no step, and with its step's length along the heading.
  std::vector<Eigen::Isometry3d> starts_from_turn(const Eigen::Isometry3d& motion) const;
  // The best fit of `first` (from the prediction) and ICP from other_starts() and the features.
  Attempt best_of_other_starts(std::size_t previous, const Eigen::Isometry3d& predicted,
                               Attempt first, OdometryFrame& frame);
  bool is_large(const Eigen::Isometry3d& motion) const;
  // Whether the pair agrees better with `challenger` (accepted) than with `incumbent`, ICP from
  // two starts, when they differ by more than feature_arbitration_m or _deg: on a degenerate
  // pair the images (grey-level RMSE below feature_arbitration_ratio times the other's), since
  // the fitness cannot tell a slide along the free direction; otherwise the fitness.
  bool agrees_better(const Attempt& challenger, const Attempt& incumbent);
  // Whether `other` replaces `best` among a doubtful registration's starts
  // (OdometryParams::recheck_by_images).
  bool better_start(std::size_t target, Attempt& other, Attempt& best);
  double images_rmse_at(std::size_t target, Attempt& attempt) const;
  // Whether the images decide for the challenger (true) or the incumbent (false): the better
  // fit's grey-level RMSE is at most photometric_doubt_rmse and under recheck_images_ratio
  // times the other's.
  std::optional<bool> images_decide(std::size_t target, Attempt& challenger,
                                    Attempt& incumbent) const;
  // The step from the frame before judged again on the part of the frame that frame sees
  // (OdometryParams::overlap_turn_deg), and registered again where that part is degenerate.
  Attempt judged_on_the_overlap(const Eigen::Isometry3d& predicted, OdometryFrame& frame,
                                Attempt attempt);
  // Whether `attempt` is judged on what the frames share: accepted, turning by more than
  // overlap_turn_deg, on a view the whole frame constrains.
  bool turns_wide_on_a_constrained_view(const Attempt& attempt) const;
  // Whether `held`, registered again as a degenerate view, replaces `first`: accepted, and the
  // images do not side with `first`.
  bool overlap_answer_stands(std::size_t previous, Attempt& first, Attempt& held) const;
  // One of a doubtful registration's answers, ICP from `start`, held on its shared part
  // (OdometryParams::overlap_every_start).
  Attempt held_on_its_overlap(std::size_t previous, const Eigen::Isometry3d& start,
                              Attempt attempt);
  // Where the part of the current frame that `motion` maps into frame `target`'s view is
  // degenerate: ICP from `start` again as a degenerate view's on that part, with its pose-graph
  // information (held_on_its_overlap, register_against_anchor).
  struct HeldOnOverlap {
    Attempt attempt;
    se3::Matrix6d information;
  };
  std::optional<HeldOnOverlap> held_where_degenerate(std::size_t target,
                                                     const Eigen::Isometry3d& motion,
                                                     const Eigen::Isometry3d& start,
                                                     const RegistrationLimits& limits);
  // The geometric information of frame `current`'s points that `motion` maps into the view of
  // frame `target` (both at the information level).
  GeometricInformation overlap_geometry(std::size_t current, std::size_t target,
                                        const Eigen::Isometry3d& motion);
  // Frames `current`'s and `target`'s pyramid levels of the geometric information, on which what
  // the two frames share is judged (overlap_geometry, view_weighed_fitness), and the depth gap
  // within which a point counts as on the other frame's surface there.
  std::pair<const PyramidLevel&, const PyramidLevel&> information_levels(std::size_t current,
                                                                         std::size_t target);
  double overlap_gap_m() const;
  // The geometric information of an information-level cloud (of the points `keep` marks; empty:
  // all) with the odometry's depth weights and degeneracy threshold.
  GeometricInformation level_geometry(const CloudView& level,
                                      std::span<const std::uint8_t> keep = {}) const;
  // Grey-level RMSE of this frame's images moved by each motion onto `target`'s (intensity_rmse);
  // empty where either frame has no colour.
  std::vector<double> images_rmse(std::size_t target,
                                  std::span<const Eigen::Isometry3d> motions) const;
  // Between two registrations of a degenerate pair: the challenger's verdict where the speed
  // bound admits one and not the other (and OdometryFrame::speed_bounded is set), else none.
  std::optional<bool> speed_decides(const Attempt& challenger, const Attempt& incumbent);
  // Whether two registrations differ by at most feature_arbitration_m and _deg.
  bool within_arbitration(const Attempt& a, const Attempt& b) const;
  // Within that distance on a degenerate view: whether `challenger`'s images were refined to a
  // grey-level RMSE below feature_arbitration_ratio times `incumbent`'s.
  bool images_tell_apart(const Attempt& challenger, const Attempt& incumbent) const;
  // A large predicted motion's registration from the prediction against ICP from the features'
  // motion: whether the prediction's is kept (agrees better, told apart by the images within the
  // arbitration distance, or beyond it a tie the refined images cannot break).
  bool keeps_prediction(const Attempt& predicted, const Attempt& seeded);
  // OdometryParams::features_over_misfit_images: the two registrations end apart on a degenerate
  // view where neither the speed bound nor the images (neither refined, both above
  // photometric_doubt_rmse) can tell them apart.
  bool neither_images_fit(const Attempt& predicted, const Attempt& seeded) const;
  // Whether the attempt's step into the frame being tracked is one the robot's drive allows
  // (OdometryParams::speed_change_margin).
  bool speed_allows(const Attempt& attempt) const;
  // The attempt's fitness weighed by how its points, mapped into `target`'s view, agree with
  // what that camera saw or lie where it saw past them (fitness_weighed_by_view,
  // contradiction_weight).
  double view_weighed_fitness(std::size_t target, const Attempt& attempt);
  // Whether the challenger's registration onto `target` fits better than the incumbent's: by
  // fitness, weighed by the view where they lie far apart (fitness_weighed_by_view).
  bool fits_better(std::size_t target, const Attempt& challenger, const Attempt& incumbent);
  // A degenerate frame's registration from the prediction against ICP from the features' motion:
  // the latter when the two disagree and its images agree better (photometric_rmse).
  std::optional<Attempt> arbitrate_by_intensity(const Attempt& predicted);
  // ICP against the previous frame from its matched features' motion (OdometryParams::features),
  // when accepted.
  std::optional<Attempt> register_from_features();
  // OdometryParams::features_turn_on_the_arc: `seeded`, or ICP from its turn with the predicted
  // step's length along the arc, whichever the pair agrees better with.
  Attempt features_turn_on_the_arc(StepFrame step_frame, const Eigen::Isometry3d& predicted,
                                   Attempt seeded);
  // OdometryParams::acceleration_on_the_arc: `chosen`, or ICP from `start` (the features' turn)
  // with a step along `travel` (a unit direction on its arc) of the predicted length changed as
  // it last changed, or as much the other way, where the images fit it clearly better.
  Attempt speeding_up_on_the_arc(StepFrame step_frame, const Eigen::Isometry3d& predicted,
                                 Eigen::Isometry3d start, const Eigen::Vector3d& travel,
                                 Attempt chosen);
  // OdometryParams::features_along_the_drive: `step` (longer than feature_arbitration_m) points
  // more across `travel` (a unit direction) than along it.
  bool across_the_drive(const Eigen::Isometry3d& step, const Eigen::Vector3d& travel) const;
  // The unit direction of travel on `step`'s arc: the heading prior's once it is ready, before
  // that the last step's direction with half its turn undone; zero after a step on the spot.
  Eigen::Vector3d travel_on_arc(const Eigen::Isometry3d& step) const;
  void keep_images_for_features(const DepthImage& depth, const RgbImage* color);
  void reestimate(OdometryFrame& frame);
  // The motions of the step constraints to frame `first` and later, from the poses as they are.
  void rechain_steps_from(std::size_t first);
  // The re-estimate of the current frame against `anchor` from `chained`, with its pose-graph
  // information, judged on what the anchor sees (OdometryParams::reestimate_on_overlap).
  struct AnchoredAttempt {
    Attempt attempt;
    se3::Matrix6d information;
    bool degenerate_overlap = false;  // registered again as a degenerate view
  };
  AnchoredAttempt register_against_anchor(std::size_t anchor, const Eigen::Isometry3d& chained,
                                          const RegistrationLimits& limits);
  struct ReestimateLimits {
    RegistrationLimits limits;
    // After degenerate frames: a correction beyond reestimate_limits must be confirmed by the
    // images (images_confirm).
    bool needs_images = false;
  };
  ReestimateLimits reestimate_limits(const OdometryFrame& frame, std::size_t anchor) const;
  bool images_confirm(std::size_t anchor, const Eigen::Isometry3d& motion,
                      const Eigen::Isometry3d& chained) const;
  // Whether frame n, just re-estimated, becomes the next anchor (AnchorPolicy).
  bool moves_anchor(std::size_t n) const;
  bool is_keyframe(const OdometryFrame& frame) const;
  FramePyramid& pyramid_of(std::size_t frame);
  // The slot holding `frame`'s pyramid, colour and plane samples; throws when it is not kept.
  std::size_t slot_of(std::size_t frame) const;
  // A slot for a new frame: one holding neither the previous frame nor the re-estimation anchor.
  std::size_t claim_slot(std::size_t frame);

  struct PlanarFrames;  // OdometryMethod::planar: the plane samples of the kept frames

  const compute::Context* context_;
  OdometryParams params_;
  int finest_level_;       // pyramid level of icp.levels[0]
  int information_level_;  // pyramid level of the geometric information
  RgbdPyramidBuilder builder_;
  IcpEngine engine_;
  static constexpr std::size_t kNoFrame = static_cast<std::size_t>(-1);
  std::vector<FramePyramid> ring_;        // the frames still needed (claim_slot)
  std::vector<PhotometricFrame> images_;  // their images (photometric refinement), same slots
  ColourRegistrationCheck colour_check_;  // OdometryParams::colour_registration
  std::vector<std::size_t> slot_frames_;  // the frame each slot holds (kNoFrame: none yet)
  GeometricInformation geometry_;         // of the frame being tracked
  const DepthImage* depth_ = nullptr;     // of the frame being tracked
  DepthImage previous_depth_;             // OdometryParams::features: the previous frame's images
  RgbImage previous_color_;
  std::shared_ptr<const FeatureDescription> current_features_;  // made on demand
  std::shared_ptr<const FeatureDescription> previous_features_;
  const RgbImage* color_ = nullptr;
  std::vector<Eigen::Isometry3d> poses_;
  // The motion priors given to track() with the frame being tracked and the one before.
  std::optional<Eigen::Isometry3d> prior_before_, prior_now_;
  // The relative motion of the frame to predict from the motion priors, when it and the frame
  // before have one.
  std::optional<Eigen::Isometry3d> prior_motion() const;
  // The step frame.index took (poses_' last two) against the prior's step, into `frame`.
  void record_prior_difference(const Eigen::Isometry3d& prior_step, OdometryFrame& frame) const;
  std::vector<OdometryFrame> frames_;
  std::vector<RelativePose> constraints_;
  std::vector<std::size_t> keyframes_;
  std::size_t anchor_ = 0;  // the next re-estimate's anchor (AnchorPolicy)
  std::unique_ptr<PlanarFrames> planar_;
  // The motion model's T_{n-1}^-1 T_n for the next frame n, from the last poses, with the step
  // kept in the world or the camera frame, or on an arc (StepFrame).
  Eigen::Isometry3d predict(StepFrame frame) const;
  Eigen::Isometry3d predict(StepFrame frame, MotionModel model) const;
  StepFrame step_frame_in_use() const;
  // StepFrame::adaptive: each frame's mean squared step error (metres^2, decaying) of the three
  // predictions on frames whose geometry measured every direction.
  void score_step_frames(const Eigen::Isometry3d& measured);
  double world_step_error_ = 0;
  double camera_step_error_ = 0;
  double arc_step_error_ = 0;
  // StepFrame::arc's direction of travel with no turn, and OdometryParams::heading_prior.
  HeadingPrior heading_prior_;
  // OdometryParams::corrections_up_to_largest_step: the largest step of a well-constrained frame.
  double largest_step_m_ = 0;
  // OdometryParams::speed_change_margin.
  SpeedBound speed_bound_;
  bool speed_bound_decided_ = false;  // for the frame being tracked (OdometryFrame::speed_bounded)
  // Whether the frame being tracked predicts a large step (is_large), and the motion prior's
  // strengths for a registration of it (OdometryParams::motion_prior, motion_prior_translation).
  bool large_step_ = false;
  MotionPriorStrength motion_prior_for(bool step_from_previous,
                                       const Eigen::Isometry3d& initial) const;
  RegistrationLimits frame_limits_now() const;
  // ICP's finest gate for this frame's registrations (OdometryParams::depth_noise_gate).
  void set_finest_gate(const DepthImage& depth);
};

}  // namespace kartograf::registration
