// The cost of the message side of a sample: filling ~joint_loads from the solver's
// results and serializing it (what roscpp does before a publish), for the 7-joint arm.
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/dynamics.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

#include <benchmark/benchmark.h>
#include <ros/serialization.h>

#include <vector>

namespace {

void messageConversion(benchmark::State& state) {
  const jle::Model<double> model =
      jle::modelFromUrdfFile(std::string(JLE_BENCH_DATA) + "/urdf/chains/panda_chain.urdf");
  jle::Data<double> data(model);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(model.nq, 0.3);
  jle::rnea(model, data, q, q, q, Eigen::Vector3d(0, 0, -9.80665));
  joint_load_estimator::JointLoads msg;
  const std::size_t n = model.moving_segments.size();
  msg.name.resize(n);
  msg.wrench.resize(n);
  msg.effort.resize(n);
  msg.measured_effort.resize(n);
  for (std::size_t i = 0; i < n; ++i) msg.name[i] = model.joint_name[model.moving_segments[i]];
  std::vector<std::uint8_t> buffer(ros::serialization::serializationLength(msg) + 64);
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) {
      const int s = model.moving_segments[i];
      geometry_msgs::Wrench& w = msg.wrench[i];
      w.force.x = data.force[s].x();
      w.force.y = data.force[s].y();
      w.force.z = data.force[s].z();
      w.torque.x = data.moment[s].x();
      w.torque.y = data.moment[s].y();
      w.torque.z = data.moment[s].z();
      msg.effort[i] = data.effort[s];
      msg.measured_effort[i] = 0.0;
    }
    ros::serialization::OStream stream(buffer.data(), static_cast<uint32_t>(buffer.size()));
    ros::serialization::serialize(stream, msg);
    benchmark::DoNotOptimize(buffer.data());
  }
}

}  // namespace

BENCHMARK(messageConversion);
BENCHMARK_MAIN();
