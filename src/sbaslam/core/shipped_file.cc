#include "sbaslam/core/shipped_file.h"

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "sbaslam/core/error.h"

namespace sbaslam {
namespace fs = std::filesystem;
namespace {

fs::path executable_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

}  // namespace

std::string shipped_file_path(const std::string& name, const std::string& what) {
  std::vector<fs::path> candidates;
  if (const char* dir = std::getenv("SBASLAM_MODEL_DIR"))
    candidates.push_back(fs::path(dir) / name);
  const fs::path exe_dir = executable_dir();
  if (!exe_dir.empty())
    candidates.push_back(exe_dir.parent_path() / "share" / "sba-slam" / "models" / name);
  candidates.push_back(fs::path(SBASLAM_SOURCE_DIR) / "models" / name);
  for (const fs::path& p : candidates)
    if (fs::exists(p)) return p.string();
  fail(
      "{}: shipped {} not found (also looked in $SBASLAM_MODEL_DIR and "
      "<prefix>/share/sba-slam/models)",
      candidates.back().string(), what);
}

}  // namespace sbaslam
