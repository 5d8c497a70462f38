#pragma once
// The camera between scene radiance and an 8-bit image: exposure gain, motion blur, vignetting and
// sensor noise, each switchable and seeded. Everything here is a pure function of its arguments,
// so frames can be rendered in any order, on any number of threads, with identical bytes.

#include <cstdint>
#include <opencv2/core.hpp>

namespace sbaslam::sim {

struct ImageEffects {
  bool sensor_noise = true;
  double read_noise = 1.2;   // gray levels, standard deviation
  double shot_noise = 0.03;  // variance per gray level (photon noise grows with brightness)
  bool motion_blur = true;
  bool exposure_changes = true;  // auto-exposure steps and drift between frames
  bool vignetting = true;
  double vignetting_strength = 0.3;  // relative fall-off at the image corners
};

// Turns radiance into an 8-bit image. blur_px is the image motion of the scene during the
// exposure, in pixels (a straight-line blur along it is applied when motion blur is on).
cv::Mat expose_image(const cv::Mat& radiance, double gain, const cv::Vec2d& blur_px,
                     const ImageEffects& effects, std::uint64_t noise_seed);

// Normalised line kernel for a blur of length |blur_px| along its direction; empty when the
// blur is below half a pixel.
cv::Mat motion_blur_kernel(const cv::Vec2d& blur_px);

}  // namespace sbaslam::sim
