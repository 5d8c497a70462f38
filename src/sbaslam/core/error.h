#pragma once
// One exception type for every user-facing failure: bad input, missing files, invalid settings.
// The CLI turns it into a one-line message and a non-zero exit; code never aborts on bad input.

#include <fmt/format.h>

#include <stdexcept>
#include <string>

namespace sbaslam {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// Formats the message with fmt and throws sbaslam::Error.
template <typename... Args>
[[noreturn]] void fail(fmt::format_string<Args...> format, Args&&... args) {
  throw Error(fmt::format(format, std::forward<Args>(args)...));
}

}  // namespace sbaslam
