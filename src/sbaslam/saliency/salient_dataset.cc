#include "sbaslam/saliency/salient_dataset.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"
#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/io/image_io.h"

namespace sbaslam::saliency {
namespace fs = std::filesystem;

bool is_static_class(std::uint8_t cityscapes_id) {
  static constexpr std::array<std::uint8_t, 13> kStatic = {7,  8,  9,  10, 11, 13, 15,
                                                           17, 18, 19, 20, 21, 22};
  return std::find(kStatic.begin(), kStatic.end(), cityscapes_id) != kStatic.end();
}

namespace {

void add_orb_corners(const cv::Mat& gray, int count, std::vector<cv::Point2f>& points) {
  OrbSettings orb;
  orb.n_features = count;
  feature::OrbExtractor extractor(orb);
  for (const feature::OrbKeypoint& kp : extractor.extract(gray).keypoints)
    points.emplace_back(kp.x, kp.y);
}

void add_line_samples(const cv::Mat& gray, const SalientDatasetOptions& options,
                      std::vector<cv::Point2f>& points) {
  cv::Ptr<cv::LineSegmentDetector> lsd = cv::createLineSegmentDetector(cv::LSD_REFINE_STD);
  std::vector<cv::Vec4f> segments;
  lsd->detect(gray, segments);
  for (const cv::Vec4f& s : segments) {
    const cv::Point2f a(s[0], s[1]), b(s[2], s[3]);
    const double length = cv::norm(b - a);
    if (length < options.min_line_length) continue;
    const int samples = std::max(1, static_cast<int>(length / options.line_sample_step));
    for (int i = 0; i <= samples; ++i) points.push_back(a + (b - a) * (float(i) / samples));
  }
}

// One edge point per cell (the first edge pixel found) so long edges do not drown the corners.
void add_edge_samples(const cv::Mat& gray, const SalientDatasetOptions& options,
                      std::vector<cv::Point2f>& points) {
  cv::Mat edges;
  cv::Canny(gray, edges, options.canny_low, options.canny_high);
  const int cell = std::max(1, options.edge_cell);
  for (int y0 = 0; y0 < edges.rows; y0 += cell)
    for (int x0 = 0; x0 < edges.cols; x0 += cell) {
      const cv::Rect r = cv::Rect(x0, y0, cell, cell) & cv::Rect(0, 0, edges.cols, edges.rows);
      std::vector<cv::Point> nz;
      cv::findNonZero(edges(r), nz);
      if (!nz.empty())
        points.emplace_back(float(x0 + nz[nz.size() / 2].x), float(y0 + nz[nz.size() / 2].y));
    }
}

void check_labels(const cv::Mat& gray, const cv::Mat& labels) {
  if (gray.empty() || gray.type() != CV_8UC1) fail("salient dataset: image must be 8-bit gray");
  if (labels.type() != CV_8UC1)
    fail("salient dataset: label map must be 8-bit Cityscapes ids, got type {}", labels.type());
  if (labels.size() != gray.size())
    fail("salient dataset: label map is {}x{} but the image is {}x{}", labels.cols, labels.rows,
         gray.cols, gray.rows);
}

}  // namespace

std::vector<cv::Point2f> geometric_points(const cv::Mat& gray,
                                          const SalientDatasetOptions& options) {
  std::vector<cv::Point2f> points;
  add_orb_corners(gray, options.orb_features, points);
  add_line_samples(gray, options, points);
  add_edge_samples(gray, options, points);
  return points;
}

std::vector<cv::Point2f> keep_static_points(const std::vector<cv::Point2f>& points,
                                            const cv::Mat& labels,
                                            const SalientDatasetOptions& options) {
  cv::Mat static_mask(labels.size(), CV_8U);
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x)
      static_mask.at<std::uint8_t>(y, x) = is_static_class(labels.at<std::uint8_t>(y, x)) ? 1 : 0;
  if (options.boundary_margin > 0) {
    const int k = 2 * options.boundary_margin + 1;
    cv::erode(static_mask, static_mask, cv::getStructuringElement(cv::MORPH_RECT, {k, k}), {-1, -1},
              1, cv::BORDER_REPLICATE);
  }
  std::vector<cv::Point2f> kept;
  for (const cv::Point2f& p : points) {
    const int x = std::clamp(static_cast<int>(std::lround(p.x)), 0, labels.cols - 1);
    const int y = std::clamp(static_cast<int>(std::lround(p.y)), 0, labels.rows - 1);
    if (static_mask.at<std::uint8_t>(y, x) != 0) kept.push_back(p);
  }
  return kept;
}

