#pragma once
// The project's text and binary outputs are written through these (images through cv::imwrite),
// so that a missing folder or a full disk is an Error naming the file, never a short file that a
// later step reads as complete.

#include <fstream>
#include <string>

namespace sbaslam {

// Opens PATH for writing, truncated and in binary mode (no newline translation).
std::ofstream open_output_file(const std::string& path);

// Flushes and closes OUT; fails if any write to it went wrong.
void close_output_file(std::ofstream& out, const std::string& path);

// Writes TEXT as the whole content of PATH.
void write_output_file(const std::string& path, const std::string& text);

}  // namespace sbaslam
