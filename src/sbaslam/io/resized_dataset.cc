#include "sbaslam/io/resized_dataset.h"

#include <opencv2/imgproc.hpp>

#include "sbaslam/core/error.h"

namespace sbaslam::io {
namespace {

cv::Mat resized(const cv::Mat& image, const ImageScaling& scaling, const std::string& path,
                int interpolation) {
  if (image.empty()) return image;
  if (image.size() != scaling.from)
    fail("{}: the image is {}x{}, but the settings describe {}x{} images (Camera.width/height)",
         path, image.cols, image.rows, scaling.from.width, scaling.from.height);
  cv::Mat out;
  cv::resize(image, out, scaling.to, 0.0, 0.0, interpolation);
  return out;
}

}  // namespace

PinholeIntrinsics ImageScaling::scaled(const PinholeIntrinsics& k) const {
  return {k.fx * sx(), k.fy * sy(), (k.cx + 0.5) * sx() - 0.5, (k.cy + 0.5) * sy() - 0.5};
}

CameraSettings ImageScaling::scaled(const CameraSettings& camera) const {
  CameraSettings out = camera;
  out.intrinsics = scaled(camera.intrinsics);
  out.width = to.width;
  out.height = to.height;
  return out;
}

Vec2 ImageScaling::to_original(const Vec2& pixel) const {
  return {(pixel.x() + 0.5) / sx() - 0.5, (pixel.y() + 0.5) / sy() - 0.5};
}

ImageScaling image_scaling(const ImageResize& resize, cv::Size from, const std::string& settings) {
  if (from.width <= 0 || from.height <= 0)
    fail("{}: Camera.newWidth/newHeight given, but the images' own size is unknown", settings);
  ImageScaling scaling{from,
                       {resize.width > 0 ? resize.width : from.width,
                        resize.height > 0 ? resize.height : from.height}};
  constexpr double kMaxFactor = 8.0;
  for (const double s : {scaling.sx(), scaling.sy()})
    if (s > kMaxFactor || s < 1.0 / kMaxFactor)
      fail("{}: Camera.newWidth/newHeight {}x{} resize {}x{} images by more than {}x", settings,
           scaling.to.width, scaling.to.height, from.width, from.height, kMaxFactor);
  return scaling;
}

ResizedDataset::ResizedDataset(std::unique_ptr<DatasetReader> inner, ImageScaling scaling)
    : inner_(std::move(inner)), scaling_(scaling) {}

FrameData ResizedDataset::load(std::size_t i) const {
  FrameData frame = inner_->load(i);
  const int shrink = scaling_.sx() * scaling_.sy() < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR;
  frame.left = resized(frame.left, scaling_, frame.left_path, shrink);
  frame.right = resized(frame.right, scaling_, frame.left_path + " (its right image)", shrink);
  frame.depth = resized(frame.depth, scaling_, frame.left_path + " (its depth image)",
                        cv::INTER_NEAREST_EXACT);
  return frame;
}

std::optional<DatasetCalibration> ResizedDataset::calibration() const {
  std::optional<DatasetCalibration> calib = inner_->calibration();
  if (!calib) return calib;
  calib->camera = scaling_.scaled(calib->camera);
  if (calib->stereo)
    calib->stereo = StereoRig(scaling_.scaled(calib->stereo->intrinsics), calib->stereo->baseline);
  return calib;
}

Vec2 ResizedDataset::file_pixel(const Vec2& image_pixel) const {
  return inner_->file_pixel(scaling_.to_original(image_pixel));
}

}  // namespace sbaslam::io
