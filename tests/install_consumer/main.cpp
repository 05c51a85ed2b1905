// Dense flow of a translated texture through the installed headers and libraries; exits 0 when
// the flow away from the border is within 0.2 px of the translation, 1 otherwise.
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "flow/dense_lk.hpp"
#include "flow/metrics.hpp"
#ifdef CONSUMER_WITH_PIPELINE
#include "pipeline/tbb_executor.hpp"
#endif

int main() {
  using namespace roiflow;
  const cv::Size size(160, 120);
  const cv::Point2f motion(1.25f, -0.5f);
  cv::Mat noise(size, CV_8UC1), frame0, frame1;
  cv::randu(noise, 0, 256);
  cv::GaussianBlur(noise, frame0, cv::Size(), 2.0);
  // frame1(x) = frame0(x - motion): the flow from frame0 to frame1 is `motion` everywhere.
  const cv::Matx23d shift(1, 0, motion.x, 0, 1, motion.y);
  cv::warpAffine(frame0, frame1, shift, size, cv::INTER_CUBIC, cv::BORDER_REFLECT);
  const cv::Mat truth(size, CV_32FC2, cv::Scalar(motion.x, motion.y));
  cv::Mat border(size, CV_8UC1, cv::Scalar(255));
  border(cv::Rect(16, 16, size.width - 32, size.height - 32)).setTo(0);

#ifdef CONSUMER_WITH_PIPELINE
  const pipeline::TbbExecutor tbb;
  const Executor* executor = &tbb;
#else
  const Executor* executor = nullptr;
#endif
  flow::DenseLK lk(flow::LkParams::paper(), executor);
  const flow::FlowResult result = lk.calc(frame0, frame1);
  const flow::FlowErrors errors = flow::flow_errors(result.flow, truth, border);
  std::printf("installed roiflow: EPE %.4f px over %lld pixels\n", errors.epe,
              static_cast<long long>(errors.pixels));
  return errors.pixels > 0 && errors.epe < 0.2 ? 0 : 1;
}
