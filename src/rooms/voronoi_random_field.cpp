// Voronoi random field room segmentation: nodes, their features, and the rooms cut at the doorway
// nodes (voronoi_random_field.hpp). The model lives in voronoi_random_field_model.cpp, the
// inference in voronoi_random_field_inference.cpp.
#include "kartograf/rooms/voronoi_random_field.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include <opencv2/imgproc.hpp>

#include "compute/cpu_parallel.hpp"
#include "kartograf/core/error.hpp"
#include "rooms/grid_neighbours.hpp"

namespace kartograf::rooms {

namespace {

constexpr std::uint32_t kUnreached = std::numeric_limits<std::uint32_t>::max();

// Breadth-first distances along the graph (8-steps over graph cells) from `sources`, and which
// source each graph cell is nearest to (ties: the source reached first).
struct GraphFlood {
  std::vector<std::uint32_t> distance;
  std::vector<std::uint32_t> owner;
};

GraphFlood flood_graph(const Image<std::uint8_t>& graph,
                       const std::vector<std::uint32_t>& sources) {
  GraphFlood flood{std::vector<std::uint32_t>(graph.size(), kUnreached),
                   std::vector<std::uint32_t>(graph.size(), kUnreached)};
  std::vector<std::uint32_t> queue;
  for (std::uint32_t s = 0; s < sources.size(); ++s) {
    flood.distance[sources[s]] = 0;
    flood.owner[sources[s]] = s;
    queue.push_back(sources[s]);
  }
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::uint32_t i = queue[head];
    detail::for_each_neighbour8(i, graph.width(), graph.height(), [&](std::uint32_t j) {
      if (!graph.data()[j] || flood.distance[j] != kUnreached) return;
      flood.distance[j] = flood.distance[i] + 1;
      flood.owner[j] = flood.owner[i];
      queue.push_back(j);
    });
  }
  return flood;
}

int graph_neighbours(const Image<std::uint8_t>& graph, std::uint32_t i) {
  int n = 0;
  detail::for_each_neighbour8(i, graph.width(), graph.height(),
                              [&](std::uint32_t j) { n += graph.data()[j]; });
  return n;
}

// Union-find over node indices.
struct Groups {
  explicit Groups(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::size_t find(std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(std::size_t a, std::size_t b) { parent[find(a)] = find(b); }
  std::vector<std::size_t> parent;
};

}  // namespace

VrfNodeGraph vrf_node_graph(const OccupancyGrid& map, const VrfNodeParams& params) {
  const std::string what = "Voronoi random field nodes";
  check_map(map, what);
  require(params.node_spacing >= 1,
          what + ": node_spacing must be >= 1, got " + std::to_string(params.node_spacing));
  VrfNodeGraph result;
  result.voronoi = build_voronoi_graph(map, params.graph);  // checks the reference resolution
  const double reference = params.graph.reference_resolution;
  result.node_spacing = cells_at_resolution(params.node_spacing, reference, map.resolution);
  result.graph_radius = cells_at_resolution(kVrfGraphRadius, reference, map.resolution);
  const Image<std::uint8_t>& graph = result.voronoi.graph;
  const int width = graph.width();
  const auto index = [&](const Eigen::Vector2i& c) {
    return static_cast<std::uint32_t>(c.y() * width + c.x());
  };

  // Seeds: critical points first, then branch and end points, none 8-adjacent to another.
  std::vector<std::uint8_t> seed(graph.size(), 0), critical(graph.size(), 0);
  std::vector<std::uint32_t> seeds;
  const auto add_seed = [&](std::uint32_t i) {
    bool crowded = seed[i] != 0;
    detail::for_each_neighbour8(i, width, graph.height(),
                                [&](std::uint32_t j) { crowded |= seed[j] != 0; });
    if (crowded) return;
    seed[i] = 1;
    seeds.push_back(i);
  };
  for (const CriticalLine& line : result.voronoi.candidates) {
    const std::uint32_t i = index(line.point);
    if (!graph.data()[i]) continue;
    critical[i] = 1;
    add_seed(i);
  }
  for (std::uint32_t i = 0; i < graph.size(); ++i) {
    if (graph.data()[i] && graph_neighbours(graph, i) != 2) add_seed(i);
  }
  // Every graph cell no seed reaches (a loop without branches) gets one.
  GraphFlood flood = flood_graph(graph, seeds);
  for (std::uint32_t i = 0; i < graph.size(); ++i) {
    if (graph.data()[i] && flood.distance[i] == kUnreached) {
      seeds.push_back(i);
      flood = flood_graph(graph, seeds);
    }
  }
  std::vector<std::uint32_t> nodes = seeds;
  const auto spacing = static_cast<std::uint32_t>(result.node_spacing);
  for (std::uint32_t i = 0; i < graph.size(); ++i) {
    if (graph.data()[i] && flood.distance[i] > 0 && flood.distance[i] % spacing == 0)
      nodes.push_back(i);
  }
  // Each graph cell joins its nearest node; touching cells of two nodes make an edge.
  flood = flood_graph(graph, nodes);
  for (std::uint32_t i = 0; i < graph.size(); ++i) {
    if (!graph.data()[i]) continue;
    detail::for_each_neighbour8(i, width, graph.height(), [&](std::uint32_t j) {
      if (!graph.data()[j] || flood.owner[j] == flood.owner[i]) return;
      const int a = static_cast<int>(std::min(flood.owner[i], flood.owner[j]));
      const int b = static_cast<int>(std::max(flood.owner[i], flood.owner[j]));
      result.edges.emplace_back(a, b);
    });
  }
  std::sort(result.edges.begin(), result.edges.end());
  result.edges.erase(std::unique(result.edges.begin(), result.edges.end()), result.edges.end());
  for (const std::uint32_t i : nodes) {
    VrfNode node;
    node.cell = Eigen::Vector2i(static_cast<int>(i % static_cast<std::uint32_t>(width)),
                                static_cast<int>(i / static_cast<std::uint32_t>(width)));
    node.clearance = result.voronoi.clearance.data()[i];
    node.critical = critical[i] != 0;
    result.nodes.push_back(node);
  }
  return result;
}

std::vector<VrfFeatures> vrf_node_features(const OccupancyGrid& map, const VrfNodeGraph& graph) {
  const Image<std::uint8_t>& cells = graph.voronoi.graph;
  require(cells.width() == map.width() && cells.height() == map.height(),
          "Voronoi random field features: the node graph differs from the map in size");
  const LaserScanner scanner(map);
  const std::size_t n = graph.nodes.size();
  std::vector<VrfFeatures> features(n);
  const double resolution = map.resolution;
  compute::detail::for_each_chunk(
      n, n * static_cast<std::size_t>(scanner.beams()),
      [&](std::size_t begin, std::size_t end, std::size_t) {
        std::vector<double> ranges(static_cast<std::size_t>(scanner.beams()));
        std::vector<std::uint32_t> stamp(cells.size(), 0), frontier, next;
        for (std::size_t k = begin; k < end; ++k) {
          const VrfNode& node = graph.nodes[k];
          scanner.scan(node.cell.x(), node.cell.y(), ranges);
          const LaserFeatures laser = laser_scan_features(ranges);
          VrfFeatures& f = features[k];
          std::copy(laser.begin(), laser.end(), f.begin());
          // The clearance around the node along the graph: a doorway is a narrow spot between wide
          // ones.
          const auto start =
              static_cast<std::uint32_t>(node.cell.y() * cells.width() + node.cell.x());
          const auto visit = static_cast<std::uint32_t>(k + 1);
          stamp[start] = visit;
          frontier.assign(1, start);
          float least = node.clearance, most = node.clearance;
          for (int step = 0; step < graph.graph_radius && !frontier.empty(); ++step) {
            next.clear();
            for (const std::uint32_t i : frontier) {
              detail::for_each_neighbour8(i, cells.width(), cells.height(), [&](std::uint32_t j) {
                if (!cells.data()[j] || stamp[j] == visit) return;
                stamp[j] = visit;
                next.push_back(j);
                least = std::min(least, graph.voronoi.clearance.data()[j]);
                most = std::max(most, graph.voronoi.clearance.data()[j]);
              });
            }
            frontier.swap(next);
          }
          const float c = std::max(node.clearance, 0.5f);
          std::size_t i = kLaserFeatureCount;
          f[i++] = static_cast<float>(node.clearance * resolution);
          f[i++] = least / c;
          f[i++] = most / c;
          f[i++] = static_cast<float>(graph_neighbours(cells, start));
          f[i++] = node.critical ? 1.0f : 0.0f;
        }
      });
  return features;
}

VrfLabelling label_voronoi_nodes(const OccupancyGrid& map, const VrfModel& model,
                                 const VrfParams& params) {
  const std::string what = "Voronoi random field segmentation";
  check_map(map, what);
  require(!model.empty(), what + ": the VRF model is empty (load or train one)");
  const double weight =
      params.pairwise_weight < 0 ? model.trained_pairwise_weight() : params.pairwise_weight;
  require(std::isfinite(weight), what + ": pairwise_weight must be finite");
  require(std::isfinite(params.doorway_bias), what + ": doorway_bias must be finite");
  VrfLabelling result;
  result.graph = vrf_node_graph(map, params.nodes);
  result.field.unary = model.unary(vrf_node_features(map, result.graph));
  for (LabelScores& u : result.field.unary)
    u[static_cast<std::size_t>(PlaceLabel::doorway)] += params.doorway_bias;
  result.field.edges = result.graph.edges;
  result.field.pairwise = weight * model.compatibility();
  result.inference = max_product_labels(result.field, params.inference);
  return result;
}

namespace {

// Graph cells within a number of steps along the graph of some start cells (stamped, reusable).
class GraphWalk {
 public:
  explicit GraphWalk(const Image<std::uint8_t>& graph) : graph_(graph), stamp_(graph.size(), 0) {}
  std::vector<std::uint32_t> within(const std::vector<std::uint32_t>& starts, int steps) {
    ++visit_;
    std::vector<std::uint32_t> cells = starts;
    for (const std::uint32_t c : starts) stamp_[c] = visit_;
    std::size_t begin = 0;
    for (int step = 0; step < steps; ++step) {
      const std::size_t end = cells.size();
      for (std::size_t k = begin; k < end; ++k) {
        detail::for_each_neighbour8(cells[k], graph_.width(), graph_.height(),
                                    [&](std::uint32_t j) {
                                      if (!graph_.data()[j] || stamp_[j] == visit_) return;
                                      stamp_[j] = visit_;
                                      cells.push_back(j);
                                    });
      }
      begin = end;
    }
    return cells;
  }

