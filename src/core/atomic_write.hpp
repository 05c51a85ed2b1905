// Write-then-rename for output files: nothing half-written ever sits under the final name.
//
//   using namespace roiflow;
//   eval::write_image_atomically("run/flow.png", bgr);           // cv::imwrite, then rename
//   write_text_atomically("run/summary.json", json.dump(2));
//   write_atomically("run/out.flo", "flow ", [&](const std::string& partial) {
//     eval::write_flo(partial, flow);
//     return true;
//   });
//
// `write` writes the partial file `dir/.name.partial.ext` (same directory, so the rename is
// atomic on POSIX file systems; same extension, so cv::imwrite picks the format from it), which
// is then renamed over `path`. A reader sees the old file or the new one, never half of one,
// and an interrupted run leaves at most a hidden partial file, never a truncated output.
// When `write` returns false or throws cv::Exception, or the rename fails, the partial file is
// removed and roiflow::Error "cannot write <what>'<path>'" is thrown (`what` names the kind of
// file, e.g. "image ", or is empty). Other exceptions from `write` propagate, after the partial
// file is removed.
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

}  // namespace roiflow
