#pragma once
// One interface over the dataset layouts sba-slam reads (KITTI odometry, EuRoC ASL, TUM RGB-D).
//
// Error policy: the constructor validates the whole listing (files present, timestamps strictly
// increasing, counts consistent, calibration readable) and throws sbaslam::Error naming the file
// on the first problem, without decoding any image. load(i) decodes frame i and throws
// sbaslam::Error naming the image if it cannot be decoded (truncated or corrupt file); the run
// loop decides whether to skip that frame with a warning or stop.

#include <cstddef>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sbaslam/core/camera.h"
#include "sbaslam/core/lie.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/core/trajectory.h"

namespace sbaslam::io {

struct FrameData {
  std::size_t index = 0;
  double timestamp = 0.0;  // seconds
  cv::Mat left;            // CV_8UC1
  cv::Mat right;           // CV_8UC1, empty without a right camera
  cv::Mat depth;           // CV_16UC1 raw values (metres = value / depth factor), or empty
  std::string left_path;   // the left image file, e.g. to find a precomputed saliency map
};

// Calibration carried by the dataset itself, describing the images load() returns.
struct DatasetCalibration {
  CameraSettings camera;            // of the left images as returned (rectified for EuRoC stereo)
  std::optional<StereoRig> stereo;  // when right images are returned
  // Pose of the returned left camera in the dataset's original left camera (cam0): identity
  // except for EuRoC stereo, where it is the rectification rotation. T_world_cam0 =
  // T_world_image * inverse(T_cam0_image).
  SE3 T_cam0_image;
  // Pose of cam0 in the body frame whose poses the ground truth gives (EuRoC T_BS of cam0);
  // identity when the ground truth is that of the camera itself (KITTI, TUM).
  SE3 T_body_cam0;
  // The dataset has no calibration files and the run's settings file calibrated it.
  bool from_settings = false;
};

struct DatasetOptions {
  bool load_right = true;  // read (and for EuRoC rectify) right images when the dataset has them
  bool load_depth = true;  // read depth images when the dataset has them
  // The run's settings file, whose cameras calibrate a dataset that has no calibration files of
  // its own (an EuRoC-layout recording without sensor.yaml); may be null. Outlives the reader's
  // constructor.
  const Settings* settings = nullptr;
};

class DatasetReader {
 public:
  virtual ~DatasetReader();

  virtual std::string kind() const = 0;  // "kitti", "euroc" or "tum"
  virtual std::size_t size() const = 0;
  virtual double timestamp(std::size_t i) const = 0;
  // Decodes frame i: grayscale 8-bit images, rectified where the dataset needs it.
  virtual FrameData load(std::size_t i) const = 0;
  virtual bool has_right() const { return false; }
  virtual bool has_depth() const { return false; }
  // Ground truth in the dataset's own convention (see each reader), if the files are present.
  virtual std::optional<Trajectory> ground_truth() const { return std::nullopt; }
  // Calibration carried by the dataset (KITTI calib.txt, EuRoC sensor.yaml); TUM has none.
  virtual std::optional<DatasetCalibration> calibration() const { return std::nullopt; }
  // Where a pixel of the left image load() returns lies in the left image file. The identity
  // except where load() rectifies (EuRoC stereo).
  virtual Vec2 file_pixel(const Vec2& image_pixel) const { return image_pixel; }
};

// kind is "kitti" (path: .../sequences/XX), "euroc" (path: the folder holding mav0/) or "tum"
// (path: the folder holding rgb.txt). Throws sbaslam::Error for an unknown kind or a bad dataset.
std::unique_ptr<DatasetReader> make_dataset_reader(const std::string& kind, const std::string& path,
                                                   const DatasetOptions& options = {});

// Strictly increasing stamps, or sbaslam::Error naming the file and the first offending entry.
void check_increasing_stamps(const std::vector<double>& stamps, const std::string& path);

}  // namespace sbaslam::io
