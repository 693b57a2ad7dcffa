// Voronoi random field room segmentation (rooms/voronoi_random_field.hpp): max-product belief
// propagation against brute force, termination on loops, the node graph, the model's training and
// file round trip, errors, a hand-made map and one real ipa map with the shipped model.
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include <unistd.h>

#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/rooms/voronoi_random_field.hpp"
#include "room_test_maps.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

using rooms::PlaceField;
using rooms::PlaceLabel;

// A field of n nodes with random unary and (symmetric) pairwise log-potentials.
PlaceField random_field(int n, std::vector<std::pair<int, int>> edges, std::mt19937& rng) {
  std::uniform_real_distribution<double> value(-2.0, 2.0);
  PlaceField field;
  for (int i = 0; i < n; ++i) field.unary.push_back({value(rng), value(rng), value(rng)});
  field.edges = std::move(edges);
  for (int a = 0; a < 3; ++a) {
    for (int b = a; b < 3; ++b) field.pairwise(a, b) = field.pairwise(b, a) = value(rng);
  }
  return field;
}

// The best score over all 3^n labellings.
double brute_force_best(const PlaceField& field) {
  const std::size_t n = field.unary.size();
  std::vector<PlaceLabel> labels(n, PlaceLabel::room);
  double best = -std::numeric_limits<double>::infinity();
  std::size_t total = 1;
  for (std::size_t i = 0; i < n; ++i) total *= 3;
  for (std::size_t code = 0; code < total; ++code) {
    std::size_t rest = code;
    for (std::size_t i = 0; i < n; ++i, rest /= 3) labels[i] = static_cast<PlaceLabel>(rest % 3);
    best = std::max(best, rooms::field_score(field, labels));
  }
  return best;
}

std::vector<std::pair<int, int>> chain(int n) {
  std::vector<std::pair<int, int>> edges;
  for (int i = 0; i + 1 < n; ++i) edges.emplace_back(i, i + 1);
  return edges;
}

// On a tree, converged max-product finds a labelling of the best score.
TEST(VrfInference, MatchesBruteForceOnChainsAndTrees) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<std::pair<int, int>> edges = chain(7);
    if (trial % 2) edges = {{0, 1}, {0, 2}, {0, 3}, {3, 4}, {3, 5}, {5, 6}, {2, 7}};  // a tree
    const PlaceField field = random_field(trial % 2 ? 8 : 7, edges, rng);
    const rooms::PlaceInference result = rooms::max_product_labels(field);
    ASSERT_TRUE(result.converged) << "trial " << trial;
    EXPECT_LE(result.iterations, 100);
    EXPECT_NEAR(rooms::field_score(field, result.labels), brute_force_best(field), 1e-9)
        << "trial " << trial;
  }
}

// A hand-made chain with a known answer: the ends are sure rooms, the middle weakly prefers
// hallway, and the compatibility strongly favours equal neighbours: all rooms.
TEST(VrfInference, SmoothsAWeakMiddleToItsNeighbours) {
  PlaceField field;
  field.unary = {{2, 0, 0}, {0, 0.5, 0}, {0, 0.5, 0}, {2, 0, 0}};
  field.edges = chain(4);
  field.pairwise = Eigen::Matrix3d::Identity();
  const rooms::PlaceInference result = rooms::max_product_labels(field);
  EXPECT_TRUE(result.converged);
  EXPECT_EQ(result.labels, std::vector<PlaceLabel>(4, PlaceLabel::room));
  field.pairwise.setZero();  // without it every node keeps its own best label
  EXPECT_EQ(rooms::max_product_labels(field).labels,
            (std::vector<PlaceLabel>{PlaceLabel::room, PlaceLabel::hallway, PlaceLabel::hallway,
                                     PlaceLabel::room}));
}

