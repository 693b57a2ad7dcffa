#include "kartograf/rooms/voronoi_graph.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "kartograf/core/error.hpp"
#include "kartograf/rooms/room_segmentation.hpp"
#include "rooms/grid_neighbours.hpp"

namespace kartograf::rooms {

namespace {

// The 8 neighbours in the order the simple-point table uses: E, NE, N, NW, W, SW, S, SE.
constexpr std::array<int, 8> kDx = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr std::array<int, 8> kDy = {0, -1, -1, -1, 0, 1, 1, 1};

// Simple points (8-connected foreground, 4-connected background): removing the cell changes no
// connectivity. Yokoi's connectivity number of the neighbourhood must be 1.
std::array<bool, 256> simple_point_table() {
  std::array<bool, 256> table{};
  for (int config = 0; config < 256; ++config) {
    const auto bg = [&](int k) { return ((config >> (k % 8)) & 1) == 0 ? 1 : 0; };
    int c8 = 0;
    for (int k = 0; k < 8; k += 2) c8 += bg(k) - bg(k) * bg(k + 1) * bg(k + 2);
    table[static_cast<std::size_t>(config)] = c8 == 1;
  }
  return table;
}

const std::array<bool, 256>& simple_points() {
  static const std::array<bool, 256> table = simple_point_table();
  return table;
}

// Bit k set when neighbour k of (x, y) is set in `mask` (outside: unset).
int neighbourhood(const Image<std::uint8_t>& mask, int x, int y) {
  int config = 0;
  for (int k = 0; k < 8; ++k) {
    const int nx = x + kDx[static_cast<std::size_t>(k)], ny = y + kDy[static_cast<std::size_t>(k)];
    if (nx >= 0 && ny >= 0 && nx < mask.width() && ny < mask.height() && mask(nx, ny))
      config |= 1 << k;
  }
  return config;
}

int count_bits(int config) {
  return __builtin_popcount(static_cast<unsigned>(config));
}

// The stretch lengths for this map's resolution (VoronoiGraphParams::reference_resolution).
VoronoiGraphParams at_resolution(VoronoiGraphParams params, double resolution) {
  const double reference = params.reference_resolution;
  params.neighbourhood_index =
      cells_at_resolution(params.neighbourhood_index, reference, resolution, 2);
  params.max_iterations = cells_at_resolution(params.max_iterations, reference, resolution);
  return params;
}

// The free space where the graph may run: opened by a 3x3 square, then eroded twice (reference).
Image<std::uint8_t> graph_domain(const Image<std::uint8_t>& free_cells, double reference,
                                 double resolution) {
  const int width = free_cells.width(), height = free_cells.height();
  cv::Mat m(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) m.at<std::uint8_t>(y, x) = free_cells(x, y) ? 255 : 0;
  const int open = cells_at_resolution(1, reference, resolution);
  cv::erode(m, m, cv::Mat(), cv::Point(-1, -1), open);
  cv::dilate(m, m, cv::Mat(), cv::Point(-1, -1), open);
  cv::erode(m, m, cv::Mat(), cv::Point(-1, -1), cells_at_resolution(2, reference, resolution));
  Image<std::uint8_t> domain(width, height, 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      domain(x, y) = (m.at<std::uint8_t>(y, x) && free_cells(x, y)) ? 1 : 0;
  return domain;
}

// Anchors of the medial axis (integer medial axis): of two 4-neighbours whose nearest obstacles
// lie farther apart than feature_separation x clearance (and > 2 cells), the one nearer to the
// bisector of those obstacles.
Image<std::uint8_t> medial_anchors(const NearestObstacles& near, const Image<std::uint8_t>& domain,
                                   double feature_separation) {
  const int width = domain.width(), height = domain.height();
  Image<std::uint8_t> anchors(width, height, 0);
  const auto consider = [&](int px, int py, int qx, int qy) {
    const float dp = near.clearance(px, py), dq = near.clearance(qx, qy);
    if (dp <= 0 || dq <= 0) return;
    const Eigen::Vector2i fp = near.nearest(px, py), fq = near.nearest(qx, qy);
    const double sep2 = (fp - fq).cast<double>().squaredNorm();
    const double need = std::max(2.0, feature_separation * std::min(dp, dq));
    if (sep2 <= need * need) return;
    const Eigen::Vector2d p(px, py), q(qx, qy);
    const auto bisector = [&](const Eigen::Vector2d& c) {
      return std::abs((c - fp.cast<double>()).squaredNorm() -
                      (c - fq.cast<double>()).squaredNorm());
    };
    const double sp = bisector(p), sq = bisector(q);
    if (sp <= sq && domain(px, py)) anchors(px, py) = 1;
    if (sq <= sp && domain(qx, qy)) anchors(qx, qy) = 1;
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (x + 1 < width) consider(x, y, x + 1, y);
      if (y + 1 < height) consider(x, y, x, y + 1);
    }
  }
  return anchors;
}

// Homotopic thinning of the domain in order of clearance, keeping the anchors: the result is
// connected like the domain and follows the clearance ridges between anchors.
Image<std::uint8_t> thin(const Image<std::uint8_t>& domain, const Image<std::uint8_t>& anchors,
                         const Image<float>& clearance) {
  const int width = domain.width(), height = domain.height();
  const auto& simple = simple_points();
  Image<std::uint8_t> fg = domain;
  constexpr float kBucketsPerCell = 4.0f;
  float max_clearance = 0;
  for (const float c : clearance.pixels()) max_clearance = std::max(max_clearance, c);
  std::vector<std::vector<std::uint32_t>> buckets(
      static_cast<std::size_t>(max_clearance * kBucketsPerCell) + 2);
  const auto bucket_of = [&](std::uint32_t i) {
    return static_cast<std::size_t>(clearance.data()[i] * kBucketsPerCell);
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!fg(x, y) || anchors(x, y)) continue;
      const int config = neighbourhood(fg, x, y);
      if ((config & 0x55) != 0x55) {  // a 4-neighbour is background: on the border
        const auto i = static_cast<std::uint32_t>(y * width + x);
        buckets[bucket_of(i)].push_back(i);
      }
    }
  }
  for (std::size_t b = 0; b < buckets.size(); ++b) {
    for (std::size_t head = 0; head < buckets[b].size(); ++head) {
      const std::uint32_t i = buckets[b][head];
      const int x = static_cast<int>(i % static_cast<std::uint32_t>(width));
      const int y = static_cast<int>(i / static_cast<std::uint32_t>(width));
      if (!fg(x, y)) continue;
      const int config = neighbourhood(fg, x, y);
      if (!simple[static_cast<std::size_t>(config)] || count_bits(config) <= 1) continue;
      fg(x, y) = 0;
      for (int k = 0; k < 8; ++k) {
        const int nx = x + kDx[static_cast<std::size_t>(k)],
                  ny = y + kDy[static_cast<std::size_t>(k)];
        if (nx < 0 || ny < 0 || nx >= width || ny >= height || !fg(nx, ny) || anchors(nx, ny))
          continue;
        const auto j = static_cast<std::uint32_t>(ny * width + nx);
        buckets[std::max(b, bucket_of(j))].push_back(j);  // never behind the sweep
      }
    }
    std::vector<std::uint32_t>().swap(buckets[b]);
  }
  // Anchor clusters can be two cells thick, and 8-paths keep staircase corners: drop every
  // simple cell that is not an end.
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!fg(x, y)) continue;
      const int config = neighbourhood(fg, x, y);
      if (simple[static_cast<std::size_t>(config)] && count_bits(config) >= 2) fg(x, y) = 0;
    }
  }
  return fg;
}

