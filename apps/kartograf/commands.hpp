#pragma once
// The CLI's subcommands. Each returns the process exit code and throws kartograf::Error on
// failure (main reports it).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "kartograf/compute/backend.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/pipeline/tracking_choices.hpp"

namespace CLI {
class App;
}  // namespace CLI

namespace kartograf::cli {

// Every backend and its devices in detail.
int run_devices_command(std::ostream& out);

// One line per backend: available with its devices, or why not.
void print_backend_summary(std::ostream& out, const std::vector<compute::BackendStatus>& backends);

struct DemoOptions {
  std::filesystem::path out_dir = "kartograf-demo";
  std::string backend = "auto";
  std::string backend_source = "--backend";  // names the setting in errors
  bool force = false;
};

// Renders a depth frame of the default synthetic world (synth/), back-projects it, estimates
// normals and writes pictures and a cloud.
int run_demo_command(const DemoOptions& options, std::ostream& out);

// `eval traj|planes|rooms|semantic GT PREDICTION`: add_eval_command registers the subcommands
// (parsing fills options); run_eval_command prints the chosen metric's table or JSON object.
struct EvalOptions {
  std::string metric;  // the subcommand given
  std::filesystem::path ground_truth, prediction;
  bool json = false;
  double delta = 1;                   // traj
  std::string delta_unit = "frames";  // traj
  bool sim3 = false;                  // traj
  double max_difference = 0.02;       // traj
  std::size_t worst_steps = 0;        // traj: 0 lists none
  std::string offset = "0";           // traj: seconds added to the estimate's stamps, or "auto"
  double threshold = 0.8;             // planes
  double resolution = 0.05;           // rooms: metres per cell
};
CLI::App* add_eval_command(CLI::App& app, EvalOptions& options);
int run_eval_command(const EvalOptions& options, std::ostream& out);

// `synth --out DIR ...`: a synthetic RGB-D data set with exact ground truth; progress on err.
struct SynthOptions {
  std::filesystem::path out_dir;
  std::uint64_t seed = 1;
  int frames = 300;
  bool frames_given = false;         // else a survey takes as many as its tour needs
  std::string trajectory = "robot";  // robot | handheld
  int room = 0;                      // handheld: room id, 0 = the largest
  double look_around_deg = 30.0;     // robot: the yaw sweep inside each room
  double pitch_deg = 12.0;           // robot: the camera's downward pitch
  bool survey = false;               // robot: a full turn in every room (TourParams::survey)
  PinholeIntrinsics intrinsics{640, 480, 525.0, 525.0, 319.5, 239.5};
  bool intrinsics_given = false;  // any of --fx --fy --cx --cy; else scaled to --width/--height
  bool no_noise = false;
  bool force = false;
  int threads = 0;
};
CLI::App* add_synth_command(CLI::App& app, SynthOptions& options);
int run_synth_command(const SynthOptions& options, std::ostream& out, std::ostream& err);

// How every command that takes a sequence folder reads it (sequence_run.hpp:
// add_sequence_input_options; io::SequenceParams).
struct SequenceInputOptions {
  std::string camera;                           // --camera; empty: the folder's
  double depth_scale = 0;                       // --depth-scale [units per metre]; 0: the layout's
  std::size_t first = 0, frames = 0, step = 1;  // --first, --frames (0: all), --step
  bool skip_bad_frames = false;
};

// Options shared by `odometry`, `slam` and `map` (sequence_run.hpp).
struct SequenceRunOptions {
  std::filesystem::path sequence;  // a folder in any supported layout (io/sequence_detect.hpp)
  SequenceInputOptions input;
  // Defaults and meaning: pipeline/tracking_choices.hpp.
  std::string method = pipeline::TrackingChoices{}.method;
  std::string backend = "auto";
  std::string backend_source = "--backend";  // names the setting in errors
  int reestimate_interval = pipeline::TrackingChoices{}.reestimate_interval;
  // One TrackingChoices for both ends: begin and end of two temporaries would be no range.
  std::vector<double> anchor_bounds = [] {
    const auto bounds = pipeline::TrackingChoices{}.anchor_bounds;
    return std::vector<double>(bounds.begin(), bounds.end());
  }();
  std::string tracking = pipeline::TrackingChoices{}.tracking;
  double model_voxel = pipeline::TrackingChoices{}.model_voxel;
  std::string motion_prior;  // --motion-prior: another sensor's camera poses (empty: none)
  // --prior-time-offset: seconds the prior file's clock is ahead of the frames' timestamps, or
  // "auto" (measured before the run: calibrate_prior_clock).
  double prior_time_offset = 0;
  bool prior_time_offset_auto = false;
  // --pose-mount x,y,z,qx,qy,qz,qw: the camera's pose in the body whose poses a --poses or
  // --motion-prior file gives (empty: the file gives the camera's own).
  std::vector<double> pose_mount;
  bool progress = true;
};

// `odometry SEQUENCE --out traj.txt`: frame-to-frame odometry, a TUM trajectory and a summary
// (ATE when the sequence has ground truth); --stats writes per-frame statistics as JSON.
struct OdometryOptions {
  SequenceRunOptions run;
  std::filesystem::path out, stats;
  bool force = false;  // replace existing files
};
CLI::App* add_odometry_command(CLI::App& app, OdometryOptions& options);
int run_odometry_command(const OdometryOptions& options, std::ostream& out, std::ostream& err);

// `slam SEQUENCE --out DIR`: odometry, loop closure, pose graph and map: DIR/trajectory.txt,
// map.ply, top_view.png, stats.json (and groundtruth.txt when the sequence has ground truth).
struct SlamOptions {
  SequenceRunOptions run;
  std::filesystem::path out_dir;
  bool no_loop_closure = false;
  bool no_map = false;
  bool features = false;  // ORB features: loop candidates by appearance, odometry seeding
  double voxel_size = 0.02;
  bool force = false;  // replace an earlier run's folder
};
CLI::App* add_slam_command(CLI::App& app, SlamOptions& options);
int run_slam_command(const SlamOptions& options, std::ostream& out, std::ostream& err);

// `planes INPUT --out DIR`: planes of an organized PCD, an RGB-D frame or a sequence's frames.
struct PlanesOptions {
  std::filesystem::path input, out_dir;
  std::filesystem::path color, intrinsics;  // depth PNG input
  double fx = 0, fy = 0, cx = -1, cy = -1;  // depth PNG input; 0 / -1: Kinect-like defaults
  double depth_scale = 0;  // units per metre; 0: 1000 for a depth PNG, the layout's for a sequence
  SequenceInputOptions sequence;                // sequences: --camera, --skip-bad-frames
  std::size_t first = 0, frames = 0, step = 1;  // sequences
  double lab_threshold = 15;
  double normal_angle_deg = 30;
  std::uint64_t min_plane_pixels = 300;
  std::string neighbours = "pixel";  // pixel | bbox
  std::string fit = "tls";           // tls | eq6
  std::string mode = "regions";      // regions (M1) | cells
  std::string backend = "auto";
  std::string backend_source = "--backend";
  bool force = false;
  bool progress = true;
};
CLI::App* add_planes_command(CLI::App& app, PlanesOptions& options);
int run_planes_command(const PlanesOptions& options, std::ostream& out, std::ostream& err);

// `rooms MAP --method NAME --out DIR`: room segmentation of an occupancy map: DIR/rooms.png,
// rooms_color.png, rooms.json. resolution_given: --resolution was set (it then overrides a YAML's).
struct RoomsOptions {
  std::filesystem::path map, out_dir;
  std::string method = "morphological";
  double resolution = 0.05;
  int free_threshold = 250;
  double min_area_m2 = -1, max_area_m2 = -1;  // < 0: the method's default
  bool keep_furniture = false;                // segment the map as it is (the reference)
  std::filesystem::path model;                // feature / vrf: trained model (empty: shipped)
  std::string backend = "auto", backend_source = "default";  // feature: where the scans run
  bool force = false;
};
CLI::App* add_rooms_command(CLI::App& app, RoomsOptions& options);
int run_rooms_command(const RoomsOptions& options, bool resolution_given, std::ostream& out);

// `rooms-eval FOLDER`: every method on every map with a ground truth: tables on out, CSV.
struct RoomsEvalOptions {
  std::filesystem::path folder, csv;
  bool force = false;                // replace an existing CSV
  std::vector<std::string> methods;  // empty: all
  std::string only;                  // map name filter
  RoomsOptions map;                  // resolution, free threshold, area limits
  bool progress = true;
};
CLI::App* add_rooms_eval_command(CLI::App& app, RoomsEvalOptions& options);
int run_rooms_eval_command(const RoomsEvalOptions& options, std::ostream& out, std::ostream& err);

// `semantic SCAN --out DIR [--goto door|wall]`: the metric-semantic grid map of an organized scan.
struct SemanticOptions {
  std::filesystem::path input, out_dir, trajectory;
  std::size_t frames = 0;         // sequence: 0 = all
  int step = 10;                  // sequence: every k-th frame
  SequenceInputOptions sequence;  // sequence: --camera, --depth-scale, --skip-bad-frames
  std::string goto_target;        // empty, "door" or "wall"
  double resolution = 0.05;
  std::vector<double> viewpoint;  // unorganized map without --trajectory: x y z (default: centroid)
  double angular_step = 1.0;      // unorganized map: range image degrees per pixel
  std::string detect;             // empty or "stairs": run the shipped cascade on every view
  std::string backend = "auto", backend_source = "default";
  bool force = false;
};
CLI::App* add_semantic_command(CLI::App& app, SemanticOptions& options);
int run_semantic_command(const SemanticOptions& options, std::ostream& out, std::ostream& err);

// `map SEQUENCE --out DIR`: the end-to-end pipeline (pipeline/map_pipeline.hpp) and its report.
struct MapOptions {
  SequenceRunOptions run;
  std::filesystem::path out_dir;
  std::size_t label_step = 5;
  std::size_t max_views = 300;
  int label_width = 320;
  double resolution = 0.05;
  std::string room_method = "distance";
  bool no_features = false;
  std::string poses;    // "groundtruth", a TUM trajectory file, or empty: estimate them
  double voxel = 0.04;  // the TSDF's (pipeline/mapper.hpp)
  std::size_t max_blocks = 1u << 14;  // the TSDF's budget
  bool force = false;
};
CLI::App* add_map_command(CLI::App& app, MapOptions& options);
int run_map_command(const MapOptions& options, std::ostream& out, std::ostream& err);

// `fuse SEQUENCE --poses FILE|groundtruth --out DIR`: the frames fused at known poses into a TSDF
// (mapping/tsdf_volume.hpp), its surface as DIR/mesh.ply (coloured) and a summary DIR/fuse.json.
struct FuseOptions {
  SequenceRunOptions run;  // the sequence, input options, backend, progress
  std::string poses;       // "groundtruth" or a TUM trajectory file
  std::filesystem::path out_dir;
  double voxel = 0.01;     // metres
  double truncation = 0;   // metres; 0: 4 voxels
  double max_depth = 4.0;  // metres: farther depth is not fused
  std::size_t max_blocks = 1 << 18;
  // With a floor height (metres, world z up): occupancy.pgm/.yaml of the robot's height band and
  // esdf.png (mapping/tsdf_slice.hpp).
  double floor_z = std::numeric_limits<double>::quiet_NaN();  // NaN: no 2-D maps
  bool force = false;
};
CLI::App* add_fuse_command(CLI::App& app, FuseOptions& options);
int run_fuse_command(const FuseOptions& options, std::ostream& out, std::ostream& err);

}  // namespace kartograf::cli