 private:
  const Image<std::uint8_t>& graph_;
  std::vector<std::uint32_t> stamp_;
  std::uint32_t visit_ = 0;
};

// The line across a doorway at `point`: to its nearest obstacle cell and to the nearest obstacle
// cell on the other side (farther than the clearance from the first, and not on its side).
std::pair<cv::Point, cv::Point> doorway_line(const Eigen::Vector2i& point,
                                             const NearestObstacles& near) {
  const Eigen::Vector2i a = near.nearest(point.x(), point.y());
  const double d = near.clearance(point.x(), point.y());
  const Eigen::Vector2d toward_a = (a - point).cast<double>();
  const int radius = static_cast<int>(std::ceil(2.0 * d)) + 2;
  const int width = near.clearance.width(), height = near.clearance.height();
  Eigen::Vector2i b = a;
  double best = std::numeric_limits<double>::infinity();
  for (int y = std::max(0, point.y() - radius); y <= std::min(height - 1, point.y() + radius);
       ++y) {
    for (int x = std::max(0, point.x() - radius); x <= std::min(width - 1, point.x() + radius);
         ++x) {
      if (near.clearance(x, y) > 0) continue;  // free
      const Eigen::Vector2i c(x, y);
      const Eigen::Vector2d v = (c - point).cast<double>();
      const double dist2 = v.squaredNorm();
      if (dist2 >= best || v.dot(toward_a) >= 0 || (c - a).cast<double>().squaredNorm() <= d * d)
        continue;
      best = dist2;
      b = c;
    }
  }
  return {cv::Point(a.x(), a.y()), cv::Point(b.x(), b.y())};
}

// 1 on the map's free cells, 0 elsewhere.
Image<std::uint8_t> free_cell_mask(const OccupancyGrid& work) {
  Image<std::uint8_t> free_cells(work.width(), work.height(), 0);
  for (std::size_t i = 0; i < free_cells.size(); ++i)
    free_cells.data()[i] = work.cells.data()[i] == CellState::free;
  return free_cells;
}

// The graph cells of each connected run of doorway nodes (indexed by a node of the run; the other
// entries are empty).
std::vector<std::vector<std::uint32_t>> doorway_runs(const VrfNodeGraph& graph,
                                                     const std::vector<PlaceLabel>& labels,
                                                     int width) {
  const std::size_t n = graph.nodes.size();
  const auto is_door = [&](std::size_t i) { return labels[i] == PlaceLabel::doorway; };
  Groups runs(n);
  for (const auto& [a, b] : graph.edges) {
    if (is_door(static_cast<std::size_t>(a)) && is_door(static_cast<std::size_t>(b)))
      runs.join(static_cast<std::size_t>(a), static_cast<std::size_t>(b));
  }
  std::vector<std::vector<std::uint32_t>> run_cells(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (is_door(i))
      run_cells[runs.find(i)].push_back(
          static_cast<std::uint32_t>(graph.nodes[i].cell.y() * width + graph.nodes[i].cell.x()));
  }
  return run_cells;
}

// Where a run of doorway nodes is cut: the cells of the run's stretch of graph (its nodes' cells
// and those within node_spacing steps) that are the narrowest within node_spacing steps, or else
// the narrowest cell of the stretch.
std::vector<std::uint32_t> narrowest_cells(const std::vector<std::uint32_t>& run,
                                           const VrfNodeGraph& graph, GraphWalk& walk) {
  const Image<float>& clearance_of = graph.voronoi.clearance;
  const auto narrower = [&](std::uint32_t a,
                            std::uint32_t b) {  // a before b: less clearance, then index
    return clearance_of.data()[a] < clearance_of.data()[b] ||
           (clearance_of.data()[a] == clearance_of.data()[b] && a < b);
  };
  const std::vector<std::uint32_t> stretch = walk.within(run, graph.node_spacing);
  std::vector<std::uint32_t> points;
  for (const std::uint32_t c : stretch) {
    const std::vector<std::uint32_t> around = walk.within({c}, graph.node_spacing);
    if (std::none_of(around.begin(), around.end(), [&](std::uint32_t o) { return narrower(o, c); }))
      points.push_back(c);
  }
  if (points.empty()) points.push_back(*std::min_element(stretch.begin(), stretch.end(), narrower));
  return points;
}

using DoorwayCut = std::array<cv::Point, 3>;  // cut point, the two ends

// Cuts at the narrowest points near each connected run of doorway nodes, drawn as obstacle lines
// into `open` (free cells 255).
std::vector<DoorwayCut> cut_doorways(const VrfNodeGraph& graph,
                                     const std::vector<PlaceLabel>& labels,
                                     const NearestObstacles& near, cv::Mat& open) {
  const int width = open.cols;
  std::vector<DoorwayCut> cuts;
  GraphWalk walk(graph.voronoi.graph);
  for (const std::vector<std::uint32_t>& run : doorway_runs(graph, labels, width)) {
    if (run.empty()) continue;
    for (const std::uint32_t c : narrowest_cells(run, graph, walk)) {
      const Eigen::Vector2i p(static_cast<int>(c % static_cast<std::uint32_t>(width)),
                              static_cast<int>(c / static_cast<std::uint32_t>(width)));
      const auto [a, b] = doorway_line(p, near);
      cuts.push_back({cv::Point(p.x(), p.y()), a, b});
      cv::line(open, cuts.back()[0], a, cv::Scalar(0), 1, cv::LINE_8);
      cv::line(open, cuts.back()[0], b, cv::Scalar(0), 1, cv::LINE_8);
    }
  }
  return cuts;
}

// The regions (connected free space between the cuts, 0: none) and their room and hallway votes:
// the nodes of each label in them.
struct Regions {
  cv::Mat parts;
  int count = 0;
  std::vector<int> room_votes, hallway_votes;

