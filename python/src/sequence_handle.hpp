#pragma once
// A sequence folder opened for Python: the reader, and what opening it found.
#include <memory>

#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/pipeline/sequence_frame_source.hpp"

namespace kartograf::python {

struct SequenceHandle {
  io::OpenedSequence opened;

  // The frames as the pipelines read them (ground truth collected as they are read).
  std::unique_ptr<pipeline::SequenceFrameSource> source() const {
    return std::make_unique<pipeline::SequenceFrameSource>(*opened.sequence);
  }
};

}  // namespace kartograf::python
