#pragma once
// Runs `f` and expects an sbaslam::Error whose one-line message contains `needle`.

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

}  // namespace sbaslam::test
