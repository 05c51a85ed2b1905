// Write-then-rename for output files: `write` fills the partial file `dir/.name.partial.ext`
// (same directory, so the rename is atomic; same extension, so cv::imwrite picks the format),
// which is then renamed over `path`. A reader sees the old file or the new one, never half of
// one. When `write` returns false or throws cv::Exception, or the rename fails, the partial file
// is removed and roiflow::Error "cannot write <what>'<path>'" is thrown.
//
//   #include <fstream>
//   roiflow::check_output_path("run/summary.json", "--summary");  // before the long work
//   roiflow::write_text_atomically("run/summary.json", "{}\n");
//   roiflow::write_atomically("run/out.txt", "text ", [](const std::string& partial) {
//     std::ofstream(partial) << "done\n";
//     return true;
//   });
#pragma once

#include <cstddef>
#include <functional>
#include <opencv2/core.hpp>
#include <string>

namespace roiflow {

// "dir/name.png" -> "dir/.name.partial.png"
std::string partial_path(const std::string& path);

void write_atomically(const std::string& path, const std::string& what,
                      const std::function<bool(const std::string& partial_path)>& write);

void write_text_atomically(const std::string& path, const std::string& text);
// `size` bytes from `data` (e.g. an image encoded in memory by cv::imencode).
void write_bytes_atomically(const std::string& path, const std::string& what, const void* data,
                            std::size_t size);

// Catches a mistyped output path before minutes of computation are spent: throws roiflow::Error
// "<option>: directory 'd' of 'd/f' does not exist" or "<option>: 'p' is a directory".
void check_output_path(const std::string& path, const std::string& option);
// An output folder, created when missing; its parent must exist (a mistyped path fails before
// minutes of computation instead of growing a tree somewhere unexpected). Throws roiflow::Error
// "<option>: ..." otherwise.
void make_output_dir(const std::string& dir, const std::string& option);

}  // namespace roiflow
