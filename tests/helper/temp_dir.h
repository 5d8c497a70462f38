#pragma once
// A fresh, uniquely named temporary folder, removed with everything in it on destruction.

#include <filesystem>
#include <string>

namespace sbaslam::test {

class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // path() / relative, as a string.
  std::string file(const std::string& relative) const { return (path_ / relative).string(); }

 private:
  std::filesystem::path path_;
};

// Writes `content` to `path`, creating the parent folders.
void write_text_file(const std::string& path, const std::string& content);
std::string read_text_file(const std::string& path);

}  // namespace sbaslam::test