  int at(int x, int y) const { return parts.at<int>(y, x); }
  bool hallway(int region) const {
    return hallway_votes[static_cast<std::size_t>(region)] >
           room_votes[static_cast<std::size_t>(region)];
  }
};

Regions vote_regions(const cv::Mat& open, const VrfNodeGraph& graph,
                     const std::vector<PlaceLabel>& labels) {
  Regions regions;
  regions.count = cv::connectedComponents(open, regions.parts, 4, CV_32S);
  regions.room_votes.assign(static_cast<std::size_t>(regions.count), 0);
  regions.hallway_votes.assign(regions.room_votes.size(), 0);
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
    const int region = regions.at(graph.nodes[i].cell.x(), graph.nodes[i].cell.y());
    if (region == 0) continue;
    if (labels[i] == PlaceLabel::room) ++regions.room_votes[static_cast<std::size_t>(region)];
    if (labels[i] == PlaceLabel::hallway) ++regions.hallway_votes[static_cast<std::size_t>(region)];
  }
  return regions;
}

// The regions within one cell of a cut's two lines (ascending, each once) that hold a node, and
// every region there marked in cut_touches.
std::vector<int> regions_along_cut(const DoorwayCut& cut, const cv::Mat& open,
                                   const Regions& regions, std::vector<std::uint8_t>& cut_touches) {
  std::vector<int> touching;
  for (const cv::Point& end : {cut[1], cut[2]}) {
    cv::LineIterator it(open, cut[0], end, 8);
    for (int k = 0; k < it.count; ++k, ++it) {
      const cv::Point c = it.pos();
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = c.x + dx, y = c.y + dy;
          if (x < 0 || y < 0 || x >= open.cols || y >= open.rows) continue;
          const int region = regions.at(x, y);
          const auto r = static_cast<std::size_t>(region);
          if (region == 0) continue;
          cut_touches[r] = 1;
          if (regions.room_votes[r] + regions.hallway_votes[r] > 0) touching.push_back(region);
        }
      }
    }
  }
  std::sort(touching.begin(), touching.end());
  touching.erase(std::unique(touching.begin(), touching.end()), touching.end());
  return touching;
}

