#pragma once
// Line-oriented parsing shared by the dataset listings (times.txt, data.csv, rgb.txt, ...).
// Failures are sbaslam::Error naming the file and the line.

#include <cstdint>
#include <string>
#include <vector>

namespace sbaslam::io {

struct TextLine {
  std::size_t number = 0;  // 1-based line number in the file
  std::string text;        // without the line ending, trimmed
};

// The non-empty lines of a file that do not start with '#'. Throws if the file cannot be read.
std::vector<TextLine> read_data_lines(const std::string& path);
// Splits on any of `separators`, trimming each field; empty fields are dropped when separators
// include whitespace only.
std::vector<std::string> split_fields(const std::string& text, const std::string& separators);
// A finite number, or sbaslam::Error "<path>:<line>: <what> '<field>' is not a number".
double parse_number(const std::string& field, const std::string& path, std::size_t line,
                    const char* what);
// Non-negative integer nanoseconds, e.g. EuRoC stamps.
std::int64_t parse_nanoseconds(const std::string& field, const std::string& path, std::size_t line);

}  // namespace sbaslam::io
