#pragma once
// The camera and stereo geometry a run uses: the settings file's, overridden by the dataset's own
// calibration where the reader has one (EuRoC's sensor.yaml, rectified by the reader).

#include <string>

#include "sbaslam/core/lie.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/io/dataset.h"
#include "sbaslam/io/resized_dataset.h"

namespace sbaslam::io {

struct DatasetGeometry {
  CameraSettings camera;
  StereoSettings stereo;
  SE3 T_cam0_image;  // from the images the reader returns to cam0, for reporting cam0 poses
  // Camera.newWidth / newHeight: camera and bf above are of the resized images; the reader's
  // frames must go through ResizedDataset with this.
  std::optional<ImageScaling> scaling;
};

// Whether the settings file's Camera fx and the dataset's own calibration disagree by more than
// 1 % where they describe the same images (not a rig the reader rectifies, nor a calibration
// that came from the settings file itself).
bool settings_fx_disagrees(const Settings& settings, const DatasetCalibration& calib);

// The dataset's calibration describes the images it returns, so it wins over the settings file's
// (then Camera.newWidth / newHeight scale the result from the size of those images);
// a disagreement in fx (settings_fx_disagrees) is logged. With `stereo`, a dataset without right
// images or a rig without a baseline throws sbaslam::Error naming `dataset_path` or the settings
// file; with `rgbd`, a dataset without depth images or settings without Camera.bf (the virtual
// stereo pair of ORB-SLAM3's RGB-D mode) does.
DatasetGeometry resolve_geometry(const Settings& settings, const DatasetReader& reader,
                                 const std::string& dataset_path, bool stereo, bool rgbd = false);

}  // namespace sbaslam::io
