// ~reconfigure: live tuning of the differentiator, the decimation and the node's
// thresholds through dynamic_reconfigure (cfg/Estimator.cfg, docs/node.md "Live tuning").
// A change is mapped onto the parameters read at start and read again by the one reader
// (parseSettings, which checks it); the decimation and the thresholds apply in place,
// a new differentiator restarts the filters (Pipeline::retune).
#include <joint_load_estimator/ros/estimator_node.hpp>
#include <joint_load_estimator/settings/settings_reader.hpp>

#include <mutex>
#include <stdexcept>
#include <string>

namespace jle {
namespace {

const char* typeName(DifferentiatorType type) { return nameOf(kDifferentiatorTypes, type); }

bool sameDifferentiatorFields(const DifferentiatorConfig& a, const DifferentiatorConfig& b) {
  return a.fields() == b.fields();
}

// The server's view of `settings`, with `status`, the answer to the last change.
joint_load_estimator::EstimatorConfig toConfig(const Settings& settings,
                                               const std::string& status) {
  joint_load_estimator::EstimatorConfig c;
  c.status = status;
  const DifferentiatorConfig& d = settings.estimator.differentiator;
  c.differentiator_type = typeName(d.type);
  c.differentiator_kalman_model = nameOf(kKalmanModels, d.kalman_model);
  c.differentiator_process_noise = d.process_noise;
  c.differentiator_measurement_noise = d.measurement_noise;
  c.differentiator_window = d.window;
  c.differentiator_order = d.order;
  c.differentiator_delay = d.delay;
  c.differentiator_max_gap = d.max_gap;
  c.differentiator_min_bandwidth = d.min_bandwidth;
  c.differentiator_max_bandwidth = d.max_bandwidth;
  c.differentiator_noise = d.noise;
  c.differentiator_memory = d.memory;
  c.differentiator_lag = d.lag;
  c.decimation = settings.estimator.decimation;
  c.base_residual_threshold = settings.base_residual_threshold;
  c.still_velocity = settings.still_velocity;
  return c;
}

// `params` (the node's private namespace) with the values of `c`, under the keys of
// config/default.yaml.
XmlRpc::XmlRpcValue withConfig(XmlRpc::XmlRpcValue params,
                               const joint_load_estimator::EstimatorConfig& c) {
  if (params.getType() != XmlRpc::XmlRpcValue::TypeStruct) params = XmlRpc::XmlRpcValue();
  XmlRpc::XmlRpcValue& d = params["differentiator"];
  d["type"] = c.differentiator_type;
  d["kalman_model"] = c.differentiator_kalman_model;
  d["process_noise"] = c.differentiator_process_noise;
  d["measurement_noise"] = c.differentiator_measurement_noise;
  d["window"] = c.differentiator_window;
  d["order"] = c.differentiator_order;
  d["delay"] = c.differentiator_delay;
  d["max_gap"] = c.differentiator_max_gap;
  d["min_bandwidth"] = c.differentiator_min_bandwidth;
  d["max_bandwidth"] = c.differentiator_max_bandwidth;
  d["noise"] = c.differentiator_noise;
  d["memory"] = c.differentiator_memory;
  d["lag"] = c.differentiator_lag;
  params["decimation"] = c.decimation;
  params["base_residual_threshold"] = c.base_residual_threshold;
  params["still_velocity"] = c.still_velocity;
  return params;
}

}  // namespace

void EstimatorNode::setUpReconfigure() {
  reconfigure_ =
      std::make_unique<dynamic_reconfigure::Server<joint_load_estimator::EstimatorConfig>>(
          reconfigure_mutex_, ros::NodeHandle(private_nh_, "reconfigure"));
  reconfigure_status_ = "the settings at start";
  joint_load_estimator::EstimatorConfig current = toConfig(settings_, reconfigure_status_);
  reconfigure_->updateConfig(current);  // the node's settings, not the .cfg's defaults
  reconfigure_->setCallback([this](joint_load_estimator::EstimatorConfig& config,
                                   std::uint32_t level) { onReconfigure(config, level); });
}

void EstimatorNode::onReconfigure(joint_load_estimator::EstimatorConfig& config,
                                  std::uint32_t /*level*/) {
  // The input callbacks may run in other threads (inline_callbacks, a nodelet manager's).
  std::lock_guard<std::mutex> lock(callbacks_mutex_);
  try {
    XmlRpc::XmlRpcValue params = withConfig(params_, config);
    const Settings next = parseSettings(params);  // throws naming the key
    const bool same = next.estimator.decimation == settings_.estimator.decimation &&
                      next.base_residual_threshold == settings_.base_residual_threshold &&
                      next.still_velocity == settings_.still_velocity;
    const DifferentiatorConfig previous = settings_.estimator.differentiator;
    const bool kept = pipeline_->retune(next.estimator.differentiator, next.estimator.decimation);
    publishDrained(ros::Time::now());
    settings_.estimator.differentiator = next.estimator.differentiator;
    settings_.estimator.decimation = next.estimator.decimation;
    settings_.base_residual_threshold = next.base_residual_threshold;
    settings_.still_velocity = next.still_velocity;
    params_ = params;
    if (!kept) {
      reconfigure_status_ = std::string("applied: differentiator '") +
                            typeName(settings_.estimator.differentiator.type) +
                            "': the filters restart";
      ROS_WARN("reconfigure: %s", reconfigure_status_.c_str());
    } else if (!sameDifferentiatorFields(previous, settings_.estimator.differentiator)) {
      reconfigure_status_ = std::string("applied: the filters kept (differentiator '") +
                            typeName(settings_.estimator.differentiator.type) +
                            "' does not read the setting changed)";
      ROS_INFO("reconfigure: %s", reconfigure_status_.c_str());
    } else if (!same) {
      reconfigure_status_ = "applied: decimation " +
                            std::to_string(settings_.estimator.decimation) +
                            ", thresholds (filters kept)";
      ROS_INFO("reconfigure: %s", reconfigure_status_.c_str());
    } else {
      reconfigure_status_ = "applied: nothing changed";
    }
  } catch (const std::exception& e) {
    // Refused whole: the server shows what is in force, and why in `status`.
    reconfigure_status_ = std::string("refused: ") + e.what();
    ROS_ERROR("reconfigure %s", reconfigure_status_.c_str());
  }
  config = toConfig(settings_, reconfigure_status_);
}

}  // namespace jle
