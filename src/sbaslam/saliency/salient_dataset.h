#pragma once
// The paper's "semantic gaze" ground truth (section III-B): the geometric cues a feature-based
// SLAM system attends to (ORB corners, points along LSD line segments, Canny edges), kept only
// where they lie on one of 13 static Cityscapes classes, splatted with a Gaussian into a smooth
// density map exactly like a human fixation map is made from eye-tracker fixations.

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace sbaslam::saliency {

// The 13 Cityscapes label ids the paper keeps: road 7, sidewalk 8, parking 9, rail track 10,
// building 11, fence 13, bridge 15, pole 17, polegroup 18, traffic light 19, traffic sign 20,
// vegetation 21, terrain 22.
bool is_static_class(std::uint8_t cityscapes_id);

struct SalientDatasetOptions {
  int orb_features = 1000;      // ORB corners per image
  int line_sample_step = 8;     // pixels between points sampled along an LSD segment
  double min_line_length = 15;  // shorter LSD segments are noise
  int edge_cell = 8;            // at most one Canny edge point per edge_cell x edge_cell cell
  double canny_low = 50, canny_high = 150;
  // A point is kept only when every label within this radius is static, so corners that a moving
  // car makes against a facade (occlusion boundaries) are dropped too.
  int boundary_margin = 2;
  // Gaussian splat sigma as a fraction of the image width (fixation maps use about one degree of
  // visual angle; 2.5 % of the width is about one degree for KITTI's 82-degree field of view).
  double sigma_fraction = 0.025;
};

// The geometric cues of one grayscale image, level-0 pixel positions, before any filtering.
std::vector<cv::Point2f> geometric_points(const cv::Mat& gray,
                                          const SalientDatasetOptions& options);

// The points whose neighbourhood (options.boundary_margin) holds only static classes.
// `labels` is CV_8U of Cityscapes ids, the size of the image the points come from.
std::vector<cv::Point2f> keep_static_points(const std::vector<cv::Point2f>& points,
                                            const cv::Mat& labels,
                                            const SalientDatasetOptions& options);

// Gaussian splatting of the points into an 8-bit density map of `size`, maximum scaled to 255
// (all zero when there are no points).
cv::Mat density_map(const std::vector<cv::Point2f>& points, const cv::Size& size,
                    const SalientDatasetOptions& options);

// Binary fixation map (255 at each point's pixel, else 0), the format NSS and AUC-Judd read.
cv::Mat fixation_map(const std::vector<cv::Point2f>& points, const cv::Size& size);

struct SalientSample {
  cv::Mat density;                // CV_8U, semantic gaze ground truth
  cv::Mat fixations;              // CV_8U binary, kept points
  cv::Mat unfiltered_density;     // CV_8U, every geometric cue (the baseline without semantics)
  std::vector<cv::Point2f> kept;  // the fixation list
  int total_points = 0;
};

// One image and its Cityscapes label map (same size) to the sample; throws sbaslam::Error when
// the sizes or types do not fit.
SalientSample make_salient_sample(const cv::Mat& gray, const cv::Mat& labels,
                                  const SalientDatasetOptions& options);

// The sample of an image whose kept points come from elsewhere (e.g. the stable features of a
// SLAM run): density and fixations from `kept`, the unfiltered density from geometric_points().
SalientSample make_sample_from_points(const cv::Mat& gray, std::vector<cv::Point2f> kept,
                                      const SalientDatasetOptions& options);

// Writes the files of a dataset one sample at a time: DIR/{maps,fixations,unfiltered}/<name>.png
// and DIR/dataset.csv (one row per image: image path, label source, map, fixations, unfiltered
// map, kept and total point counts), the layout python/train_saliency.py reads.
class SalientDatasetWriter {
 public:
  // Creates the folders and dataset.csv; throws sbaslam::Error naming what cannot be written.
  explicit SalientDatasetWriter(const std::string& out_dir);
  void add(const std::string& image_path, const std::string& label_source,
           const std::string& output_name, const SalientSample& sample);
  int count() const { return count_; }

 private:
  std::string out_dir_;
  std::string csv_path_;
  int count_ = 0;
};

// One image/label pair of a dataset.
struct LabelledImage {
  std::string image_path;
  std::string label_path;
  std::string output_name;  // file name of the sample's maps, unique within a dataset
};

// Pairs from a folder written by `sba-slam simulate`: KITTI layout
// (DIR/sequences/*/{image_0,semantic}) or EuRoC layout (DIR/mav0/{cam0,semantic0}/data).
std::vector<LabelledImage> pairs_from_simulation(const std::string& dir);

// Pairs by file stem: every image in `image_dir` with a label PNG of the same stem in
// `label_dir` (Cityscapes "*_gtFine_labelIds.png" names are matched too). Images without a label
// are an error naming the image.
std::vector<LabelledImage> pairs_from_folders(const std::string& image_dir,
                                              const std::string& label_dir);

// Writes the semantic-gaze sample of every pair with SalientDatasetWriter. Returns the number of
// samples written.
int write_salient_dataset(const std::vector<LabelledImage>& pairs, const std::string& out_dir,
                          const SalientDatasetOptions& options);

}  // namespace sbaslam::saliency
