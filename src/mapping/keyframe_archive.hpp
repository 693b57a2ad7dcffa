#pragma once
// The loop closure's per-keyframe data besides depth (mapping/loop_closure.hpp): the overlap
// samples and the local features. The newest keyframes stay in memory up to a budget; older ones
// are written once to a temporary file as they leave it and read back when a loop candidate needs
// them, so that a long run's memory does not grow by them (35-65 KB a keyframe).
#include <cstddef>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "kartograf/mapping/spill_file.hpp"
#include "kartograf/registration/feature_front_end.hpp"

namespace kartograf::mapping {

class KeyframeArchive {
 public:
  struct Entry {
    std::vector<Eigen::Vector3f> samples;                              // camera frame
    std::shared_ptr<const registration::FeatureDescription> features;  // or null
  };

  // front_end: what made the features (null: no keyframe has any); it writes and reads them.
  KeyframeArchive(std::shared_ptr<const registration::FeatureFrontEnd> front_end,
                  std::size_t memory_budget);

  void add(Entry entry);
  // Keyframe k's data, from memory or from the file; Error when there is no keyframe k.
  std::shared_ptr<const Entry> at(std::size_t k) const;
  // Whether keyframe k has features, without reading it back; Error when there is no keyframe k.
  bool has_features(std::size_t k) const;
  std::size_t size() const { return records_.size(); }
  std::size_t bytes_in_memory() const { return memory_bytes_; }
  std::size_t bytes_on_disk() const { return file_.size(); }

 private:
  struct Record {
    std::shared_ptr<const Entry> entry;                      // null once on disk
    std::size_t bytes = 0;                                   // in memory
    std::size_t offset = 0, samples = 0, feature_bytes = 0;  // in the file
    bool has_features = false;
  };
  void spill(Record& record);
  const Record& record(std::size_t k) const;

  std::shared_ptr<const registration::FeatureFrontEnd> front_end_;
  std::size_t memory_budget_;
  std::vector<Record> records_;
  std::size_t first_in_memory_ = 0;  // records before it are on disk
  std::size_t memory_bytes_ = 0;
  SpillFile file_{"loop closure keyframes"};
};

}  // namespace kartograf::mapping
