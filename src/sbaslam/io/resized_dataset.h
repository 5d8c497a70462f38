#pragma once
// ORB-SLAM3's Camera.newWidth / Camera.newHeight: every image a dataset gives is resized before
// tracking, and the camera scaled with it. Pixel centres sit at integer coordinates, as in
// cv::resize, so a pixel u of the original image lies at (u + 0.5) s - 0.5 in the resized one
// (ORB-SLAM3 scales cx by s alone, 0.5 (s - 1) px away from where cv::resize puts it).

#include <memory>
#include <opencv2/core.hpp>

#include "sbaslam/io/dataset.h"

namespace sbaslam::io {

struct ImageScaling {
  cv::Size from, to;

  double sx() const { return static_cast<double>(to.width) / from.width; }
  double sy() const { return static_cast<double>(to.height) / from.height; }
  PinholeIntrinsics scaled(const PinholeIntrinsics& k) const;
  // The camera of the resized images: intrinsics scaled, size `to`, lens unchanged.
  CameraSettings scaled(const CameraSettings& camera) const;
  // A pixel of the resized image in the original one.
  Vec2 to_original(const Vec2& pixel) const;
};

// The scaling that ORB-SLAM3's keys ask of images of `from`'s size (sides left at 0 keep theirs).
// Throws sbaslam::Error naming the settings file if a side would grow or shrink by more than 8x.
ImageScaling image_scaling(const ImageResize& resize, cv::Size from, const std::string& settings);

// A dataset whose frames come resized: images by pixel area when shrinking (linearly when
// growing), depth images by the nearest pixel, so no depth is mixed across an edge.
class ResizedDataset : public DatasetReader {
 public:
  ResizedDataset(std::unique_ptr<DatasetReader> inner, ImageScaling scaling);

  std::string kind() const override { return inner_->kind(); }
  std::size_t size() const override { return inner_->size(); }
  double timestamp(std::size_t i) const override { return inner_->timestamp(i); }
  // Throws sbaslam::Error naming the image if it is not of the size the settings describe.
  FrameData load(std::size_t i) const override;
  bool has_right() const override { return inner_->has_right(); }
  bool has_depth() const override { return inner_->has_depth(); }
  std::optional<Trajectory> ground_truth() const override { return inner_->ground_truth(); }
  // The inner dataset's, scaled.
  std::optional<DatasetCalibration> calibration() const override;
  Vec2 file_pixel(const Vec2& image_pixel) const override;

 private:
  std::unique_ptr<DatasetReader> inner_;
  ImageScaling scaling_;
};

}  // namespace sbaslam::io
