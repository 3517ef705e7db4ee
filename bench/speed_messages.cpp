// The cost of the message side of a sample, on the node's own code for the 7-joint arm
// with the default settings: a sensor_msgs/JointState through jle::feed (the Pipeline),
// the record into ~joint_loads (jle::toMessage) and its serialization (what roscpp does
// before a publish); against the same samples given to the Estimator alone, in the same
// run, so that the ratio is the message path's overhead. nodeMessagePath/0 has the
// immediate stream alone (smoothed/enabled: false); /1 both streams, the default, the
// smoothed record serialised too (docs/how_it_works.md "Two streams": their ratio is the cost of
// both).
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>
#include <joint_load_estimator/ros/conversions.hpp>

#include "benchmark_main.hpp"

#include <benchmark/benchmark.h>
#include <ros/serialization.h>

#include <cmath>
#include <vector>

namespace {

const jle::Model<double>& panda() {
  static const jle::Model<double> model =
      jle::modelFromUrdfFile(std::string(JLE_BENCH_DATA) + "/urdf/chains/panda_chain.urdf");
  return model;
}

// Sample k of a smooth motion at 1 kHz (the positions of every coordinate).
void positions(int k, std::vector<double>& q) {
  for (std::size_t i = 0; i < q.size(); ++i)
    q[i] = 0.5 * std::sin(2e-3 * k * (1.0 + 0.1 * static_cast<double>(i)) + static_cast<double>(i));
}

void estimatorOnly(benchmark::State& state) {
  jle::Estimator estimator(panda(), jle::Settings().estimator);
  std::vector<double> q(static_cast<std::size_t>(panda().nq));
  int k = 0;
  for (auto _ : state) {
    positions(k, q);
    benchmark::DoNotOptimize(estimator.addJointSample(1e-3 * k++, q.data()));
  }
}

// The record into a ~joint_loads message and its bytes.
void serialize(const jle::LoadsRecord& record, joint_load_estimator::JointLoads& msg,
               std::vector<std::uint8_t>& buffer) {
  jle::toMessage(record, msg);
  ros::serialization::OStream stream(buffer.data(), static_cast<uint32_t>(buffer.size()));
  ros::serialization::serialize(stream, msg);
  benchmark::DoNotOptimize(buffer.data());
}

void nodeMessagePath(benchmark::State& state) {
  jle::Settings settings;
  settings.smoothed.enabled = state.range(0) != 0;
  jle::Pipeline pipeline(panda(), settings, nullptr);
  sensor_msgs::JointState js;
  js.name = panda().coordinate_names;
  js.position.resize(js.name.size());
  js.effort.assign(js.name.size(), 1.0);
  joint_load_estimator::JointLoads msg;
  jle::prepare(pipeline.record(), msg);
  std::vector<std::uint8_t> buffer(ros::serialization::serializationLength(msg) + 64);
  const ros::Time start(1700000000, 0);
  int k = 0;
  for (auto _ : state) {
    positions(k, js.position);
    js.header.stamp = start + ros::Duration(1e-3 * k++);
    const bool immediate = jle::feed(pipeline, js, js.header.stamp) == jle::Outcome::kPublished;
    if (immediate) serialize(pipeline.record(), msg, buffer);
    if (pipeline.smoothedPublished()) serialize(pipeline.smoothedRecord(), msg, buffer);
  }
}

}  // namespace

BENCHMARK(estimatorOnly);
BENCHMARK(nodeMessagePath)->Arg(0)->Arg(1);
int main(int argc, char** argv) {
  const char* const usage =
      "usage: bench_speed_messages [Google Benchmark options, e.g. --benchmark_filter=REGEX]\n"
      "The node's message path per joint state (jle::Pipeline, the record into a message and\n"
      "its serialization), the immediate stream alone and both streams, beside the estimator\n"
      "alone in the same run.\n";
  return jle_bench::benchmarkMain(argc, argv, "bench_speed_messages", usage);
}