cv::Mat density_map(const std::vector<cv::Point2f>& points, const cv::Size& size,
                    const SalientDatasetOptions& options) {
  cv::Mat density = cv::Mat::zeros(size, CV_32F);
  for (const cv::Point2f& p : points) {
    const int x = std::clamp(static_cast<int>(std::lround(p.x)), 0, size.width - 1);
    const int y = std::clamp(static_cast<int>(std::lround(p.y)), 0, size.height - 1);
    density.at<float>(y, x) += 1.0f;
  }
  const double sigma = std::max(0.5, options.sigma_fraction * size.width);
  cv::GaussianBlur(density, density, cv::Size(), sigma, sigma, cv::BORDER_CONSTANT);
  double max_value = 0.0;
  cv::minMaxLoc(density, nullptr, &max_value);
  cv::Mat out;
  density.convertTo(out, CV_8U, max_value > 0 ? 255.0 / max_value : 0.0);
  return out;
}

cv::Mat fixation_map(const std::vector<cv::Point2f>& points, const cv::Size& size) {
  cv::Mat fixations = cv::Mat::zeros(size, CV_8U);
  for (const cv::Point2f& p : points) {
    const int x = std::clamp(static_cast<int>(std::lround(p.x)), 0, size.width - 1);
    const int y = std::clamp(static_cast<int>(std::lround(p.y)), 0, size.height - 1);
    fixations.at<std::uint8_t>(y, x) = 255;
  }
  return fixations;
}

SalientSample make_sample_from_points(const cv::Mat& gray, std::vector<cv::Point2f> kept,
                                      const SalientDatasetOptions& options) {
  if (gray.empty() || gray.type() != CV_8UC1) fail("salient dataset: image must be 8-bit gray");
  const std::vector<cv::Point2f> all = geometric_points(gray, options);
  SalientSample sample;
  sample.kept = std::move(kept);
  sample.total_points = static_cast<int>(all.size());
  sample.density = density_map(sample.kept, gray.size(), options);
  sample.fixations = fixation_map(sample.kept, gray.size());
  sample.unfiltered_density = density_map(all, gray.size(), options);
  return sample;
}

SalientSample make_salient_sample(const cv::Mat& gray, const cv::Mat& labels,
                                  const SalientDatasetOptions& options) {
  check_labels(gray, labels);
  const std::vector<cv::Point2f> all = geometric_points(gray, options);
  SalientSample sample;
  sample.kept = keep_static_points(all, labels, options);
  sample.total_points = static_cast<int>(all.size());
  sample.density = density_map(sample.kept, gray.size(), options);
  sample.fixations = fixation_map(sample.kept, gray.size());
  sample.unfiltered_density = density_map(all, gray.size(), options);
  return sample;
}

namespace {

std::vector<LabelledImage> pairs_by_stem(const fs::path& image_dir, const fs::path& label_dir,
                                         const std::string& name_prefix) {
  std::vector<LabelledImage> pairs;
  for (const char* ext : {".png", ".jpg", ".jpeg"}) {
    for (const std::string& name : io::list_files(image_dir.string(), ext)) {
      const std::string stem = fs::path(name).stem().string();
      fs::path label = label_dir / (stem + ".png");
      if (!fs::exists(label)) {
        // Cityscapes: <city>_<seq>_<frame>_leftImg8bit.png <-> ..._gtFine_labelIds.png
        const std::string suffix = "_leftImg8bit";
        const std::string base =
            stem.size() > suffix.size() &&
                    stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0
                ? stem.substr(0, stem.size() - suffix.size())
                : stem;
        label = label_dir / (base + "_gtFine_labelIds.png");
      }
      if (!fs::exists(label))
        fail("{}: no label map {} for this image", (image_dir / name).string(),
             (label_dir / (stem + ".png")).string());
      pairs.push_back({(image_dir / name).string(), label.string(), name_prefix + stem + ".png"});
    }
  }
  return pairs;
}

}  // namespace

