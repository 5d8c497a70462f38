#include "sbaslam/core/output_file.h"

#include "sbaslam/core/error.h"

namespace sbaslam {

std::ofstream open_output_file(const std::string& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) fail("{}: cannot open for writing", path);
  return out;
}

void close_output_file(std::ofstream& out, const std::string& path) {
  out.close();
  if (!out) fail("{}: write error", path);
}

void write_output_file(const std::string& path, const std::string& text) {
  std::ofstream out = open_output_file(path);
  out << text;
  close_output_file(out, path);
}

}  // namespace sbaslam
