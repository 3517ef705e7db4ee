// The force plates of the estimator (PlateInputConfig): their samples, their contact at
// the estimate's stamp, and the decoded reaction applied to the foot. ROS-free.
#pragma once

#include <joint_load_estimator/estimation/input_buffer.hpp>
#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/force_plate.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>

#include <vector>

namespace jle {

struct PlateInputConfig;  // config.hpp

/// The force plates of one estimator, each filtered in six bank channels (force, moment:
/// what the foot applies to the plate, plate frame, about its origin). Every sample
/// enters the filter as measured. Where the raw signal at the estimate's stamp is in
/// contact (at or above the threshold) the reaction is the filtered wrench, decoded (COP,
/// free moment); below the threshold it is the raw wrench at the stamp, applied without a
/// COP (a force of at most the threshold; so the filters' memory of a stance never loads
/// a swinging foot, and the reaction has no step at heel strike or toe-off).
class PlateInputs {
 public:
  PlateInputs() = default;
  /// Plate k is filtered in channels first_channel + 6 k .. + 5. Throws
  /// std::invalid_argument naming the plate (link, timeout, threshold, surface, pose).
  PlateInputs(const Model<double>& model, const std::vector<PlateInputConfig>& configs,
              int first_channel);

  int size() const { return static_cast<int>(plates_.size()); }
  /// A sample of plate k at time t [s] (PlateInputConfig). Dropped (false) unless newer
  /// than the newest held and finite.
  bool add(int k, double t, const Eigen::Vector3d& force_plate,
           const Eigen::Vector3d& moment_plate);
  /// The pose of plate k in the world [m]. Throws naming the plate unless a finite
  /// rotation and position.
  void setPose(int k, const Eigen::Matrix3d& R_world_plate, const Eigen::Vector3d& p_world_plate);
  /// Which plates act on a computed segment: dynamics[s] != 0 for the computed segments s.
  void setNeeded(const Model<double>& model, const std::vector<char>& dynamics);

  /// At the joint sample t [s]: every needed plate's value into its six channels (half > 0:
  /// InputBuffer::centredAt).
  void resample(double t, double* channels, double half = 0.0) {
    for (Plate& p : plates_) p.samples.resample(t, p.needed, channels + p.channel, half);
  }
  /// Whether a plate with the kStop policy is stale.
  bool stopped() const {
    for (const Plate& p : plates_)
      if (p.samples.stopped()) return true;
    return false;
  }
  /// The contact of every needed plate on its raw signal at the estimate's stamp [s];
  /// true when any changed since the last call.
  bool updateContacts(double stamp);
  /// The reaction of every needed plate, added to its foot (after forwardKinematics,
  /// before inverseDynamics): in contact at the stamp decoded from its filtered wrench,
  /// else the raw wrench at the stamp (nothing where it does not press into the plate).
  template <typename Scalar>
  void apply(const Model<Scalar>& model, Data<Scalar>& data, const DifferentiatorBank& bank);
  /// Forgets every sample and contact.
  void reset();

  /// Plate k as applied at the last apply() (not loaded: nothing was applied; loaded
  /// without contact: the raw wrench, no COP).
  const PlateReading& reading(int k) const { return plates_[static_cast<std::size_t>(k)].reading; }
  /// Whether plate k was stale at the last joint sample.
  bool stale(int k) const { return plates_[static_cast<std::size_t>(k)].samples.stale(); }
  /// Whether plate k's foot is on a computed segment.
  bool needed(int k) const { return plates_[static_cast<std::size_t>(k)].needed; }

 private:
  struct Plate {
    ForcePlateConfig raw;       // as configured (the threshold acts on the raw signal)
    ForcePlateConfig filtered;  // raw with a zero threshold: decodes the filtered wrench
    InputBuffer samples;        // as measured
    InputBuffer::Vector6 raw_at_stamp = InputBuffer::Vector6::Zero();  // at the estimate's stamp
    int frame = 0;                                                     // the foot
    int channel = 0;
    bool needed = true;
    bool contact = false;  // raw signal in contact at the estimate's stamp
    PlateReading reading;
  };
  std::vector<Plate> plates_;
};

template <typename Scalar>
void PlateInputs::apply(const Model<Scalar>& model, Data<Scalar>& data,
                        const DifferentiatorBank& bank) {
  for (Plate& p : plates_) {
    p.reading = PlateReading();
    if (!p.needed) continue;
    if (p.contact) {
      const Wrench<double> w = filteredWrench(bank, p.channel);
      // In contact at the stamp; the filtered wrench still pressing into the plate.
      p.reading = readForcePlate(p.filtered, w.force, w.moment);
    } else {
      // Below the threshold: loaded without a COP (raw's threshold), or not at all.
      p.reading = readForcePlate(p.raw, p.raw_at_stamp.head<3>(), p.raw_at_stamp.tail<3>());
    }
    applyPlateReaction(model, data, p.frame, p.filtered, p.reading);  // joint_loads' code too
  }
}

}  // namespace jle