// Loops: it always stops within max_iterations, and its labelling is at least as good as every
// labelling one change away (the ICM refinement). On a frustrated odd loop (neighbours must
// differ, nearly equal unaries) the damped messages keep changing: BP stops at the cap, not
// converged, and the refined labelling is still a best one.
TEST(VrfInference, TerminatesOnLoops) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 10; ++trial) {
    // A 3 x 3 grid: 12 edges, 4 loops.
    std::vector<std::pair<int, int>> edges;
    for (int y = 0; y < 3; ++y) {
      for (int x = 0; x < 3; ++x) {
        if (x < 2) edges.emplace_back(3 * y + x, 3 * y + x + 1);
        if (y < 2) edges.emplace_back(3 * y + x, 3 * y + x + 3);
      }
    }
    const PlaceField field = random_field(9, edges, rng);
    const rooms::PlaceInference result = rooms::max_product_labels(field, {30, 0.5, 1e-9});
    ASSERT_EQ(result.labels.size(), 9u);
    EXPECT_LE(result.iterations, 30);
    const double score = rooms::field_score(field, result.labels);
    EXPECT_LE(score, brute_force_best(field) + 1e-9);
    for (std::size_t i = 0; i < 9; ++i) {
      std::vector<PlaceLabel> changed = result.labels;
      for (int l = 0; l < 3; ++l) {
        changed[i] = static_cast<PlaceLabel>(l);
        EXPECT_LE(rooms::field_score(field, changed), score + 1e-9);
      }
    }
  }
  PlaceField frustrated;
  frustrated.unary.assign(5, {0, 0, 0});
  frustrated.edges = {{0, 1}, {1, 2}, {2, 3}, {3, 4}, {0, 4}};
  frustrated.unary[0] = {0.1, 0, 0};  // break the symmetry a little
  frustrated.pairwise = -5.0 * Eigen::Matrix3d::Identity();
  const rooms::PlaceInference result = rooms::max_product_labels(frustrated, {25, 0.5, 1e-12});
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.iterations, 25);
  EXPECT_EQ(result.labels.size(), 5u);
  EXPECT_NEAR(rooms::field_score(frustrated, result.labels), brute_force_best(frustrated), 1e-9);
}

TEST(VrfInference, RejectsBadFields) {
  PlaceField field;
  field.unary = {{0, 0, 0}, {0, 0, 0}};
  field.edges = {{0, 2}};
  EXPECT_ERROR_MENTIONS(rooms::max_product_labels(field), "edge (0, 2)");
  field.edges = {{1, 1}};
  EXPECT_ERROR_MENTIONS(rooms::max_product_labels(field), "itself");
  field.edges = {{0, 1}};
  EXPECT_ERROR_MENTIONS(rooms::max_product_labels(field, {100, 1.0, 1e-6}), "damping");
  EXPECT_ERROR_MENTIONS(rooms::max_product_labels(field, {0, 0.5, 1e-6}), "max_iterations");
  field.unary[1][2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_ERROR_MENTIONS(rooms::max_product_labels(field), "not finite");
  const std::vector<PlaceLabel> one(1, PlaceLabel::room);
  EXPECT_ERROR_MENTIONS(rooms::field_score(field, one), "1 labels for 2 nodes");
}

// Nodes lie on the graph, no closer than 8-adjacent to each other; the edges join the graph's
// nodes into one piece (the free space and its graph are connected) and run between nearby nodes.
TEST(VrfNodes, SampleTheGraphAndFollowIt) {
  const OccupancyGrid map = testing::rooms_off_a_corridor(3);
  rooms::VrfNodeParams params;
  params.node_spacing = 5;
  const rooms::VrfNodeGraph graph = rooms::vrf_node_graph(map, params);
  ASSERT_GT(graph.nodes.size(), 20u);
  std::size_t graph_cells = 0;
  for (const auto c : graph.voronoi.graph.pixels()) graph_cells += c;
  EXPECT_LT(graph.nodes.size(), graph_cells / 2);
  std::vector<int> parent(graph.nodes.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  const auto find = [&](int i) {
    while (parent[static_cast<std::size_t>(i)] != i) i = parent[static_cast<std::size_t>(i)];
    return i;
  };
  for (const auto& [a, b] : graph.edges) {
    ASSERT_LT(a, b);
    const Eigen::Vector2i d = graph.nodes[static_cast<std::size_t>(a)].cell -
                              graph.nodes[static_cast<std::size_t>(b)].cell;
    EXPECT_LE(d.cwiseAbs().maxCoeff(), 2 * params.node_spacing + 1);
    parent[static_cast<std::size_t>(find(a))] = find(b);
  }
  std::set<int> pieces;
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
    const rooms::VrfNode& node = graph.nodes[i];
    EXPECT_TRUE(graph.voronoi.graph(node.cell.x(), node.cell.y()));
    EXPECT_EQ(node.clearance, graph.voronoi.clearance(node.cell.x(), node.cell.y()));
    pieces.insert(find(static_cast<int>(i)));
  }
  EXPECT_EQ(pieces.size(), 1u);
  int critical = 0;
  for (const rooms::VrfNode& node : graph.nodes) critical += node.critical;
  EXPECT_GE(critical, 3);  // at least the three doorways
  const std::vector<rooms::VrfFeatures> features = rooms::vrf_node_features(map, graph);
  ASSERT_EQ(features.size(), graph.nodes.size());
  for (std::size_t i = 0; i < features.size(); ++i)
    EXPECT_FLOAT_EQ(features[i][rooms::kLaserFeatureCount], graph.nodes[i].clearance * 0.05f);
}

// A training drawing made in code: rooms_off_a_corridor with its rooms, corridor and doorways.
rooms::VrfTrainingMap drawn_training_map(int rooms_count) {
  LabelImage truth;
  rooms::VrfTrainingMap training{"drawn", testing::rooms_off_a_corridor(rooms_count, &truth), {}};
  training.labels = Image<std::uint8_t>(truth.width(), truth.height(), 0);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (training.map.cells.data()[i] != CellState::free) continue;
    const Label l = truth.data()[i];
    const PlaceLabel place = l == 0                 ? PlaceLabel::doorway
                             : l == rooms_count + 1 ? PlaceLabel::hallway
                                                    : PlaceLabel::room;
    training.labels.data()[i] = static_cast<std::uint8_t>(1 + static_cast<int>(place));
  }
  return training;
}

