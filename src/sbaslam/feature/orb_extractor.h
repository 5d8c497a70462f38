#pragma once
// ORB features with ORB-SLAM's behaviour: a scale pyramid, FAST on a grid of cells with a lower
// threshold where a cell found nothing, a quadtree spreading the keypoints, orientation by
// intensity centroid and a 256-bit steered BRIEF descriptor on the Gaussian-blurred level.
//
// Levels receive a geometric share of the features with ratio 1 / scale_factor from level to level,
// exactly as ORB-SLAM (and OpenCV's ORB) do. Note that this is the ratio of the levels' side
// lengths, not of their areas (which would be 1 / scale_factor^2).

#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "sbaslam/core/settings.h"
#include "sbaslam/feature/gaussian_blur.h"
#include "sbaslam/feature/quadtree.h"

namespace sbaslam::feature {

struct OrbKeypoint {
  float x = 0.0f, y = 0.0f;  // level-0 pixel coordinates (as detected, i.e. distorted)
  float size = 0.0f;         // patch diameter at level 0: 31 * scale of the octave
  float angle = 0.0f;        // degrees in [0, 360), direction of the intensity centroid
  float response = 0.0f;     // FAST score at the keypoint's level
  int octave = 0;            // pyramid level
};

// Per-level scale factors and the variance of a keypoint's position at each level (ORB-SLAM's
// mvLevelSigma2): sigma^2 = scale^2, used to weight reprojection errors in BA.
struct ScaleLevels {
  std::vector<float> scale, inv_scale, sigma2, inv_sigma2;
  static ScaleLevels make(int n_levels, double scale_factor);
  int size() const { return static_cast<int>(scale.size()); }
};

struct OrbFeatures {
  std::vector<OrbKeypoint> keypoints;
  cv::Mat descriptors;  // keypoints.size() x 32, CV_8U; row i describes keypoints[i]
  std::size_t size() const { return keypoints.size(); }
};

// Throws sbaslam::Error naming the ORBextractor.* key for any value ORB-SLAM could not run with.
void validate_orb_settings(const OrbSettings& settings);

// ORB-SLAM's feature allotment: n_features split over the levels as a geometric series of ratio
// 1 / scale_factor, the last level taking what the rounding left.
std::vector<int> features_per_level(const OrbSettings& settings);

// Keypoints lie at least this far from a level's border (ORB-SLAM's EDGE_THRESHOLD).
inline constexpr int kEdgeThreshold = 19;

// Not thread-safe as a whole: use one extractor per image stream (a stereo rig has two). Buffers
// are kept between calls, so extracting a stream of same-size images allocates almost nothing.
//
// extract() is begin(), then extract_level() for every level, then finish(). The levels are
// independent: a caller may run extract_level() for distinct levels on different threads at
// once (StereoExtractor does), with the same result, bit for bit.
class OrbExtractor {
 public:
  explicit OrbExtractor(const OrbSettings& settings);

  // `image` must be 8-bit, one channel; anything else throws sbaslam::Error.
  void extract(const cv::Mat& image, OrbFeatures& out);
  OrbFeatures extract(const cv::Mat& image) {
    OrbFeatures out;
    extract(image, out);
    return out;
  }

  // extract() with the levels, and `beside` (optional, longest first), as parallel tasks on both
  // cores (run_tasks_in_parallel): a monocular frame's extraction and its saliency inference.
  void extract_sharing_cores(const cv::Mat& image, OrbFeatures& out,
                             const std::function<void()>& beside = {});

  // Checks the image and builds its pyramid. `image` must outlive finish().
  void begin(const cv::Mat& image);
  // Detects, spreads and describes the keypoints of one level.
  void extract_level(int level);
  // The levels' keypoints in level order.
  void finish(OrbFeatures& out) const;

  // Unblurred level images of the last extraction (level 0 shares the input's pixels).
  const std::vector<cv::Mat>& pyramid() const { return pyramid_; }
  const ScaleLevels& levels() const { return levels_; }
  const std::vector<int>& wanted_per_level() const { return wanted_per_level_; }
  const OrbSettings& settings() const { return settings_; }

 private:
  // Buffers for one level's work, reused between calls: extract() passes one set through all
  // levels, which keeps it in cache (one set per level cost 2-4 % of the extraction time);
  // extract_level() uses the level's own set, so that levels can run at once.
  struct LevelScratch {
    std::vector<cv::KeyPoint> candidates;
    std::vector<int> kept;
    std::vector<cv::KeyPoint> cell_corners;
    std::vector<int> cell_counts;
    cv::Mat blurred;
    GaussianBlur7 gaussian;
    QuadtreeDistributor quadtree;
  };

  void extract_level(int level, LevelScratch& scratch);
  void build_pyramid(const cv::Mat& image);
  // FAST candidates of one level, in level coordinates, into work.candidates.
  void detect_on_grid(const cv::Mat& level_image, LevelScratch& work) const;
  void add_fallback_corners(const cv::Mat& roi, const cv::Rect& cell, LevelScratch& work) const;
  void describe_level(int level, LevelScratch& work, OrbFeatures& out) const;

  OrbSettings settings_;
  ScaleLevels levels_;
  std::vector<int> wanted_per_level_;
  std::vector<cv::Mat> pyramid_;
  std::vector<LevelScratch> scratch_;        // one per level
  std::vector<OrbFeatures> level_features_;  // the last extraction's keypoints, by level
};

}  // namespace sbaslam::feature
