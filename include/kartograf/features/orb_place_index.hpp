#pragma once
// Place recognition over ORB descriptions (registration::PlaceIndex): every descriptor of a query
// votes for the place that holds its nearest stored descriptor (Hamming, brute force over all
// places added so far), unless the second nearest belongs to another place and is nearly as near
// (Lowe's ratio test; two near rows of one place still vote for it). A place seen again shares many
// distinctive corners with the query; an unrelated one collects only scattered votes.
#include <cstddef>
#include <memory>
#include <vector>

#include "kartograf/registration/feature_front_end.hpp"

namespace kartograf::features {

struct OrbPlaceParams {
  double ratio = 0.8;          // nearest vs second nearest, when that is another place's
  std::size_t min_votes = 20;  // the similarity floor: fewer votes, not reported
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
