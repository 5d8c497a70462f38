#include "sbaslam/loop/vocabulary_training.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>

#include "sbaslam/core/error.h"
#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/io/image_io.h"

namespace sbaslam::loop {
namespace {

// Paths of every `every`-th image of `folder`, by sorted name.
std::vector<std::string> pick_images(const std::string& folder, int every) {
  if (!std::filesystem::is_directory(folder)) fail("{}: not a folder", folder);
  std::vector<std::string> names;
  for (const char* extension : {".png", ".jpg", ".jpeg"}) {
    const std::vector<std::string> more = io::list_files(folder, extension);
    names.insert(names.end(), more.begin(), more.end());
  }
  if (names.empty()) fail("{}: no .png or .jpg images", folder);
  std::sort(names.begin(), names.end());
  std::vector<std::string> paths;
  for (std::size_t i = 0; i < names.size(); i += static_cast<std::size_t>(every))
    paths.push_back((std::filesystem::path(folder) / names[i]).string());
  return paths;
}

}  // namespace

std::string VocabularyTrainingReport::summary(const std::string& out) const {
  return fmt::format("vocabulary: {} images, {} descriptors, {} words, {:.1f} kB in {}, {:.1f} s",
                     images, descriptors, words, static_cast<double>(file_bytes) / 1000.0, out,
                     seconds);
}

VocabularyTrainingReport train_vocabulary_from_folders(const std::vector<std::string>& folders,
                                                       const VocabularyTrainingOptions& options,
                                                       const std::string& out) {
  const auto start = std::chrono::steady_clock::now();
  if (folders.empty()) fail("vocabulary training: no image folder given");
  if (options.every < 1)
    fail("vocabulary training: every must be at least 1, got {}", options.every);
  if (options.max_features < 1)
    fail("vocabulary training: max features must be at least 1, got {}", options.max_features);
  OrbSettings orb;
  orb.n_features = options.max_features;
  // All folders are listed before any image is read, so a bad folder fails at once.
  std::vector<std::string> paths;
  for (const std::string& folder : folders) {
    const std::vector<std::string> more = pick_images(folder, options.every);
    paths.insert(paths.end(), more.begin(), more.end());
  }

  feature::OrbExtractor extractor(orb);
  VocabularyTrainingReport report;
  std::vector<cv::Mat> descriptor_sets;
  for (const std::string& path : paths) {
    descriptor_sets.push_back(extractor.extract(io::read_gray_image(path)).descriptors);
    report.descriptors += static_cast<std::size_t>(descriptor_sets.back().rows);
  }
  const Vocabulary vocabulary = Vocabulary::train(descriptor_sets, options.vocabulary);
  vocabulary.save(out);

  report.images = paths.size();
  report.words = vocabulary.word_count();
  report.file_bytes = std::filesystem::file_size(out);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace sbaslam::loop