// Collapses every leaf branch into the branch point it starts from; branch points (cells with
// more than two graph neighbours before pruning) stay.
void prune_leaves(Image<std::uint8_t>& graph) {
  const int width = graph.width(), height = graph.height();
  Image<std::uint8_t> branch(width, height, 0);
  std::vector<std::uint32_t> leaves;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!graph(x, y)) continue;
      const int n = count_bits(neighbourhood(graph, x, y));
      if (n > 2)
        branch(x, y) = 1;
      else if (n <= 1)
        leaves.push_back(static_cast<std::uint32_t>(y * width + x));
    }
  }
  for (std::size_t head = 0; head < leaves.size(); ++head) {
    const std::uint32_t i = leaves[head];
    const int x = static_cast<int>(i % static_cast<std::uint32_t>(width));
    const int y = static_cast<int>(i / static_cast<std::uint32_t>(width));
    if (!graph(x, y)) continue;
    graph(x, y) = 0;
    for (int k = 0; k < 8; ++k) {
      const int nx = x + kDx[static_cast<std::size_t>(k)],
                ny = y + kDy[static_cast<std::size_t>(k)];
      if (nx < 0 || ny < 0 || nx >= width || ny >= height || !graph(nx, ny) || branch(nx, ny))
        continue;
      if (count_bits(neighbourhood(graph, nx, ny)) <= 1)
        leaves.push_back(static_cast<std::uint32_t>(ny * width + nx));
    }
  }
}

