#pragma once
// Voronoi random field room segmentation (docs/methods.md M4 step 5; S. Friedman, H. Pasula,
// D. Fox, "Voronoi Random Fields: Extracting the Topological Structure of Indoor Environments via
// Place Labeling", IJCAI 2007; ipa_room_segmentation's VoronoiRandomFieldSegmentation, which the
// survey reports never finishing). A conditional random field over points of the Voronoi graph
// labels each point room, hallway or doorway; the doorways cut the free space into rooms.
//
// 1. Nodes (vrf_node_graph): the pruned Voronoi graph of the map without furniture
//    (voronoi_graph.hpp, furniture.hpp). Its branch points, end points and critical points (all
//    candidates, before the spacing filter) are nodes, and so is every graph cell whose distance
//    along the graph (8-steps) to the nearest of those is a multiple of node_spacing. Every graph
//    cell belongs to its nearest node along the graph; two nodes are joined by an edge when their
//    graph cells touch (so edges follow the graph, loops included).
// 2. Unary potentials: three one-vs-rest boosted classifiers (room, hallway, doorway; OpenCV
//    discrete AdaBoost) score each node from the 27 laser scan features of a scan simulated there
//    (laser_features.hpp) and 5 node features (clearance; clearance relative to the least and the
//    largest clearance of the graph cells within kVrfGraphRadius steps along the graph; graph
//    neighbours; whether it is a critical point). None depends on the node spacing. A softmax
//    over the three scores (a multinomial logistic regression fitted on scores the classifiers give
//    to maps they were not trained on) turns them into log-probabilities: the unary log-potentials.
// 3. Pairwise potential: one 3x3 log-compatibility for every edge, the pointwise mutual information
//    of the two labels at the ends of the training maps' edges, times a weight (pairwise_weight;
//    the trained default maximises the pseudo-likelihood of the training labels).
// 4. Inference: loopy max-product belief propagation in log space (max-sum) with damping, at most
//    max_iterations sweeps; it stops once no message changed by more than `tolerance` (converged)
//    and always terminates. Each node then takes the label of its largest belief, and iterated
//    conditional modes refine that labelling to one no single change improves (which matters
//    when BP did not converge).
// 5. Segmentation: each connected run of doorway nodes cuts the free space at every narrowest
//    point of its stretch of graph (the graph cells within node_spacing steps of its nodes whose
//    clearance is least within node_spacing steps along the graph; a run crossing a corridor from
//    door to door has two), with the line from that cell to its nearest obstacle cell and to the
//    nearest obstacle cell on the other side. The free space cut by those lines splits into regions
//    (4-connected); a region is a hallway when most of its nodes are hallway nodes, else a room;
//    hallway regions that meet across a cut are merged (a hallway stays whole). Regions outside
//    room_area and regions without a node beside a cut (slivers between cuts) are dropped; a piece
//    of free space with neither node nor cut (too narrow for the graph) is a room. The rooms then
//    grow over the free space (grow_rooms).
//
// Departures from the reference: nodes on our pruned graph instead of the reference's node
// sampling; pointwise mutual information times one weight instead of the reference's learned
// pairwise features (its training, conjugate gradient on the pseudo-likelihood of all features, is
// what never finished); cuts at the narrowest points of doorway runs instead of at every doorway
// node; an ICM pass after BP; furniture removed before the graph is built.
//
// The shipped model (models/rooms/vrf_model.yml.gz, tools/train_vrf, about a minute) was trained on
// the ipa VRF training maps of buildings that are not among the ipa test maps (NLB, lab_d, intel,
// office_h). node_spacing, doorway_bias and the boosting settings (weak_count, max_depth) were
// chosen on the ipa test maps; the pairwise weight is the training's pseudo-likelihood choice.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/image.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/rooms/furniture.hpp"
#include "kartograf/rooms/laser_features.hpp"
#include "kartograf/rooms/room_segmentation.hpp"
#include "kartograf/rooms/voronoi_graph.hpp"

