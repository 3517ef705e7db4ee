#include <joint_load_estimator/estimation/sensor_sign.hpp>

#include <cstdio>

namespace jle {

void tallySign(const InputRecord& input, double min_force, SignTally& tally) {
  const double predicted = input.predicted.force.norm();
  if (!input.used || !(predicted > min_force)) return;
  ++tally.decisive;
  // The reading is residual + predicted; opposed: reading + predicted near zero.
  const Eigen::Vector3d sum = input.residual.force + 2.0 * input.predicted.force;
  if (sum.norm() < 0.25 * predicted) ++tally.opposed;
  if (tally.decisive >= kSignMemory) {  // forget the older half: the recent readings decide
    tally.decisive /= 2;
    tally.opposed /= 2;
  }
}

std::string signWarning(const std::string& sensor_joint, double sign, const SignTally& tally) {
  constexpr long kMinDecisive = 20;
  if (tally.decisive < kMinDecisive || 5 * tally.opposed <= 4 * tally.decisive) return {};
  char text[320];
  std::snprintf(text, sizeof text,
                "sensor %s: its readings are the opposite of the model's prediction in %ld of "
                "%ld samples: is its sign wrong? (sign: %g; the input is the wrench the "
                "joint's parent link exerts on its child link)",
                sensor_joint.c_str(), tally.opposed, tally.decisive, sign);
  return text;
}

}  // namespace jle