// Graph cells of >= 2 graph neighbours whose clearance is least in their graph neighbourhood.
std::vector<Eigen::Vector2i> critical_points(const Image<std::uint8_t>& graph,
                                             const Image<float>& clearance,
                                             const VoronoiGraphParams& params) {
  const int width = graph.width(), height = graph.height();
  std::vector<std::uint32_t> stamp(graph.size(), 0);
  std::vector<std::uint32_t> frontier, next;
  std::vector<Eigen::Vector2i> points;
  std::uint32_t visit = 0;
  const auto before = [&](std::uint32_t a, std::uint32_t b) {  // a ranks lower than b
    const float ca = clearance.data()[a], cb = clearance.data()[b];
    return ca < cb || (ca == cb && a < b);
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!graph(x, y) || count_bits(neighbourhood(graph, x, y)) < 2) continue;
      const auto p = static_cast<std::uint32_t>(y * width + x);
      const int rounded = std::max(1, static_cast<int>(std::lround(clearance(x, y))));
      const int wanted = params.neighbourhood_index / rounded;
      ++visit;
      stamp[p] = visit;
      frontier.assign(1, p);
      int found = 0;
      bool minimum = true;
      for (int step = 0;
           step < params.max_iterations && found <= wanted && !frontier.empty() && minimum;
           ++step) {
        next.clear();
        for (const std::uint32_t c : frontier) {
          detail::for_each_neighbour8(c, width, height, [&](std::uint32_t n) {
            if (!graph.data()[n] || stamp[n] == visit) return;
            stamp[n] = visit;
            next.push_back(n);
            ++found;
            if (before(n, p)) minimum = false;
          });
        }
        frontier.swap(next);
      }
      if (minimum) points.emplace_back(x, y);
    }
  }
  return points;
}

// The reference's variant: the graph is cut into stretches, each grown breadth first from the
// first unvisited cell in raster order over unvisited cells (neighbourhood_index / clearance cells
// or max_iterations steps); each stretch gives its cell of least clearance.
std::vector<Eigen::Vector2i> stretch_minima(const Image<std::uint8_t>& graph,
                                            const Image<float>& clearance,
                                            const VoronoiGraphParams& params) {
  const int width = graph.width(), height = graph.height();
  std::vector<std::uint8_t> used(graph.size(), 0);
  std::vector<std::uint32_t> frontier, next;
  std::vector<Eigen::Vector2i> points;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const auto p = static_cast<std::uint32_t>(y * width + x);
      if (!graph(x, y) || used[p]) continue;
      const int rounded = std::max(1, static_cast<int>(std::lround(clearance(x, y))));
      const int wanted = params.neighbourhood_index / rounded;
      used[p] = 1;
      frontier.assign(1, p);
      std::uint32_t best = p;
      int found = 0;
      for (int step = 0; step < params.max_iterations && found <= wanted && !frontier.empty();
           ++step) {
        next.clear();
        for (const std::uint32_t c : frontier) {
          detail::for_each_neighbour8(c, width, height, [&](std::uint32_t n) {
            if (!graph.data()[n] || used[n]) return;
            used[n] = 1;
            next.push_back(n);
            ++found;
            if (clearance.data()[n] < clearance.data()[best] ||
                (clearance.data()[n] == clearance.data()[best] && n < best))
              best = n;
          });
        }
        frontier.swap(next);
      }
      points.emplace_back(static_cast<int>(best % static_cast<std::uint32_t>(width)),
                          static_cast<int>(best / static_cast<std::uint32_t>(width)));
    }
  }
  return points;
}

// The obstacle cells that touch free space (where critical lines may end).
Image<std::uint8_t> obstacle_border(const Image<std::uint8_t>& free_cells) {
  const int width = free_cells.width(), height = free_cells.height();
  Image<std::uint8_t> border(width, height, 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (free_cells(x, y)) continue;
      for (int k = 0; k < 8 && !border(x, y); ++k) {
        const int nx = x + kDx[static_cast<std::size_t>(k)],
                  ny = y + kDy[static_cast<std::size_t>(k)];
        if (nx >= 0 && ny >= 0 && nx < width && ny < height && free_cells(nx, ny)) border(x, y) = 1;
      }
    }
  }
  return border;
}

