#include "sbaslam/sim/image_effects.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace sbaslam::sim {

cv::Mat motion_blur_kernel(const cv::Vec2d& blur_px) {
  const double length = std::hypot(blur_px[0], blur_px[1]);
  if (length < 0.5) return {};
  const int half = static_cast<int>(std::ceil(0.5 * length)) + 1;
  const int size = 2 * half + 1;
  cv::Mat kernel(size, size, CV_32F, cv::Scalar(0.0f));
  // Splat evenly spaced samples of the segment bilinearly, then normalise.
  const int samples = std::max(8, static_cast<int>(8.0 * length));
  for (int k = 0; k < samples; ++k) {
    const double a = (k + 0.5) / samples - 0.5;
    const double x = half + a * blur_px[0], y = half + a * blur_px[1];
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
    kernel.at<float>(y0, x0) += (1 - fx) * (1 - fy);
    kernel.at<float>(y0, x0 + 1) += fx * (1 - fy);
    kernel.at<float>(y0 + 1, x0) += (1 - fx) * fy;
    kernel.at<float>(y0 + 1, x0 + 1) += fx * fy;
  }
  return kernel / cv::sum(kernel)[0];
}

cv::Mat expose_image(const cv::Mat& radiance, double gain, const cv::Vec2d& blur_px,
                     const ImageEffects& effects, std::uint64_t noise_seed) {
  cv::Mat signal = radiance * (255.0 * gain);
  if (effects.motion_blur) {
    const cv::Mat kernel = motion_blur_kernel(blur_px);
    if (!kernel.empty())
      cv::filter2D(signal, signal, -1, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  }
  const int w = signal.cols, h = signal.rows;
  cv::Mat noise;
  if (effects.sensor_noise) {
    noise.create(h, w, CV_32F);
    cv::RNG rng(noise_seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
  }
  const double cx = 0.5 * (w - 1), cy = 0.5 * (h - 1);
  const double inv_r2 = 1.0 / (cx * cx + cy * cy);
  const float strength =
      effects.vignetting ? static_cast<float>(effects.vignetting_strength) : 0.0f;
  const float read2 = static_cast<float>(effects.read_noise * effects.read_noise);
  const float shot = static_cast<float>(effects.shot_noise);
  // Each step is a simple loop over a row buffer so that the compiler vectorises it; the square
  // root goes through cv::sqrt, whose SIMD code rounds exactly like std::sqrt.
  std::vector<double> dx2(static_cast<std::size_t>(w));
  for (int x = 0; x < w; ++x) dx2[static_cast<std::size_t>(x)] = (x - cx) * (x - cx);
  cv::Mat value_row(1, w, CV_32F), sigma_row(1, w, CV_32F);
  float* value = value_row.ptr<float>();
  float* sigma = sigma_row.ptr<float>();
  cv::Mat out(h, w, CV_8U);
  for (int y = 0; y < h; ++y) {
    const float* s = signal.ptr<float>(y);
    const double dy2 = (y - cy) * (y - cy);
    for (int x = 0; x < w; ++x) {
      const float r2 = static_cast<float>((dx2[static_cast<std::size_t>(x)] + dy2) * inv_r2);
      const float falloff = 1.0f - strength * r2 * (2.0f - r2);  // smooth, flat at the centre
      value[x] = s[x] * falloff;
    }
    if (!noise.empty()) {
      const float* n = noise.ptr<float>(y);
      for (int x = 0; x < w; ++x) sigma[x] = read2 + shot * std::max(0.0f, value[x]);
      cv::sqrt(sigma_row, sigma_row);
      for (int x = 0; x < w; ++x) value[x] += n[x] * sigma[x];
    }
    std::uint8_t* o = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < w; ++x)  // round
      o[x] = static_cast<std::uint8_t>(std::min(std::max(value[x], 0.0f), 255.0f) + 0.5f);
  }
  return out;
}

}  // namespace sbaslam::sim
