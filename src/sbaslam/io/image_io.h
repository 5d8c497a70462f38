#pragma once
// Image decoding for the dataset readers. Every failure is an sbaslam::Error naming the file.

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace sbaslam::io {

// 8-bit grayscale (colour images are converted); throws if the file is missing or undecodable.
cv::Mat read_gray_image(const std::string& path);
// 16-bit single-channel depth image as stored; throws if missing, undecodable or not 16-bit.
cv::Mat read_depth_image(const std::string& path);
// Width and height from a PNG header without decoding; nullopt for a file that is not a PNG.
std::optional<cv::Size> read_png_size(const std::string& path);
// Names (not paths) of the regular files in `dir` ending in `extension` (e.g. ".png"), sorted.
std::vector<std::string> list_files(const std::string& dir, const std::string& extension);

}  // namespace sbaslam::io