CriticalLine critical_line(const Eigen::Vector2i& point, const NearestObstacles& near,
                           const Image<std::uint8_t>& border) {
  CriticalLine line;
  line.point = point;
  line.clearance = near.clearance(point.x(), point.y());
  line.basis_a = near.nearest(point.x(), point.y());
  line.basis_b = line.basis_a;
  // The nearest border obstacle farther than the clearance from basis_a: the other side.
  const double d = line.clearance;
  const int radius = static_cast<int>(std::ceil(2.0 * d)) + 2;
  double best = std::numeric_limits<double>::infinity();
  const int x0 = std::max(0, point.x() - radius),
            x1 = std::min(border.width() - 1, point.x() + radius);
  const int y0 = std::max(0, point.y() - radius),
            y1 = std::min(border.height() - 1, point.y() + radius);
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      if (!border(x, y)) continue;
      const Eigen::Vector2i c(x, y);
      const double to_point = (c - point).cast<double>().squaredNorm();
      if (to_point >= best || (c - line.basis_a).cast<double>().squaredNorm() <= d * d) continue;
      best = to_point;
      line.basis_b = c;
    }
  }
  const Eigen::Vector2d a = (line.basis_a - point).cast<double>(),
                        b = (line.basis_b - point).cast<double>();
  const double na = a.norm(), nb = b.norm();
  line.length = na + nb;
  line.angle_deg = (na > 0 && nb > 0 && line.basis_a != line.basis_b)
                       ? std::acos(std::clamp(a.dot(b) / (na * nb), -1.0, 1.0)) * 180.0 / M_PI
                       : 0.0;
  return line;
}

// Drops corner lines and, of critical points too close together, all but the widest angle.
std::vector<CriticalLine> filter_lines(const std::vector<CriticalLine>& lines,
                                       const VoronoiGraphParams& params) {
  std::vector<CriticalLine> kept;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const CriticalLine& a = lines[i];
    if (a.angle_deg < params.min_angle_deg || a.basis_a == a.basis_b) continue;
    const double radius = a.clearance * params.min_critical_point_distance_factor;
    bool keep = true;
    for (std::size_t j = 0; j < lines.size() && keep; ++j) {
      const CriticalLine& b = lines[j];
      if (j == i || (b.point - a.point).cast<double>().norm() >= radius) continue;
      if (a.angle_deg < b.angle_deg)
        keep = false;
      else if (a.angle_deg == b.angle_deg &&
               (a.length > b.length || (a.length == b.length && j < i)))
        keep = false;
    }
    if (keep) kept.push_back(a);
  }
  return kept;
}

}  // namespace

