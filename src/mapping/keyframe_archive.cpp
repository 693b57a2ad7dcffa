#include "mapping/keyframe_archive.hpp"

#include <span>
#include <string>
#include <utility>

#include "kartograf/core/error.hpp"

namespace kartograf::mapping {

KeyframeArchive::KeyframeArchive(std::shared_ptr<const registration::FeatureFrontEnd> front_end,
                                 std::size_t memory_budget)
    : front_end_(std::move(front_end)), memory_budget_(memory_budget) {}

void KeyframeArchive::add(Entry entry) {
  require(!entry.features || front_end_,
          "loop closure keyframes: features given without the front end that made them");
  Record record;
  record.has_features = entry.features != nullptr;
  record.bytes = entry.samples.size() * sizeof(Eigen::Vector3f) +
                 (entry.features ? entry.features->memory_bytes() : 0);
  record.entry = std::make_shared<const Entry>(std::move(entry));
  memory_bytes_ += record.bytes;
  records_.push_back(std::move(record));
  // The oldest leave first: loop candidates are mostly the newest keyframe against a few old ones.
  while (memory_bytes_ > memory_budget_ && first_in_memory_ < records_.size())
    spill(records_[first_in_memory_++]);
}

void KeyframeArchive::spill(Record& record) {
  const Entry& entry = *record.entry;
  std::vector<std::uint8_t> features;
  if (entry.features) features = front_end_->serialize(*entry.features);
  const std::span<const std::uint8_t> pieces[] = {
      bytes_of(entry.samples.data(), entry.samples.size()), features};
  record.offset = file_.append(std::span<const std::span<const std::uint8_t>>(pieces));
  record.samples = entry.samples.size();
  record.feature_bytes = features.size();
  record.entry.reset();
  memory_bytes_ -= record.bytes;
  record.bytes = 0;
}

const KeyframeArchive::Record& KeyframeArchive::record(std::size_t k) const {
  require(k < records_.size(), "loop closure keyframes: no keyframe " + std::to_string(k));
  return records_[k];
}

bool KeyframeArchive::has_features(std::size_t k) const {
  return record(k).has_features;
}

std::shared_ptr<const KeyframeArchive::Entry> KeyframeArchive::at(std::size_t k) const {
  const Record& record = this->record(k);
  if (record.entry) return record.entry;
  auto entry = std::make_shared<Entry>();
  entry->samples.resize(record.samples);
  file_.read(record.offset, bytes_of(entry->samples.data(), record.samples));
  if (record.has_features) {
    std::vector<std::uint8_t> features(record.feature_bytes);
    file_.read(record.offset + record.samples * sizeof(Eigen::Vector3f), features);
    entry->features = front_end_->deserialize(features);
  }
  return entry;
}

}  // namespace kartograf::mapping
