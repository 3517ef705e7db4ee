// The estimator as a nodelet: zero-copy beside a driver in the same manager.
#include <joint_load_estimator/ros/estimator_node.hpp>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

namespace jle {

class EstimatorNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      node_ = std::make_unique<EstimatorNode>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL("joint_load_estimator: %s", e.what());
      throw;
    }
  }
  std::unique_ptr<EstimatorNode> node_;
};

}  // namespace jle

PLUGINLIB_EXPORT_CLASS(jle::EstimatorNodelet, nodelet::Nodelet)