NearestObstacles nearest_obstacles(const Image<std::uint8_t>& free_cells) {
  const int width = free_cells.width(), height = free_cells.height();
  NearestObstacles out{Image<float>(width, height, 0.0f), Image<Eigen::Vector2i>(width, height)};
  // Columns: the nearest obstacle row above or below each cell (rows -1 and height are walls).
  std::vector<int> row_of(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int x = 0; x < width; ++x) {
    int last = -1;
    for (int y = 0; y < height; ++y) {
      if (!free_cells(x, y)) last = y;
      row_of[static_cast<std::size_t>(y) * width + x] = last;
    }
    int next = height;
    for (int y = height - 1; y >= 0; --y) {
      if (!free_cells(x, y)) next = y;
      int& r = row_of[static_cast<std::size_t>(y) * width + x];
      if (next - y < y - r) r = next;
    }
  }
  // Rows: the lower envelope of the parabolas (x - s)^2 + g(s)^2 over columns s = -1 .. width,
  // the outer two being walls (g = 0).
  const int sites = width + 2;
  std::vector<double> g2(static_cast<std::size_t>(sites)), z(static_cast<std::size_t>(sites) + 1);
  std::vector<int> v(static_cast<std::size_t>(sites));
  for (int y = 0; y < height; ++y) {
    for (int s = 0; s < sites; ++s) {
      const int x = s - 1;
      const double g = (x < 0 || x >= width)
                           ? 0.0
                           : std::abs(row_of[static_cast<std::size_t>(y) * width + x] - y);
      g2[static_cast<std::size_t>(s)] = g * g;
    }
    int k = 0;
    v[0] = 0;
    z[0] = -std::numeric_limits<double>::infinity();
    z[1] = std::numeric_limits<double>::infinity();
    const auto intersection = [&](int q, int r) {
      return ((g2[static_cast<std::size_t>(q)] + double(q) * q) -
              (g2[static_cast<std::size_t>(r)] + double(r) * r)) /
             (2.0 * (q - r));
    };
    for (int q = 1; q < sites; ++q) {
      double s = intersection(q, v[static_cast<std::size_t>(k)]);
      while (s <= z[static_cast<std::size_t>(k)]) {  // z[0] = -inf stops it
        --k;
        s = intersection(q, v[static_cast<std::size_t>(k)]);
      }
      ++k;
      v[static_cast<std::size_t>(k)] = q;
      z[static_cast<std::size_t>(k)] = s;
      z[static_cast<std::size_t>(k) + 1] = std::numeric_limits<double>::infinity();
    }
    k = 0;
    for (int x = 0; x < width; ++x) {
      const int q = x + 1;
      while (z[static_cast<std::size_t>(k) + 1] < q) ++k;
      const int s = v[static_cast<std::size_t>(k)];
      const int sx = s - 1;
      const int sy = (sx < 0 || sx >= width) ? y : row_of[static_cast<std::size_t>(y) * width + sx];
      out.nearest(x, y) = Eigen::Vector2i(sx, sy);
      const double d2 = double(q - s) * (q - s) + g2[static_cast<std::size_t>(s)];
      out.clearance(x, y) = free_cells(x, y) ? static_cast<float>(std::sqrt(d2)) : 0.0f;
      if (!free_cells(x, y)) out.nearest(x, y) = Eigen::Vector2i(x, y);
    }
  }
  return out;
}

int cells_at_resolution(double count, double reference_resolution, double resolution, int power) {
  const double scaled = count * std::pow(reference_resolution / resolution, power);
  return static_cast<int>(std::clamp(std::lround(scaled), 1L, long{1} << 30));
}

VoronoiGraph build_voronoi_graph(const OccupancyGrid& map, const VoronoiGraphParams& params) {
  const std::string what = "Voronoi graph";
  check_map(map, what);
  require(params.neighbourhood_index >= 1 && params.max_iterations >= 1,
          what + ": neighbourhood_index and max_iterations must be >= 1");
  require(std::isfinite(params.min_critical_point_distance_factor) &&
              params.min_critical_point_distance_factor >= 0,
          what + ": min_critical_point_distance_factor must be >= 0");
  require(std::isfinite(params.min_angle_deg) && params.min_angle_deg >= 0 &&
              params.min_angle_deg <= 180,
          what + ": min_angle_deg must lie in [0, 180]");
  require(std::isfinite(params.feature_separation) && params.feature_separation >= 0,
          what + ": feature_separation must be >= 0");
  require(std::isfinite(params.reference_resolution) && params.reference_resolution > 0,
          what + ": reference_resolution must be > 0");
  const int width = map.width(), height = map.height();
  Image<std::uint8_t> free_cells(width, height, 0);
  for (std::size_t i = 0; i < free_cells.size(); ++i)
    free_cells.data()[i] = map.cells.data()[i] == CellState::free ? 1 : 0;

  NearestObstacles near = nearest_obstacles(free_cells);
  const Image<std::uint8_t> domain =
      graph_domain(free_cells, params.reference_resolution, map.resolution);
  VoronoiGraph result;
  result.graph =
      thin(domain, medial_anchors(near, domain, params.feature_separation), near.clearance);
  prune_leaves(result.graph);
  const Image<std::uint8_t> border = obstacle_border(free_cells);
  const VoronoiGraphParams scaled = at_resolution(params, map.resolution);
  const std::vector<Eigen::Vector2i> points =
      params.stretch_minima ? stretch_minima(result.graph, near.clearance, scaled)
                            : critical_points(result.graph, near.clearance, scaled);
  for (const Eigen::Vector2i& p : points)
    result.candidates.push_back(critical_line(p, near, border));
  result.critical_lines = filter_lines(result.candidates, params);
  result.clearance = std::move(near.clearance);
  return result;
}

}  // namespace kartograf::rooms
