// Under ThreadSanitizer only (linked into every executable of the tsan preset: the test binaries
// and the roiflow CLI the end-to-end tests start): OpenCV's parallel loops run on the TBB
// backend OpenCV ships as a header (opencv2/core/parallel/backend/parallel_for.tbb.hpp),
// compiled here, with -fsanitize=thread, against the oneTBB built with TSan.
//
// Debian's OpenCV runs its loops on oneTBB through TBB templates inlined into its own,
// uninstrumented library: TSan sees neither the spawn nor the join of those loops. A worker that
// touched memory on the caller's stack during one (oneTBB's bookkeeping reads the loop's
// task_group_context) then looks as if it raced with whatever the caller later puts at that
// address, and when TSan can no longer restore the worker's stack, no suppression can tell that
// report from a real one (CI saw one in the Kalman filter's Eigen product inside run_mot). With
// the templates compiled here, the spawn and the join are instrumented; the loop bodies stay
// OpenCV's. This changes nothing but where OpenCV's tbb::parallel_for is instantiated: the same
// oneTBB runs the same loops at the same thread count (cv::setNumThreads reaches this backend).
#include <opencv2/core/parallel/backend/parallel_for.tbb.hpp>
#include <opencv2/core/parallel/parallel_backend.hpp>

#include <memory>

namespace {

const bool installed = [] {
  cv::parallel::setParallelForBackend(std::make_shared<cv::parallel::tbb::ParallelForBackend>());
  return true;
}();

}  // namespace
