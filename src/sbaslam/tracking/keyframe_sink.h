#pragma once
// What tracking needs of local mapping, so that data flows one way: tracking hands keyframes
// over and asks whether mapping can take more; it never includes mapping's headers.

#include <cstddef>

namespace sbaslam::map {
class KeyFrame;
}

namespace sbaslam::tracking {

class KeyframeSink {
 public:
  virtual ~KeyframeSink() = default;
  virtual void insert_keyframe(map::KeyFrame* kf) = 0;
  // True when mapping has nothing queued and is not processing (ORB-SLAM's AcceptKeyFrames).
  virtual bool is_idle() const = 0;
  virtual std::size_t queued_keyframes() const = 0;
  // Asks a running local BA to stop early so that a new keyframe gets in sooner.
  virtual void interrupt_bundle_adjustment() = 0;
};

}  // namespace sbaslam::tracking
