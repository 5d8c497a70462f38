#include "sbaslam/io/text_lines.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "sbaslam/core/error.h"

namespace sbaslam::io {
namespace {

std::string trim(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return {};
  const auto end = text.find_last_not_of(" \t\r\n");
  return text.substr(begin, end - begin + 1);
}

}  // namespace

std::vector<TextLine> read_data_lines(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) fail("{}: file not found", path);
  std::ifstream in(path);
  if (!in) fail("{}: cannot open for reading", path);
  std::vector<TextLine> lines;
  std::string raw;
  for (std::size_t number = 1; std::getline(in, raw); ++number) {
    std::string text = trim(raw);
    if (text.empty() || text[0] == '#') continue;
    lines.push_back({number, std::move(text)});
  }
  if (in.bad()) fail("{}: read error", path);
  return lines;
}

std::vector<std::string> split_fields(const std::string& text, const std::string& separators) {
  std::vector<std::string> fields;
  const bool whitespace_only = separators.find_first_not_of(" \t") == std::string::npos;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = text.find_first_of(separators, start);
    std::string field = trim(text.substr(start, end == std::string::npos ? end : end - start));
    if (!(whitespace_only && field.empty())) fields.push_back(std::move(field));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return fields;
}

double parse_number(const std::string& field, const std::string& path, std::size_t line,
                    const char* what) {
  const char* begin = field.c_str();
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(begin, &end);
  if (field.empty() || end != begin + field.size() || errno == ERANGE || !std::isfinite(value))
    fail("{}:{}: {} '{}' is not a finite number", path, line, what, field);
  return value;
}

std::int64_t parse_nanoseconds(const std::string& field, const std::string& path,
                               std::size_t line) {
  if (field.empty() || field.size() > 19 ||
      field.find_first_not_of("0123456789") != std::string::npos)
    fail("{}:{}: timestamp '{}' is not an integer number of nanoseconds", path, line, field);
  return std::stoll(field);
}

}  // namespace sbaslam::io
