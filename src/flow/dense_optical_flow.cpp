// createDenseLK: DenseLK behind OpenCV's cv::DenseOpticalFlow interface.
#include <opencv2/video/tracking.hpp>

#include "flow/dense_lk.hpp"

namespace roiflow::flow {

namespace {

class DenseLKOpticalFlow final : public cv::DenseOpticalFlow {
 public:
  DenseLKOpticalFlow(const LkParams& params, const Executor* executor) : lk_(params, executor) {}

  void calc(cv::InputArray i0, cv::InputArray i1, cv::InputOutputArray flow) override {
    const cv::Mat a = i0.getMat(), b = i1.getMat();
    if (flow.isUMat()) {
      lk_.calc(a, b, result_, options_);
      result_.flow.copyTo(flow);
      return;
    }
    // Straight into the caller's matrix when it has the right size and type already (a video
    // loop), as DIS does.
    if (!a.empty()) flow.create(a.size(), CV_32FC2);
    result_.flow = flow.getMat();
    lk_.calc(a, b, result_, options_);
    if (result_.flow.data != flow.getMat().data) result_.flow.copyTo(flow);
    result_.flow.release();
  }

  void collectGarbage() override {
    lk_.collectGarbage();
    result_ = FlowResult();
  }

 private:
  DenseLK lk_;
  FlowResult result_;
  // The caller sees only the flow: no confidence is computed.
  FlowOptions options_ = no_confidence();

  static FlowOptions no_confidence() {
    FlowOptions o;
    o.confidence = false;
    return o;
  }
};

}  // namespace

cv::Ptr<cv::DenseOpticalFlow> createDenseLK(const LkParams& params, const Executor* executor) {
  return cv::makePtr<DenseLKOpticalFlow>(params, executor);
}

}  // namespace roiflow::flow
