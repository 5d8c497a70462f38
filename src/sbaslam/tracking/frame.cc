#include "sbaslam/tracking/frame.h"

namespace sbaslam::tracking {

int Frame::matched_count() const {
  int count = 0;
  for (const map::MapPoint* mp : map_points)
    if (mp && !mp->is_bad()) ++count;
  return count;
}

int Frame::discard_outliers() {
  int good = 0;
  for (std::size_t i = 0; i < map_points.size(); ++i) {
    if (!map_points[i]) continue;
    if (outlier[i]) {
      map_points[i]->track_in_view = false;
      map_points[i]->last_seen_frame = id;
      map_points[i] = nullptr;
      outlier[i] = 0;
    } else if (!map_points[i]->is_bad()) {
      ++good;
    }
  }
  return good;
}

}  // namespace sbaslam::tracking
