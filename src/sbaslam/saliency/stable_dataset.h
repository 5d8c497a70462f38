#pragma once
// `sba-slam saliency make-dataset --images DIR --stable RUN/stable_features.csv`: a saliency
// dataset whose fixations are the stable features of a SLAM run (self-supervised labels) instead
// of the semantic gaze. The files are those of write_salient_dataset(), so the trainer reads both.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sbaslam/saliency/salient_dataset.h"
#include "sbaslam/saliency/stable_features.h"

namespace sbaslam::saliency {

// The stable features of one image.
struct StableImage {
  std::string image_path;   // images_dir / the csv's image name
  std::string output_name;  // <stem>.png
  std::vector<cv::Point2f> points;
};

// Groups the rows by image, in the order the images first appear; an image that is not in
// `images_dir` is an error naming the file and the csv.
std::vector<StableImage> stable_images(const std::vector<StableFeature>& rows,
                                       const std::string& images_dir, const std::string& csv_path);

// Reads the csv and writes one sample per image with stable features. Returns the number written.
int write_stable_dataset(const std::string& images_dir, const std::string& csv_path,
                         const std::string& out_dir, const SalientDatasetOptions& options);

}  // namespace sbaslam::saliency
