#include "sbaslam/core/input_file.h"

#include <filesystem>
#include <fstream>
#include <iterator>

#include "sbaslam/core/error.h"

namespace sbaslam {

std::string read_input_file(const std::string& path, const std::string& what) {
  if (!std::filesystem::exists(path)) fail("{}: {} not found", path, what);
  if (!std::filesystem::is_regular_file(path)) fail("{}: not a regular file", path);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("{}: cannot open for reading", path);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) fail("{}: read error", path);
  return bytes;
}

}  // namespace sbaslam
