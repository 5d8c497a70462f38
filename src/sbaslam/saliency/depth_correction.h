#pragma once
// Algorithm 1 of the paper: nearer things matter more, S_final = a * S_init / D + b, normalised to
// 0..255. D comes from stereo (SGBM on the rectified pair), an RGB-D depth image, or sparse
// map-point depths densified on a coarse grid (monocular).
//
// Conventions (the paper leaves them open):
//   - S_init is the 8-bit map divided by 255, so S in [0, 1]; D is in metres.
//   - Normalisation divides by the largest value: S_final = 255 * max(S_hat, 0) / max(S_hat).
//     Min-max normalisation would cancel a and b altogether; dividing by the maximum keeps b as a
//     floor that lifts far-away salient points (b / (a / D_min + b) of the peak).
//   - Per pixel fallback: where D is invalid (not finite or <= 0) the pixel uses the median of the
//     valid depths, i.e. it keeps its S_init ranking at a typical depth and is normalised with the
//     others. With no valid depth at all the result is S_init unchanged.
//   - D is resampled (nearest) to the saliency map's size when the two differ.
//   - Optionally D = max(D, near_depth): nearer points then count alike (SaliencySettings).

#include <opencv2/core.hpp>
#include <vector>

namespace sbaslam::saliency {

// S_init = min(1, S_init / saturation) on the 8-bit map (saturation in (0, 1]; 1 returns the map
// itself): values above saturation * 255 all become 255.
cv::Mat saturated_saliency(const cv::Mat& s_init, double saturation);

// s_init: CV_8U; depth: CV_32F metres (any size). Returns CV_8U of s_init's size. Depths below
// near_depth count as near_depth.
cv::Mat depth_corrected_saliency(const cv::Mat& s_init, const cv::Mat& depth, double a, double b,
                                 double near_depth = 0.0);

// CV_32F depth in metres from a rectified 8-bit stereo pair with cv::StereoSGBM: D = fx * B / d;
// pixels without a valid disparity are 0 (invalid).
cv::Mat stereo_depth(const cv::Mat& left, const cv::Mat& right, double fx, double baseline,
                     int max_disparity = 128);

// CV_32F metres from a raw RGB-D depth image (16-bit or float): raw / depth_map_factor, 0 invalid.
cv::Mat rgbd_depth(const cv::Mat& raw, double depth_map_factor);

struct DepthSample {
  float u = 0, v = 0;  // pixel
  float depth = 0;     // metres, > 0
};

// The median of the samples' depths (the upper one of an even count); 0 without samples.
double median_sample_depth(const std::vector<DepthSample>& samples);

// Dense CV_32F depth of `size` from sparse samples (monocular map points): samples are averaged
// into cells of cell x cell pixels, empty cells take the inverse-squared-distance weighted mean of
// the k nearest filled cells (equally distant ones taken by row, then column), and the coarse grid
// is upsampled bilinearly. No samples: all 0 (invalid).
cv::Mat densify_sparse_depth(const std::vector<DepthSample>& samples, const cv::Size& size,
                             int cell = 16, int neighbours = 4);

// Algorithm 1 for a stereo frame: D from its matched keypoints (level-0 pixels of the image of
// `image_size`, depths in metres), densified at the saliency map's own resolution with cells of
// about 1/40 of its width.
cv::Mat depth_corrected_saliency(const cv::Mat& s_init, const cv::Size& image_size,
                                 const std::vector<DepthSample>& keypoint_depths, double a,
                                 double b, double near_depth = 0.0);

}  // namespace sbaslam::saliency