// The rooms of the merged regions (0: none), numbered in region order: a region (or merged
// hallway) with a room or hallway node, within the area limits.
std::vector<Label> number_rooms(const OccupancyGrid& work, const AreaLimits& room_area,
                                const Regions& regions,
                                const std::vector<std::uint8_t>& cut_touches, Groups& merged) {
  const int count = regions.count;
  std::vector<long> cells(static_cast<std::size_t>(count), 0), voters(cells.size(), 0);
  for (int y = 0; y < work.height(); ++y)
    for (int x = 0; x < work.width(); ++x)
      ++cells[merged.find(static_cast<std::size_t>(regions.at(x, y)))];
  for (int region = 1; region < count; ++region) {
    const auto r = static_cast<std::size_t>(region);
    // A piece of free space no cut touches and no node lies in (too narrow for the graph) is a
    // room of its own: nothing could grow into it.
    voters[merged.find(r)] +=
        regions.room_votes[r] + regions.hallway_votes[r] + (cut_touches[r] ? 0 : 1);
  }
  const double cell_area = work.resolution * work.resolution;
  std::vector<Label> room_of(static_cast<std::size_t>(count), 0);
  Label next = 0;
  for (int region = 1; region < count; ++region) {
    const std::size_t root = merged.find(static_cast<std::size_t>(region));
    if (room_of[root] != 0 || next == 65535) continue;
    if (voters[root] > 0 && room_area.contains(static_cast<double>(cells[root]) * cell_area))
      room_of[root] = ++next;
  }
  return room_of;
}

}  // namespace