std::vector<LabelledImage> pairs_from_simulation(const std::string& dir) {
  const fs::path root(dir);
  if (!fs::is_directory(root)) fail("{}: not a folder", dir);
  std::vector<LabelledImage> pairs;
  if (fs::is_directory(root / "sequences")) {
    std::vector<fs::path> sequences;
    for (const auto& entry : fs::directory_iterator(root / "sequences"))
      if (fs::is_directory(entry.path() / "semantic")) sequences.push_back(entry.path());
    std::sort(sequences.begin(), sequences.end());
    for (const fs::path& seq : sequences) {
      auto more = pairs_by_stem(seq / "image_0", seq / "semantic", seq.filename().string() + "_");
      pairs.insert(pairs.end(), more.begin(), more.end());
    }
  } else if (fs::is_directory(root / "mav0" / "semantic0")) {
    pairs =
        pairs_by_stem(root / "mav0" / "cam0" / "data", root / "mav0" / "semantic0" / "data", "");
  }
  if (pairs.empty())
    fail(
        "{}: no simulated images with labels (expected sequences/*/{{image_0,semantic}} or "
        "mav0/{{cam0,semantic0}}/data, as written by 'sba-slam simulate')",
        dir);
  return pairs;
}

std::vector<LabelledImage> pairs_from_folders(const std::string& image_dir,
                                              const std::string& label_dir) {
  if (!fs::is_directory(image_dir)) fail("{}: not a folder", image_dir);
  if (!fs::is_directory(label_dir)) fail("{}: not a folder", label_dir);
  std::vector<LabelledImage> pairs = pairs_by_stem(image_dir, label_dir, "");
  if (pairs.empty()) fail("{}: no .png or .jpg images", image_dir);
  return pairs;
}

namespace {

void write_png(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) fail("{}: cannot write", path.string());
}

cv::Mat read_labels(const std::string& path) {
  cv::Mat labels = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (labels.empty()) fail("{}: missing or not an image", path);
  if (labels.type() != CV_8UC1)
    fail("{}: label map must be 8-bit single-channel Cityscapes ids", path);
  return labels;
}

}  // namespace

SalientDatasetWriter::SalientDatasetWriter(const std::string& out_dir)
    : out_dir_(out_dir), csv_path_((fs::path(out_dir) / "dataset.csv").string()) {
  std::error_code ec;
  for (const char* sub : {"maps", "fixations", "unfiltered"}) {
    fs::create_directories(fs::path(out_dir) / sub, ec);
    if (ec) fail("{}: cannot create folder: {}", (fs::path(out_dir) / sub).string(), ec.message());
  }
  write_output_file(csv_path_, "image,labels,map,fixations,unfiltered,kept_points,total_points\n");
}

void SalientDatasetWriter::add(const std::string& image_path, const std::string& label_source,
                               const std::string& output_name, const SalientSample& sample) {
  const fs::path out(out_dir_);
  write_png(out / "maps" / output_name, sample.density);
  write_png(out / "fixations" / output_name, sample.fixations);
  write_png(out / "unfiltered" / output_name, sample.unfiltered_density);
  // Appended row by row so that a failure half-way leaves a readable csv of what was written.
  std::ofstream csv(csv_path_, std::ios::app);
  csv << fs::absolute(image_path).string() << ',' << label_source << ",maps/" << output_name
      << ",fixations/" << output_name << ",unfiltered/" << output_name << ',' << sample.kept.size()
      << ',' << sample.total_points << '\n';
  close_output_file(csv, csv_path_);
  ++count_;
}

int write_salient_dataset(const std::vector<LabelledImage>& pairs, const std::string& out_dir,
                          const SalientDatasetOptions& options) {
  SalientDatasetWriter writer(out_dir);
  for (const LabelledImage& pair : pairs) {
    const cv::Mat gray = io::read_gray_image(pair.image_path);
    const cv::Mat labels = read_labels(pair.label_path);
    if (labels.size() != gray.size())
      fail("{}: label map is {}x{} but the image {} is {}x{}", pair.label_path, labels.cols,
           labels.rows, pair.image_path, gray.cols, gray.rows);
    writer.add(pair.image_path, fs::absolute(pair.label_path).string(), pair.output_name,
               make_salient_sample(gray, labels, options));
  }
  return writer.count();
}

}  // namespace sbaslam::saliency
