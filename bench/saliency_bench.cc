// Saliency model inference on one core at the model's input size (the paper: 8 ms on a GPU), the
// depth correction of Algorithm 1 at KITTI resolution, and what saliency adds to a stereo frame's
// front end.

#include <benchmark/benchmark.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include "sbaslam/io/dataset.h"
#include "sbaslam/io/dataset_geometry.h"
#include "sbaslam/saliency/depth_correction.h"
#include "sbaslam/saliency/observation_weight.h"
#include "sbaslam/saliency/saliency_model.h"
#include "sbaslam/tracking/measurement_builder.h"

namespace {

const std::string kKittiImage =
    std::string(SBASLAM_SHARED_DIR) + "/data/kitti06_first51/sequences/06/image_0/000000.png";

void BM_SaliencyModel(benchmark::State& state) {
  cv::setNumThreads(static_cast<int>(state.range(0)));
  sbaslam::saliency::SaliencyModel model(sbaslam::saliency::shipped_model_path());
  const cv::Mat image = cv::imread(kKittiImage, cv::IMREAD_GRAYSCALE);
  model.predict(image);  // OpenCV dnn's one-time setup
  for (auto _ : state) benchmark::DoNotOptimize(model.predict(image));
  state.SetLabel(std::to_string(model.input_size().width) + "x" +
                 std::to_string(model.input_size().height) + " from 1226x370");
}
BENCHMARK(BM_SaliencyModel)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_DepthCorrection(benchmark::State& state) {
  cv::setNumThreads(1);
  cv::Mat s(370, 1226, CV_8U), d(370, 1226, CV_32F);
  cv::randu(s, 0, 256);
  cv::randu(d, 1.0, 50.0);
  for (auto _ : state)
    benchmark::DoNotOptimize(sbaslam::saliency::depth_corrected_saliency(s, d, 1.0, 0.1));
}
BENCHMARK(BM_DepthCorrection)->Unit(benchmark::kMillisecond);

// What tracking adds to inference per stereo frame: Algorithm 1 on the model's 320x96 map with
// D densified from the frame's matched keypoints (an EuRoC frame has ~700 of 1200), then one
// weight per keypoint.
void BM_StereoFrameWeights(benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Size image(752, 480);
  cv::Mat s(96, 320, CV_8U);
  cv::randu(s, 0, 256);
  cv::RNG rng(7);
  std::vector<sbaslam::saliency::DepthSample> depths;
  std::vector<sbaslam::feature::OrbKeypoint> keypoints(1200);
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    keypoints[i].x = rng.uniform(0.f, 752.f);
    keypoints[i].y = rng.uniform(0.f, 480.f);
    if (i % 12 < 7) depths.push_back({keypoints[i].x, keypoints[i].y, rng.uniform(0.5f, 20.f)});
  }
  const sbaslam::SaliencySettings settings;
  for (auto _ : state) {
    const cv::Mat corrected =
        sbaslam::saliency::depth_corrected_saliency(s, image, depths, 1.0, 0.0);
    benchmark::DoNotOptimize(
        sbaslam::saliency::keypoint_weights(corrected, image, keypoints, settings));
  }
}
BENCHMARK(BM_StereoFrameWeights)->Unit(benchmark::kMillisecond);

// The front end of one EuRoC stereo frame (rectified pair, config/EuRoC_stereo.yaml, OpenCV's
// default threads as in a run): 0 = uniform, no map; 1 = the shipped model's map, depth correction
// and weights. 1 - 0 is what saliency adds before tracking; compare it with BM_SaliencyModel/2.
void BM_StereoFrontEndSaliency(benchmark::State& state) {
  cv::setNumThreads(-1);  // the default: the benches above leave one thread set
  const sbaslam::Settings settings =
      sbaslam::load_settings(std::string(SBASLAM_SOURCE_DIR) + "/config/EuRoC_stereo.yaml");
  const std::string euroc = std::string(SBASLAM_SHARED_DIR) + "/data/euroc_v101_micro";
  const auto reader = sbaslam::io::make_dataset_reader("euroc", euroc);
  const sbaslam::io::DatasetGeometry geometry =
      sbaslam::io::resolve_geometry(settings, *reader, euroc, true);
  const sbaslam::map::CameraRig rig =
      sbaslam::tracking::make_camera_rig(geometry.camera, geometry.stereo, settings.orb, true);
  sbaslam::tracking::MeasurementBuilder builder(rig, settings.orb, settings.saliency);
  sbaslam::saliency::SaliencyModel model(sbaslam::saliency::shipped_model_path());
  const sbaslam::io::FrameData frame = reader->load(0);
  model.predict(frame.left);  // OpenCV dnn's one-time setup
  const bool with_saliency = state.range(0) == 1;
  for (auto _ : state) {
    const cv::Mat map = with_saliency ? model.predict(frame.left) : cv::Mat();
    benchmark::DoNotOptimize(builder.build(frame.left, frame.right, map)->weights.data());
  }
}
BENCHMARK(BM_StereoFrontEndSaliency)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
