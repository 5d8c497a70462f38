#include "sbaslam/io/image_io.h"

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sbaslam/core/error.h"

namespace sbaslam::io {
namespace {

cv::Mat decode(const std::string& path, int flags) {
  if (!std::filesystem::is_regular_file(path)) fail("{}: image file not found", path);
  cv::Mat image;
  try {
    image = cv::imread(path, flags);
  } catch (const cv::Exception& e) {
    fail("{}: cannot decode the image ({})", path, e.err);
  }
  if (image.empty()) fail("{}: cannot decode the image (corrupt or truncated file?)", path);
  return image;
}

}  // namespace

cv::Mat read_gray_image(const std::string& path) {
  cv::Mat image = decode(path, cv::IMREAD_GRAYSCALE);
  if (image.depth() != CV_8U) image.convertTo(image, CV_8U);
  return image;
}

cv::Mat read_depth_image(const std::string& path) {
  cv::Mat depth = decode(path, cv::IMREAD_UNCHANGED);
  if (depth.type() != CV_16UC1)
    fail("{}: depth image must be 16-bit single-channel, got {} channel(s) of depth {}", path,
         depth.channels(), depth.depth());
  return depth;
}

std::optional<cv::Size> read_png_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<unsigned char, 24> header{};
  if (!in.read(reinterpret_cast<char*>(header.data()), header.size())) return std::nullopt;
  static constexpr std::array<unsigned char, 8> kSignature = {0x89, 'P',  'N',  'G',
                                                              '\r', '\n', 0x1a, '\n'};
  if (!std::equal(kSignature.begin(), kSignature.end(), header.begin())) return std::nullopt;
  // IHDR is the first chunk: width and height are big-endian at bytes 16 and 20.
  const auto be32 = [&](std::size_t at) {
    return (static_cast<std::uint32_t>(header[at]) << 24) |
           (static_cast<std::uint32_t>(header[at + 1]) << 16) |
           (static_cast<std::uint32_t>(header[at + 2]) << 8) | header[at + 3];
  };
  const std::uint32_t width = be32(16), height = be32(20);
  if (width == 0 || height == 0 || width > (1u << 30) || height > (1u << 30)) return std::nullopt;
  return cv::Size(static_cast<int>(width), static_cast<int>(height));
}

std::vector<std::string> list_files(const std::string& dir, const std::string& extension) {
  std::vector<std::string> names;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (!it->is_regular_file()) continue;
    const std::string name = it->path().filename().string();
    if (name.size() > extension.size() &&
        name.compare(name.size() - extension.size(), extension.size(), extension) == 0)
      names.push_back(name);
  }
  if (ec) fail("{}: cannot list the folder ({})", dir, ec.message());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace sbaslam::io