TEST(VrfModel, TrainsSavesAndLoads) {
  rooms::VrfTrainingParams params;
  params.weak_count = 10;
  params.folds = 1;
  const rooms::VrfModel model = rooms::VrfModel::train({drawn_training_map(3)}, params);
  ASSERT_FALSE(model.empty());
  // Equal labels go together along edges more than chance, rooms and hallways never touch.
  EXPECT_GT(model.compatibility()(0, 0), 0.0);
  EXPECT_LT(model.compatibility()(0, 1), model.compatibility()(0, 2));
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("kartograf_vrf_" + std::to_string(::getpid()) + ".yml.gz");
  model.save(path);
  const rooms::VrfModel loaded = rooms::VrfModel::load(path);
  std::filesystem::remove(path);
  EXPECT_EQ(loaded.compatibility(), model.compatibility());
  EXPECT_EQ(loaded.trained_pairwise_weight(), model.trained_pairwise_weight());
  const OccupancyGrid map = testing::rooms_in_a_row(2);
  const rooms::VrfNodeGraph graph = rooms::vrf_node_graph(map);
  const std::vector<rooms::VrfFeatures> features = rooms::vrf_node_features(map, graph);
  const auto a = model.unary(features), b = loaded.unary(features);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    double total = 0;
    for (int l = 0; l < 3; ++l) {
      EXPECT_NEAR(a[i][static_cast<std::size_t>(l)], b[i][static_cast<std::size_t>(l)], 1e-6);
      total += std::exp(a[i][static_cast<std::size_t>(l)]);
    }
    EXPECT_NEAR(total, 1.0, 1e-9);  // log-probabilities
  }
}

