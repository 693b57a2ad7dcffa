// ORB place recognition by descriptor votes (features/orb_place_index.hpp).
#include "kartograf/features/orb_place_index.hpp"

#include <algorithm>
#include <string>

#include <opencv2/features2d.hpp>

#include "features/orb_description.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::features {

// Places in the order added (ids increasing), so the places below an id hold a prefix of the rows.
struct OrbPlaceIndex::Store {
  std::vector<std::size_t> ids;
  std::vector<int> end_row;    // per place: one past its last row in `descriptors`
  std::vector<int> row_place;  // per row: the position of its place in `ids`
  cv::Mat descriptors;         // every place's rows, one after the other

  // How many places have an id below `before`.
  std::size_t places_below(std::size_t before) const {
    return static_cast<std::size_t>(std::lower_bound(ids.begin(), ids.end(), before) - ids.begin());
  }
};

namespace {

// cv::BFMatcher indexes train rows in 18 bits (IMGIDX_SHIFT): a larger store is searched in blocks.
constexpr int kRowsPerSearch = 1 << 17;

// Per query row, its `count` nearest stored rows (trainIdx in `stored`), nearest first.
std::vector<std::vector<cv::DMatch>> nearest_rows(const cv::Mat& query, const cv::Mat& stored,
                                                  std::size_t count) {
  std::vector<std::vector<cv::DMatch>> best(static_cast<std::size_t>(query.rows));
  const cv::BFMatcher matcher(cv::NORM_HAMMING);
  for (int first = 0; first < stored.rows; first += kRowsPerSearch) {
    const int last = std::min(stored.rows, first + kRowsPerSearch);
    std::vector<std::vector<cv::DMatch>> knn;
    matcher.knnMatch(query, stored.rowRange(first, last), knn, static_cast<int>(count));
    for (const auto& neighbours : knn)
      for (cv::DMatch m : neighbours) {
        m.trainIdx += first;
        auto& kept = best[static_cast<std::size_t>(m.queryIdx)];
        kept.push_back(m);
        std::sort(kept.begin(), kept.end());  // DMatch orders by distance
        if (kept.size() > count) kept.pop_back();
      }
  }
  return best;
}

// Per place (position in the store), the query descriptors whose nearest stored row is its own.
std::vector<std::size_t> count_votes(const cv::Mat& query, const cv::Mat& stored,
                                     const std::vector<int>& row_place, std::size_t place_count,
                                     const OrbPlaceParams& params) {
  std::vector<std::size_t> votes(place_count, 0);
  const auto place_of = [&](const cv::DMatch& m) {
    return static_cast<std::size_t>(row_place[static_cast<std::size_t>(m.trainIdx)]);
  };
  const auto same_place = [&](std::size_t a, std::size_t b) {
    return (a > b ? a - b : b - a) <= params.same_place_span;
  };
  // The nearest row of each place within the span, and one more: the rival, if any.
  const std::size_t searched = 2 * params.same_place_span + 2;
  for (const auto& neighbours : nearest_rows(query, stored, searched)) {
    if (neighbours.empty()) continue;
    const std::size_t place = place_of(neighbours[0]);
    // Near rows of one place (repeated texture) or of the places beside it in the order added (the
    // same view from the next keyframe) still point to that place: the ratio test only weighs the
    // best against a rival elsewhere.
    const auto rival =
        std::find_if(neighbours.begin() + 1, neighbours.end(),
                     [&](const cv::DMatch& m) { return !same_place(place_of(m), place); });
    if (rival != neighbours.end() && neighbours[0].distance >= params.ratio * rival->distance)
      continue;
    ++votes[place];
  }
  return votes;
}

// The first `count` rows: descriptions list the strongest corners first.
cv::Mat strongest_rows(const cv::Mat& descriptors, int count) {
  if (descriptors.rows <= count) return descriptors;  // also the empty (0-dimensional) matrix
  return descriptors.rowRange(0, count);
}

}  // namespace

OrbPlaceIndex::OrbPlaceIndex(const OrbPlaceParams& params)
    : params_(params), store_(std::make_unique<Store>()) {
  require(params.ratio > 0 && params.ratio <= 1, "ORB place index: ratio must be in (0, 1]");
  require(params.same_place_span <= 32, "ORB place index: same_place_span must be at most 32");
  require(params.descriptors_per_place > 0,
          "ORB place index: descriptors_per_place must be positive");
}

OrbPlaceIndex::~OrbPlaceIndex() = default;

void OrbPlaceIndex::add(std::size_t place, const registration::FeatureDescription& features) {
  const OrbDescription& orb = as_orb(features, "ORB place index");
  Store& s = *store_;
  require(s.ids.empty() || place > s.ids.back(),
          "ORB place index: place " + std::to_string(place) + " added after place " +
              (s.ids.empty() ? std::string() : std::to_string(s.ids.back())) +
              " (ids must increase)");
  const cv::Mat strongest = strongest_rows(orb.descriptors(), params_.descriptors_per_place);
  if (strongest.rows > 0) s.descriptors.push_back(strongest);
  s.row_place.insert(s.row_place.end(), static_cast<std::size_t>(strongest.rows),
                     static_cast<int>(s.ids.size()));
  s.end_row.push_back(s.descriptors.rows);
  s.ids.push_back(place);
}

std::vector<registration::PlaceMatch> OrbPlaceIndex::query(
    const registration::FeatureDescription& features, std::size_t before,
    std::size_t max_results) const {
  const cv::Mat query = strongest_rows(as_orb(features, "ORB place query").descriptors(),
                                       params_.descriptors_per_place);
  const Store& s = *store_;
  const std::size_t candidates = s.places_below(before);
  std::vector<registration::PlaceMatch> result;
  if (candidates == 0 || query.rows == 0 || s.end_row[candidates - 1] == 0) return result;
  const cv::Mat stored = s.descriptors.rowRange(0, s.end_row[candidates - 1]);
  const std::vector<std::size_t> votes =
      count_votes(query, stored, s.row_place, candidates, params_);
  for (std::size_t k = 0; k < candidates; ++k)
    if (votes[k] >= params_.min_votes) result.push_back({s.ids[k], static_cast<double>(votes[k])});
  // Stable: equal votes keep the lower id first.
  std::stable_sort(result.begin(), result.end(),
                   [](const auto& a, const auto& b) { return a.score > b.score; });
  if (result.size() > max_results) result.resize(max_results);
  return result;
}

std::size_t OrbPlaceIndex::places() const {
  return store_->ids.size();
}

}  // namespace kartograf::features
