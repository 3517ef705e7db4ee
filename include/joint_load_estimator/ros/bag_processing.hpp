// A bag through the node's message path, offline: what process_bag runs and the Python
// bindings call (joint_load_estimator.process_bag). The joint states, the configured
// wrench and force plate topics and /tf, /tf_static are read in the bag's time order
// and fed to jle::Pipeline through the node's own conversions; the loads go to a sink.
#pragma once

#include <joint_load_estimator/filters/zero_phase.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <string>

namespace jle {

/// What to read, and how (process_bag's options but its outputs).
struct BagOptions {
  std::string bag;   ///< the input bag
  std::string urdf;  ///< the robot
  /// The node's parameters as a YAML file (config/default.yaml); empty: every default.
  std::string config;
  /// Smooth the whole record offline first (process_bag --zero-phase, zero_phase.hpp):
  /// the positions and, with the same filter, every wrench and plate message; the
  /// differentiator is then central differences of the smoothed positions.
  bool smooth = false;
  ZeroPhaseConfig smoothing;
  /// process_bag --accept-nonphysical-inertia: the setting accept_nonphysical_inertia
  /// set to true whatever the config says (false: the config's).
  bool accept_nonphysical_inertia = false;
  /// Progress (on a terminal) and the summary lines on standard error; warnings are
  /// said in any case.
  bool summary = true;
};

/// Where the loads of a bag go.
class LoadsSink {
 public:
  virtual ~LoadsSink() = default;
  /// Once, before the first message: the pipeline is set up and its record sized.
  virtual void open(const Pipeline& pipeline) = 0;
  /// Every published sample, `seq` counting from 0.
  virtual void write(const LoadsRecord& record, long seq) = 0;
  /// Every sample of the smoothed stream (Pipeline::smoothedRecord), `seq` counting from 0.
  virtual void writeSmoothed(const LoadsRecord& /*record*/, long /*seq*/) {}
  /// After the last message, when there were loads.
  virtual void commit() {}
  /// For the summary: " to PATH", or " (not written)".
  virtual std::string destination() const { return ""; }
};

/// Runs the bag through the pipeline into `sink`. Warnings (each problem once) and the
/// summary go to standard error, prefixed "process_bag: ". Throws std::runtime_error
/// naming the culprit: an unreadable bag or URDF, a bad setting (with the config file's
/// name), a missing joint-states topic, a frame the bag cannot resolve, no loads at all.
void processBag(const BagOptions& options, LoadsSink& sink);

}  // namespace jle