TEST(VrfModel, ErrorsNameTheProblem) {
  const rooms::VrfModel empty;
  EXPECT_ERROR_MENTIONS(rooms::segment_voronoi_random_field(testing::rooms_in_a_row(2), empty),
                        "model is empty");
  EXPECT_ERROR_MENTIONS(rooms::VrfModel::load("/nonexistent/vrf.yml.gz"), "/nonexistent/vrf.yml.gz",
                        "does not exist");
  EXPECT_ERROR_MENTIONS(rooms::vrf_training_map("drawing.png", Image<std::uint8_t>()),
                        "drawing.png", "empty");
  rooms::VrfTrainingParams params;
  params.folds = 2;
  EXPECT_ERROR_MENTIONS(rooms::VrfModel::train({drawn_training_map(2)}, params), "training maps");
  const rooms::VrfModel model = rooms::VrfModel::load(rooms::default_vrf_model_path());
  const OccupancyGrid walls = testing::carve_map(20, 20, {});
  EXPECT_ERROR_MENTIONS(rooms::segment_voronoi_random_field(walls, model), "no free cell");
  rooms::VrfParams bad;
  bad.room_area = {5, 1};
  EXPECT_ERROR_MENTIONS(rooms::segment_voronoi_random_field(testing::rooms_in_a_row(2), model, bad),
                        "area limits");
  bad = {};
  bad.nodes.node_spacing = 0;
  EXPECT_ERROR_MENTIONS(rooms::segment_voronoi_random_field(testing::rooms_in_a_row(2), model, bad),
                        "node_spacing");
}

// Three rooms off a corridor, with the shipped model: four rooms, each the truth's.
TEST(VrfSegmentation, RoomsOffACorridor) {
  LabelImage truth;
  const OccupancyGrid map = testing::rooms_off_a_corridor(3, &truth);
  const rooms::VrfModel model = rooms::VrfModel::load(rooms::default_vrf_model_path());
  const rooms::RoomSegmentation result = rooms::segment_voronoi_random_field(map, model);
  EXPECT_EQ(result.method, "vrf");
  EXPECT_EQ(result.records.size(), 4u);
  const auto scores = eval::evaluate_room_segmentation(truth, result.rooms);
  EXPECT_GT(scores.recall_mean, 0.95);
  EXPECT_GT(scores.precision_mean, 0.95);
  testing::expect_free_space_covered(map, result.rooms);
  const rooms::VrfLabelling labelling = rooms::label_voronoi_nodes(map, model);
  EXPECT_TRUE(labelling.inference.converged);
  int doorways = 0;
  for (const PlaceLabel l : labelling.inference.labels) doorways += l == PlaceLabel::doorway;
  EXPECT_GE(doorways, 3);
}

// Free space too narrow for the graph (a corridor 4 cells wide): no node, and still one room.
TEST(VrfSegmentation, SpaceWithoutNodesIsARoom) {
  const OccupancyGrid map = testing::carve_map(510, 10, {{5, 3, 505, 7}});  // 25 x 0.2 m
  const rooms::VrfModel model = rooms::VrfModel::load(rooms::default_vrf_model_path());
  EXPECT_TRUE(rooms::label_voronoi_nodes(map, model).graph.nodes.empty());
  const rooms::RoomSegmentation result = rooms::segment_voronoi_random_field(map, model);
  ASSERT_EQ(result.records.size(), 1u);
  EXPECT_EQ(result.records[0].cells, 2000);
}

// One real map with the shipped model (trained on VRF training maps of other buildings), against
// its ground truth.
TEST(VrfSegmentation, RealIpaMap) {
  const rooms::VrfModel model = rooms::VrfModel::load(rooms::default_vrf_model_path());
  const auto scores = testing::benchmark_map_scores("office_c", [&](const OccupancyGrid& map) {
    return rooms::segment_voronoi_random_field(map, model);
  });
  EXPECT_GT(scores.recall_mean, 0.98);     // measured 0.998
  EXPECT_GT(scores.precision_mean, 0.96);  // measured 0.985
}

// Nodes, stretches and the clearance radius count metres, not cells: office_e at 0.1 m a cell is
// segmented as at 0.05 m (with cell counts kept: 17 segments for its 32 rooms, precision 0.742).
TEST(VrfSegmentation, RealIpaMapAtACoarserResolution) {
  const rooms::VrfModel model = rooms::VrfModel::load(rooms::default_vrf_model_path());
  const auto scores = testing::resampled_map_scores("office_e", 2, [&](const OccupancyGrid& map) {
    return rooms::segment_voronoi_random_field(map, model);
  });
  EXPECT_GT(scores.recall_mean, 0.95);     // measured 0.973 (0.974 at 0.05 m)
  EXPECT_GT(scores.precision_mean, 0.92);  // measured 0.950 (0.899)
}

}  // namespace
}  // namespace kartograf