LabelImage vrf_rooms(const OccupancyGrid& work, const VrfLabelling& labelling,
                     const VrfParams& params) {
  const AreaLimits& room_area = params.room_area;
  room_area.check("vrf_rooms");
  const int width = work.width(), height = work.height();
  const VrfNodeGraph& graph = labelling.graph;
  const std::vector<PlaceLabel>& labels = labelling.inference.labels;
  require(labels.size() == graph.nodes.size() && graph.voronoi.graph.width() == width &&
              graph.voronoi.graph.height() == height,
          "vrf_rooms: the labelling does not belong to the map");
  const Image<std::uint8_t> free_cells = free_cell_mask(work);
  const NearestObstacles near = nearest_obstacles(free_cells);
  cv::Mat open(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) open.at<std::uint8_t>(y, x) = free_cells(x, y) ? 255 : 0;
  const std::vector<DoorwayCut> cuts = cut_doorways(graph, labels, near, open);
  const Regions regions = vote_regions(open, graph, labels);

  // Hallway regions meeting across a cut are one hallway.
  Groups merged(static_cast<std::size_t>(regions.count));
  std::vector<std::uint8_t> cut_touches(static_cast<std::size_t>(regions.count), 0);
  for (const DoorwayCut& cut : cuts) {
    int first_hallway = 0;
    for (const int region : regions_along_cut(cut, open, regions, cut_touches)) {
      if (!regions.hallway(region)) continue;
      if (first_hallway == 0) first_hallway = region;
      merged.join(static_cast<std::size_t>(region), static_cast<std::size_t>(first_hallway));
    }
  }
  const std::vector<Label> room_of = number_rooms(work, room_area, regions, cut_touches, merged);
  LabelImage rooms(width, height, 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int region = regions.at(x, y);
      if (region != 0) rooms(x, y) = room_of[merged.find(static_cast<std::size_t>(region))];
    }
  }
  grow_rooms(rooms, work);
  return rooms;
}

RoomSegmentation segment_voronoi_random_field(const OccupancyGrid& map, const VrfModel& model,
                                              const VrfParams& params) {
  const auto start = std::chrono::steady_clock::now();
  const std::string what = "Voronoi random field segmentation";
  check_map(map, what);
  params.room_area.check(what);
  require(!model.empty(), what + ": the VRF model is empty (load or train one)");
  const OccupancyGrid work = params.furniture ? without_furniture(map, *params.furniture) : map;
  const VrfLabelling labelling = label_voronoi_nodes(work, model, params);
  return finish_segmentation(vrf_rooms(work, labelling, params),
                             room_cells(map, work, params.furniture), "vrf", start);
}

}  // namespace kartograf::rooms
