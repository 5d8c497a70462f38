#pragma once
// `sba-slam vocabulary train`: the ORB features of the images in some folders, a vocabulary
// trained on them and saved to a file.

#include <cstdint>
#include <string>
#include <vector>

#include "sbaslam/loop/vocabulary.h"

namespace sbaslam::loop {

struct VocabularyTrainingOptions {
  VocabularyTrainOptions vocabulary;  // branching, levels, k-means iterations, seed
  // ORB features per image; the other ORB settings are ORB-SLAM's (scale 1.2, 8 levels, FAST
  // thresholds 20 and 7), as in config/KITTI04-12.yaml, so the words match what tracking extracts.
  int max_features = 1000;
  int every = 1;  // every Nth image of each folder, by sorted name, from the first
};

struct VocabularyTrainingReport {
  std::size_t images = 0;
  std::size_t descriptors = 0;
  std::size_t words = 0;
  std::uintmax_t file_bytes = 0;
  double seconds = 0.0;                               // extraction, training and saving
  std::string summary(const std::string& out) const;  // one line, no newline
};

// Reads every `options.every`-th .png/.jpg/.jpeg image of each folder (grey), extracts its ORB
// features, trains a vocabulary and saves it to `out`. A missing folder, a folder without images,
// an undecodable image or an unwritable `out` throws a one-line sbaslam::Error naming it.
VocabularyTrainingReport train_vocabulary_from_folders(const std::vector<std::string>& folders,
                                                       const VocabularyTrainingOptions& options,
                                                       const std::string& out);

}  // namespace sbaslam::loop
