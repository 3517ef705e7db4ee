#pragma once
// Whether a force/torque sensor is declared with the wrong sign: a sensor input
// (WrenchInputConfig::sensor_joint) whose readings, once signed by `sign`, are the
// opposite of the wrench the model predicts at its joint. A payload or tool that the URDF
// holds distal to the sensor makes the prediction its weight (and inertia); a reading of
// -prediction is what a sensor reporting the other side's load gives. Counted over the
// records of a stream (the node per diagnostics period, process_bag over the bag), not
// decided on one sample: a push can oppose the prediction for a moment, a wrong sign does
// at every sample.
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <string>

namespace jle {

/// The samples of one sensor input that decide (used, the predicted force above a
/// minimum) and, of those, the ones whose reading opposes the prediction.
struct SignTally {
  long decisive = 0;
  long opposed = 0;
};

/// The decisive samples a tally remembers: at this many both counts are halved, so that a
/// sign corrected live (a retune, a sensor replaced) is no longer named after a while.
constexpr long kSignMemory = 2000;

/// Adds one record's sensor input: decisive when the reading was used and the predicted
/// force is above `min_force` [N]; opposed when the reading's force is within a quarter
/// of the predicted force's size of minus the prediction.
void tallySign(const InputRecord& input, double min_force, SignTally& tally);

/// A warning naming `sensor_joint` and its `sign` when at least 20 samples decided and
/// more than 80 % of them opposed the prediction; empty otherwise.
std::string signWarning(const std::string& sensor_joint, double sign, const SignTally& tally);

}  // namespace jle
