#pragma once
// Place recognition over ORB descriptions (registration::PlaceIndex): every descriptor of a query
// votes for the place that holds its nearest stored descriptor (Hamming, brute force over all
// places added so far), unless the nearest row of a place elsewhere is nearly as near (Lowe's
// ratio test; near rows of one place, or of the places added just before and after it, which see
// the same corners, still vote for it). A place seen again shares many
// distinctive corners with the query; an unrelated one collects only scattered votes.
#include <cstddef>
#include <memory>
#include <vector>

#include "kartograf/registration/feature_front_end.hpp"

namespace kartograf::features {

struct OrbPlaceParams {
  double ratio = 0.8;          // nearest vs second nearest, when that is another place's
  std::size_t min_votes = 20;  // the similarity floor: fewer votes, not reported
  // Places this close in the order added (consecutive keyframes) see the same corners: a row of
  // one of them is no rival in the ratio test. 0: every other place is a rival, so a place seen
  // again lost the votes its neighbours shared (survey seed 11's tour back at its start: 12 votes
  // for the place it began at, where 31 with this span).
  std::size_t same_place_span = 3;
  // Only each place's and each query's strongest descriptors are matched: the search costs
  // (places x this) x this Hamming distances.
  int descriptors_per_place = 300;
};

// Over descriptions made by OrbFrontEnd; keeps each place's strongest descriptors (about 10 KB a
// place), not the descriptions. query() may run on several threads at once, but not while add()
// runs (the caller serialises adding).
class OrbPlaceIndex final : public registration::PlaceIndex {
 public:
  explicit OrbPlaceIndex(const OrbPlaceParams& params = {});
  ~OrbPlaceIndex() override;
  OrbPlaceIndex(const OrbPlaceIndex&) = delete;
  OrbPlaceIndex& operator=(const OrbPlaceIndex&) = delete;

  // Throws Error when place is not above every id added before, or the features are not ORB's.
  void add(std::size_t place, const registration::FeatureDescription& features) override;
  // Scores are the votes (a count), best first; ties: the lower id first.
  std::vector<registration::PlaceMatch> query(const registration::FeatureDescription& features,
                                              std::size_t before,
                                              std::size_t max_results) const override;
  std::size_t places() const;

 private:
  struct Store;  // the descriptors of every place, one matrix (OpenCV stays in the .cpp)
  OrbPlaceParams params_;
  std::unique_ptr<Store> store_;
};

}  // namespace kartograf::features