namespace kartograf::rooms {

// ---- The random field and its inference ---------------------------------------------------------

enum class PlaceLabel : std::uint8_t { room = 0, hallway = 1, doorway = 2 };
inline constexpr int kPlaceLabels = 3;
using LabelScores = std::array<double, kPlaceLabels>;  // indexed by PlaceLabel

// A pairwise random field over discrete labels: log-potentials (larger: more likely) per node and
// one symmetric label compatibility for every edge. Its score of a labelling y is
// sum_i unary[i][y_i] + sum_(i,j) pairwise(y_i, y_j).
struct PlaceField {
  std::vector<LabelScores> unary;
  std::vector<std::pair<int, int>> edges;  // node indices, i != j
  Eigen::Matrix3d pairwise = Eigen::Matrix3d::Zero();
};

struct BeliefPropagationParams {
  int max_iterations = 300;
  double damping = 0.5;     // new message = (1 - damping) x update + damping x old; in [0, 1)
  double tolerance = 1e-6;  // converged: no message changed by more than this in a sweep
};

struct PlaceInference {
  std::vector<PlaceLabel> labels;
  int iterations = 0;  // sweeps run
  bool converged = false;
  int refined_labels = 0;  // labels the ICM pass after BP changed
};

// Max-product (max-sum) loopy belief propagation (exact on trees when converged), its labelling
// then refined by iterated conditional modes (at most max_iterations sweeps; the score never
// decreases). Throws Error for
// edges naming missing nodes or joining a node to itself, non-finite potentials or bad parameters.
PlaceInference max_product_labels(const PlaceField& field,
                                  const BeliefPropagationParams& params = {});

// The field's score of a labelling (labels.size() == unary.size()).
double field_score(const PlaceField& field, std::span<const PlaceLabel> labels);

// ---- Nodes on the Voronoi graph -----------------------------------------------------------------

inline constexpr int kVrfGraphRadius = 16;  // graph steps on maps of the reference resolution

struct VrfNodeParams {
  VoronoiGraphParams graph;
  // Graph steps between nodes on maps of graph.reference_resolution; scaled to the map's, so
  // that nodes lie the same metres apart (as the graph's stretches and kVrfGraphRadius are).
  int node_spacing = 4;
};

struct VrfNode {
  Eigen::Vector2i cell = Eigen::Vector2i::Zero();  // (column, row)
  float clearance = 0;                             // cells
  bool critical = false;                           // a critical point of the graph
};

struct VrfNodeGraph {
  std::vector<VrfNode> nodes;
  std::vector<std::pair<int, int>> edges;  // i < j
  VoronoiGraph voronoi;
  int node_spacing = 1;                // graph steps, at the map's resolution
  int graph_radius = kVrfGraphRadius;  // the same (vrf_node_features' clearance around a node)
};

// Throws Error for a map without free cells or node_spacing < 1 (or bad graph parameters).
VrfNodeGraph vrf_node_graph(const OccupancyGrid& map, const VrfNodeParams& params = {});

inline constexpr std::size_t kVrfFeatureCount = kLaserFeatureCount + 5;
using VrfFeatures = std::array<float, kVrfFeatureCount>;

// The features of every node (scans with LaserScanParams / LaserFeatureParams defaults).
std::vector<VrfFeatures> vrf_node_features(const OccupancyGrid& map, const VrfNodeGraph& graph);

// ---- The trained model --------------------------------------------------------------------------

// A training map: free space and what each free cell is (none: unused).
struct VrfTrainingMap {
  std::string name;  // for messages
  OccupancyGrid map;
  Image<std::uint8_t> labels;  // the map's size: 0 none, 1 + PlaceLabel otherwise
};

// An ipa VRF training drawing (grey 0 obstacle, 77 room, 115 hallway, 179 doorway, anything else
// free but unlabelled; io::read_map_gray reads one) as a training map. Throws Error naming `name`
// for an empty drawing or a resolution <= 0.
VrfTrainingMap vrf_training_map(std::string name, const Image<std::uint8_t>& drawing,
                                double resolution = 0.05);

struct VrfTrainingParams {
  VrfNodeParams nodes;
  int weak_count = 200;  // boosting rounds per classifier
  int max_depth = 3;
  int sample_stride = 2;  // classifiers train on every n-th graph cell (nodes at spacing 1)
  int folds = 2;          // held-out folds of maps for the calibration and the pairwise weight
  std::optional<FurnitureParams> furniture = FurnitureParams{};  // as VrfParams::furniture
};

// Room, hallway and doorway classifiers, their calibration and the pairwise compatibility.
// Copies share the model.
class VrfModel {
 public:
  VrfModel() = default;
  bool empty() const { return !model_; }

  // Throws Error when a class has no sample, there are fewer maps than folds, or a map is bad
  // (naming it).
  static VrfModel train(const std::vector<VrfTrainingMap>& maps,
                        const VrfTrainingParams& params = {});
  // OpenCV FileStorage (.yml.gz recommended). Errors name the file.
  static VrfModel load(const std::filesystem::path& path);
  void save(const std::filesystem::path& path) const;

  // Unary log-potentials (log-probabilities) of nodes from their features.
  std::vector<LabelScores> unary(std::span<const VrfFeatures> features) const;
  // PMI of the labels at the ends of an edge (unweighted).
  const Eigen::Matrix3d& compatibility() const;
  // The pairwise weight that maximised the held-out pseudo-likelihood in training.
  double trained_pairwise_weight() const;

  struct Model;  // OpenCV's, kept out of the header

 private:
  explicit VrfModel(std::shared_ptr<const Model> model) : model_(std::move(model)) {}
  std::shared_ptr<const Model> model_;
};

// models/rooms/vrf_model.yml.gz: $KARTOGRAF_VRF_MODEL when set, else the models folder the library
// was built or installed with.
std::filesystem::path default_vrf_model_path();

// ---- Segmentation -------------------------------------------------------------------------------

struct VrfParams {
  VrfNodeParams nodes;
  BeliefPropagationParams inference;
  double pairwise_weight = -1;  // < 0: the model's trained weight
  // Added to every node's doorway log-potential: > 0 finds more doorways (more, smaller rooms).
  double doorway_bias = 0.5;
  AreaLimits room_area{1.0, 1e6};
  // Segment without furniture (furniture.hpp); empty: the map as it is.
  std::optional<FurnitureParams> furniture = FurnitureParams{};
};

// What the segmentation saw: the nodes, their field and its labelling.
struct VrfLabelling {
  VrfNodeGraph graph;
  PlaceField field;
  PlaceInference inference;
};

// Steps 1-4 on the map (without furniture when params.furniture is set). Throws Error for a map
// without free cells, an empty model or bad parameters.
VrfLabelling label_voronoi_nodes(const OccupancyGrid& map, const VrfModel& model,
                                 const VrfParams& params = {});

// Throws as label_voronoi_nodes, and for bad area limits.
RoomSegmentation segment_voronoi_random_field(const OccupancyGrid& map, const VrfModel& model,
                                              const VrfParams& params = {});
// Step 5 alone, from a labelling of `work` (the map the nodes were built on).
// Throws Error when the labelling is not of `work`.
LabelImage vrf_rooms(const OccupancyGrid& work, const VrfLabelling& labelling,
                     const VrfParams& params = {});

}  // namespace kartograf::rooms
