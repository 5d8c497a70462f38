#include "helper/orbslam2_stereo.h"

#include <fmt/format.h>

#include <opencv2/calib3d.hpp>

#include "helper/fixture_copy.h"
#include "sbaslam/core/camera.h"
#include "sbaslam/io/euroc_sensor.h"

namespace sbaslam::test {
namespace {

CameraRectification side(const CameraSettings& raw, const cv::Mat& R, const cv::Mat& P) {
  CameraRectification r;
  r.raw = raw;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) {
      if (j < 3) r.R(i, j) = R.at<double>(i, j);
      r.P(i, j) = P.at<double>(i, j);
    }
  return r;
}

std::string matrix_text(const std::string& key, int rows, int cols, const double* values,
                        bool quirk) {
  std::string text =
      fmt::format("{}: !!opencv-matrix\n   rows: {}\n   cols: {}\n   dt: d\n", key, rows, cols);
  text += quirk ? "   data:[" : "   data: [";
  for (int i = 0; i < rows * cols; ++i) text += fmt::format("{}{:.17g}", i ? ", " : "", values[i]);
  return text + "]\n";
}

std::string side_text(const std::string& name, const CameraRectification& r) {
  const PinholeIntrinsics& k = r.raw.intrinsics;
  const RadTanDistortion& d = r.raw.distortion;
  const double K[] = {k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0};
  const double D[] = {d.k1, d.k2, d.p1, d.p2, d.k3};
  double R[9], P[12];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) {
      if (j < 3) R[3 * i + j] = r.R(i, j);
      P[4 * i + j] = r.P(i, j);
    }
  return fmt::format("{0}.height: {1}\n{0}.width: {2}\n", name, r.raw.height, r.raw.width) +
         matrix_text(name + ".D", 1, 5, D, true) + matrix_text(name + ".K", 3, 3, K, false) +
         matrix_text(name + ".R", 3, 3, R, false) + matrix_text(name + ".P", 3, 4, P, false);
}

}  // namespace

PrecomputedRectification euroc_fixture_rectification(double alpha) {
  const std::string mav0 = euroc_fixture_dir() + "/mav0";
  const io::EurocCameraSensor cam0 = io::read_euroc_camera_sensor(mav0 + "/cam0/sensor.yaml");
  const io::EurocCameraSensor cam1 = io::read_euroc_camera_sensor(mav0 + "/cam1/sensor.yaml");
  const SE3 T_c2_c1 = cam1.T_BS.inverse() * cam0.T_BS;
  cv::Mat R(3, 3, CV_64F), t(3, 1, CV_64F);
  for (int i = 0; i < 3; ++i) {
    t.at<double>(i) = T_c2_c1.translation()(i);
    for (int j = 0; j < 3; ++j) R.at<double>(i, j) = T_c2_c1.rotation()(i, j);
  }
  const cv::Size size(cam0.camera.width, cam0.camera.height);
  cv::Mat R1, R2, P1, P2, Q;
  const PinholeCamera left(cam0.camera), right(cam1.camera);
  cv::stereoRectify(cv::Mat(left.K()), left.dist_coeffs(), cv::Mat(right.K()), right.dist_coeffs(),
                    size, R, t, R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY, alpha, size);
  return {side(cam0.camera, R1, P1), side(cam1.camera, R2, P2)};
}

std::string orbslam2_stereo_settings(const PrecomputedRectification& r) {
  const Mat34& P = r.left.P;
  return fmt::format(R"(%YAML:1.0

Camera.type: "PinHole"
Camera.fx: {:.17g}
Camera.fy: {:.17g}
Camera.cx: {:.17g}
Camera.cy: {:.17g}
Camera.k1: 0.0
Camera.k2: 0.0
Camera.p1: 0.0
Camera.p2: 0.0
Camera.bFishEye: 0
Camera.width: {}
Camera.height: {}
Camera.fps: 20.0
Camera.bf: {:.17g}
Camera.RGB: 1
ThDepth: 35.0
)",
                     P(0, 0), P(1, 1), P(0, 2), P(1, 2), r.left.raw.width, r.left.raw.height,
                     -r.right.P(0, 3)) +
         side_text("LEFT", r.left) + "\n" + side_text("RIGHT", r.right) + R"(
ORBextractor.nFeatures: 1200
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 20
ORBextractor.minThFAST: 7
Viewer.KeyFrameSize: 0.05
Viewer.PointSize:2
Viewer.ViewpointF: 500
)";
}

}  // namespace sbaslam::test
