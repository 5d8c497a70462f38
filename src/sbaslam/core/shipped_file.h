#pragma once
// Files the project makes and ships in models/ (the saliency model, the ORB vocabulary), found
// where an installed or a built-in-place program expects them.

#include <string>

namespace sbaslam {

// The first that exists of $SBASLAM_MODEL_DIR/NAME, <prefix>/share/sba-slam/models/NAME (beside
// the running program's bin/) and the source tree's models/NAME. Fails naming the last place
// looked in, with `what` saying which file it is ("saliency model").
std::string shipped_file_path(const std::string& name, const std::string& what);

}  // namespace sbaslam
