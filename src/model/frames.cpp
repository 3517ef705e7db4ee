#include <joint_load_estimator/model/frames.hpp>

namespace jle {

bool rigidFrameInLink(const Model<double>& model, const std::string& link, const std::string& frame,
                      Eigen::Matrix3d& R_link_frame, Eigen::Vector3d& p_link_frame) {
  const Frame<double>& l = model.frames[static_cast<std::size_t>(model.frameIndex(link))];
  for (const Frame<double>& f : model.frames) {
    if (f.name != frame) continue;
    if (f.segment != l.segment) return false;
    R_link_frame = l.R_segment_frame.transpose() * f.R_segment_frame;
    p_link_frame = l.R_segment_frame.transpose() * (f.p_segment_frame - l.p_segment_frame);
    return true;
  }
  return false;
}

}  // namespace jle
