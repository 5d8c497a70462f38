#include "sbaslam/map/map_point.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "sbaslam/map/keyframe.h"
#include "sbaslam/map/map.h"
#include "sbaslam/match/hamming.h"

namespace sbaslam::map {

bool KeyFrameIdLess::operator()(const KeyFrame* a, const KeyFrame* b) const {
  return a->id() < b->id();
}

MapPoint::MapPoint(std::size_t id, const Vec3& position, KeyFrame* reference, Map* map)
    : position_(position),
      id_(id),
      first_keyframe_id_(reference ? reference->id() : 0),
      reference_(reference),
      map_(map) {}

void MapPoint::add_observation(KeyFrame* kf, std::size_t keypoint) {
  if (!observations_.emplace(kf, keypoint).second) return;
  observation_count_ += kf->measurements().u_right[keypoint] >= 0.0f ? 2 : 1;
}

void MapPoint::erase_observation(KeyFrame* kf) {
  const auto it = observations_.find(kf);
  if (it == observations_.end()) return;
  observation_count_ -= kf->measurements().u_right[it->second] >= 0.0f ? 2 : 1;
  observations_.erase(it);
  if (reference_ == kf && !observations_.empty()) reference_ = observations_.begin()->first;
  if (observation_count_ <= 2) set_bad();
}

long MapPoint::keypoint_in(const KeyFrame* kf) const {
  const auto it = observations_.find(const_cast<KeyFrame*>(kf));
  return it == observations_.end() ? -1 : static_cast<long>(it->second);
}

void MapPoint::set_bad() {
  if (bad_) return;
  bad_ = true;
  const Observations observations = std::move(observations_);
  observations_.clear();
  observation_count_ = 0;
  for (const auto& [kf, index] : observations) kf->erase_map_point(index);
  map_->erase_map_point(this);
}

void MapPoint::replace_with(MapPoint* other) {
  if (other == this || bad_) return;
  const Observations observations = std::move(observations_);
  observations_.clear();
  bad_ = true;
  replaced_by_ = other;
  for (const auto& [kf, index] : observations) {
    if (other->is_in_keyframe(kf)) {
      kf->erase_map_point(index);
    } else {
      kf->add_map_point(other, index);
      other->add_observation(kf, index);
    }
  }
  other->increase_found(found_);
  other->increase_visible(visible_);
  other->update_descriptor();
  map_->erase_map_point(this);
}

void MapPoint::update_descriptor() {
  if (bad_ || observations_.empty()) return;
  std::vector<const std::uint8_t*> descriptors;
  descriptors.reserve(observations_.size());
  for (const auto& [kf, index] : observations_)
    if (!kf->is_bad()) descriptors.push_back(kf->measurements().descriptor(index));
  if (descriptors.empty()) return;

  const std::size_t n = descriptors.size();
  std::vector<int> distances(n * n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const int d = match::descriptor_distance(descriptors[i], descriptors[j]);
      distances[i * n + j] = d;
      distances[j * n + i] = d;
    }
  std::size_t best = 0;
  int best_median = match::kMaxDescriptorDistance + 1;
  std::vector<int> row(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::copy(distances.begin() + static_cast<long>(i * n),
              distances.begin() + static_cast<long>((i + 1) * n), row.begin());
    std::nth_element(row.begin(), row.begin() + static_cast<long>((n - 1) / 2), row.end());
    const int median = row[(n - 1) / 2];
    if (median < best_median) {
      best_median = median;
      best = i;
    }
  }
  descriptor_ = cv::Mat(1, match::kDescriptorBytes, CV_8U);
  std::copy(descriptors[best], descriptors[best] + match::kDescriptorBytes,
            descriptor_.ptr<std::uint8_t>());
}

void MapPoint::update_normal_and_depth() {
  if (bad_ || observations_.empty() || reference_ == nullptr) return;
  Vec3 normal = Vec3::Zero();
  int n = 0;
  for (const auto& [kf, index] : observations_) {
    normal += (position_ - kf->camera_center()).normalized();
    ++n;
  }
  const long index = keypoint_in(reference_);
  if (index < 0) return;
  const Vec3 from_reference = position_ - reference_->camera_center();
  const double distance = from_reference.norm();
  const feature::ScaleLevels& levels = reference_->rig().levels;
  const int level = reference_->measurements().keypoints_un[static_cast<std::size_t>(index)].octave;
  max_distance_ = distance * levels.scale[static_cast<std::size_t>(level)];
  min_distance_ = max_distance_ / levels.scale.back();
  normal_ = normal / n;
}

int MapPoint::predict_level(double distance, const feature::ScaleLevels& levels) const {
  const double ratio = max_distance_ / distance;
  const double log_scale = std::log(static_cast<double>(levels.scale[1]));
  const int level = static_cast<int>(std::ceil(std::log(ratio) / log_scale));
  return std::clamp(level, 0, levels.size() - 1);
}

}  // namespace sbaslam::map
