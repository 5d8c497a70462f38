#pragma once
// Runs `f` and expects an sbaslam::Error whose one-line message contains `needle`; or returns the
// message of the error `f` throws ("no error" when it throws none).

#include <gtest/gtest.h>

#include <string>

#include "sbaslam/core/error.h"

namespace sbaslam::test {

template <typename F>
void expect_error_naming(F&& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one naming " << needle;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

template <typename F>
std::string error_message(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace sbaslam::test
