// The result record of one published sample, and the part of the message path that fills
// it (pipeline.hpp): from the estimator that published the loads, the loads of the
// published joints, their coordinates and uncertainty, the inputs' and plates' side
// outputs, the base residual and the status bits; and from the joint samples it was told
// of, the stamp and the measured efforts of the sample the loads describe, which for a
// delayed estimate (a smoother's, due after later samples, or drained at a reset, a retune
// or the end of a stream) is not the newest. ROS-free; no allocation per record.
#pragma once

#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/estimation/external_effort.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/force_plate.hpp>
#include <joint_load_estimator/model/model.hpp>
#include <joint_load_estimator/pipeline/frame_resolver.hpp>
#include <joint_load_estimator/pipeline/timeline.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace jle {

/// Why a record's loads are not to be trusted: LoadsRecord::status holds these bits, 0
/// (kTrusted) when none applies. The node's JointLoads.status carries the same bits.
enum LoadsStatus : std::uint8_t {
  kTrusted = 0,
  /// Within plausibility/settle_time after the filters (re)started (a start, a jump of
  /// time, a gap, a retune, a confirmed jump of a position): the filters are settling.
  kSettling = 1,
  /// A needed wrench input or force plate was stale at the sample (its stale_policy
  /// applied: held, read as zero).
  kStaleInput = 2,
  /// An effort beyond plausibility/effort_factor times its joint's URDF effort limit.
  kImplausibleLoad = 4,
  /// Within plausibility/settle_time of a sample that held a needed joint's position from
  /// an earlier message (a publisher of split joint states slower than the others, or dead).
  kHeldJoint = 8,
};

/// The bits of `status` in words ("settling, stale input"); "trusted" for 0.
std::string describeStatus(std::uint8_t status);

/// A wrench input (settings.wrenches[k]) as it entered one published sample.
struct InputRecord {
  bool stale = false;  ///< stale at the sample (its stale_policy applied)
  /// A force/torque sensor (sensor_joint set): whether its reading was used (not while it
  /// is stale with the zero policy), and the reading minus the model's prediction: the
  /// load the distal side exerts beyond what the model and the other inputs explain (a
  /// tool's contact, or a bias), in the reading's frame `frame`, moment about its origin,
  /// the reading's sign [N, N m]. Zero when unused or not a sensor.
  bool used = false;
  Wrench<double> residual;
  /// The wrench the model predicts at the sensor's joint (same frame, point and sign as
  /// `residual`; the reading is residual + predicted). Zero when unused or not a sensor.
  Wrench<double> predicted;
  std::string frame;  ///< the reading's frame (the input's link when it has none)
};

/// A force plate (settings.force_plates[k]) as it entered one published sample.
struct PlateRecord {
  bool stale = false;  ///< stale at the sample
  /// Contact, centre of pressure and free moment (plate frame), reaction on the foot.
  PlateReading reading;
  std::string frame;  ///< the frame of the centre of pressure (the plate's)
};

/// The whole result of one published sample, sized at construction (no allocation per
/// sample): every front end (node, process_bag, joint_loads, the writers) reads this and
/// nothing else. Index i runs over the published joints.
struct LoadsRecord {
  Stamp stamp = 0;                 ///< the stamp of the joint state the loads describe
  std::vector<std::string> joint;  ///< URDF joint names
  std::vector<std::string> link;   ///< child link: the frame of force and moment
  std::vector<int> segment;        ///< model segment of each joint
  /// Joint wrench (on the child, by the parent), child link frame, moment about the
  /// joint origin [N], [N m].
  std::vector<Eigen::Vector3d> force, moment;
  std::vector<double> effort;           ///< [N m or N] projection on the joint axis
  std::vector<double> measured_effort;  ///< from the joint state at `stamp`; NaN: none
  /// With uncertainty enabled: 1-sigma effort [N m or N] and the wrench covariance per
  /// joint, row-major, 36 numbers (fx fy fz mx my mz), or 6 variances (diagonal_only).
  std::vector<double> effort_stddev, covariance;
  std::vector<double> effort_per_kg;  ///< effort / body_mass; empty when not configured
  /// The q, q-dot, q-ddot the loads were computed from (the filter's estimate at `stamp`,
  /// a mimic joint's mapped from its leader's) [rad or m, /s, /s^2]; 0 for a fixed joint.
  std::vector<double> position, velocity, acceleration;
  /// With settings.friction.enabled: effort + damping velocity + friction tanh(velocity /
  /// velocity_scale) (friction.hpp) [N m or N]; empty when off.
  std::vector<double> motor_effort;
  /// With external_effort/enabled (external_effort.hpp; empty when off): per joint the
  /// external effort of the configured method, the environment's generalised force on the
  /// robot [N m or N] (NaN where no effort was measured or the joint does not move), and
  /// with uncertainty its 1-sigma from external_effort/effort_noise.
  std::vector<double> external_effort, external_effort_stddev;
  /// The wrench at each external_effort/contacts link (link frame, about its origin).
  std::vector<ContactEstimate> contacts;
  /// Contact detection at this sample: in contact, it started / ended here, its joint
  /// changed here while it lasts, and the contact's joint (the most distal over its
  /// threshold, ExternalEffort::contactJoint), with its child link. A contact event (the
  /// node's ~contact) is a sample where it started, changed or ended.
  bool in_contact = false, contact_started = false, contact_ended = false, contact_changed = false;
  std::string contact_joint, contact_link;
  /// The estimated q, q-dot, q-ddot of every coordinate (model coordinate order) [rad or
  /// m, /s, /s^2].
  Eigen::VectorXd q, qd, qdd;
  /// Per wrench input and per force plate (settings order).
  std::vector<InputRecord> inputs;
  std::vector<PlateRecord> plates;
  /// A floating base: the wrench the model needs at the base beyond every input (root
  /// link frame, about its origin) [N, N m], zero when the inputs explain the motion (a
  /// check of the model and the inputs). Zero for a fixed base.
  Eigen::Vector3d base_force = Eigen::Vector3d::Zero(), base_moment = Eigen::Vector3d::Zero();
  bool planar = false;             ///< computed by the planar 3x3 path (savings.planar)
  std::uint8_t status = kTrusted;  ///< LoadsStatus bits: why the loads are not to be trusted
};

/// The ModelOptions that `settings` ask for (floating_base, keep_fixed_joints,

/// Segments whose loads are published: `joints` (URDF names of moving joints, or of
/// fixed joints kept as segments), or every moving segment when it is empty. Throws
/// SettingsError naming the joint.
std::vector<int> publishedSegments(const Model<double>& model,
                                   const std::vector<std::string>& joints);

/// Fills the records of one stream (the immediate or the smoothed: the same builder for
/// both, each record sized by sizedRecord()).
class RecordBuilder {
 public:
  /// `model`, `settings` (estimator.joints, the uncertainty, friction, plausibility and
  /// body_mass settings, the wrench inputs and plates), `frames` and `timeline` must
  /// outlive the builder. Throws SettingsError naming body_mass where it is -1 and the
  /// URDF has no mass.
  RecordBuilder(const Model<double>& model, const Settings& settings, const FrameResolver& frames,
                const Timeline& timeline);

  /// A record of the published joints (publishedSegments(settings.estimator.joints)), the
  /// inputs and the plates, its vectors sized and its names set: fill() changes only
  /// values. No external outputs (the Pipeline adds them).
  LoadsRecord sizedRecord() const;

  /// A joint sample was taken: at estimator time t [s], stamped `stamp`, with the measured
  /// efforts of the published joints (published-joint order) or null when its messages had
  /// none. `delay`: the most samples behind the newest that an estimate still to come can
  /// be (Estimator::Filters::delaySamples over the streams): the samples remembered grow to twice
  /// that when they do not fit (rare after the warm-up: a faster rate, a gap).
  void remember(double t, Stamp stamp, const std::vector<double>* effort, int delay);
  /// Forgets the samples remembered (the filters restarted: no estimate of theirs comes).
  void forget() { ring_count_ = 0; }
  /// A sample at estimator time t [s] held a needed joint's position from an earlier
  /// message: the records within plausibility/settle_time of it are kHeldJoint.
  void heldAt(double t) { held_t_ = t; }
  /// No sample held a joint on this timeline (a jump of time).
  void clearHeld() { held_t_ = -1e300; }

  /// The stamp of the joint sample at estimator time t [s]: its own where remembered, else
  /// the timeline's Timeline::absolute(t).
  Stamp stampAt(double t) const;
  /// `rec` (as sizedRecord() made it) for the loads `estimator` published last, in a stream
  /// whose filters last (re)started at estimator time `settle_from` [s]: stamp and measured
  /// efforts of their own sample, loads, coordinates, uncertainty, side outputs, status.
  /// Returns whether every force, moment and effort of `rec` (and its base residual) is
  /// finite: a record that may be published.
  bool fill(const Estimator& estimator, double settle_from, LoadsRecord& rec) const;
  /// The LoadsStatus bits of `rec`, filled from `estimator`'s last published loads.
  std::uint8_t status(const Estimator& estimator, double settle_from, const LoadsRecord& rec) const;

 private:
  // Whether every force, moment and effort of `rec` (and its base residual) is finite.
  static bool finiteLoads(const LoadsRecord& rec);

  // One joint sample taken: its time, stamp and measured efforts.
  struct Sample {
    double t = 0.0;
    Stamp stamp = 0;
    bool has_effort = false;
    std::vector<double> effort;
  };
  const Sample* sampleAt(double t) const;
  void growRing(std::size_t size);
  void fillSideOutputs(const Estimator& estimator, LoadsRecord& rec) const;
  void fillCoordinates(const Estimator& estimator, LoadsRecord& rec, std::size_t i,
                       std::size_t segment) const;

  const Model<double>& model_;
  const Settings& settings_;
  const FrameResolver& frames_;
  const Timeline& timeline_;
  std::vector<int> segments_;  // published
  double body_mass_ = 0.0;     // [kg] effort_per_kg divisor; 0: none
  // Ring of the latest joint samples, to give an estimate its stamp and measured efforts.
  std::vector<Sample> ring_;
  std::size_t ring_head_ = 0, ring_count_ = 0;
  double held_t_ = -1e300;  // estimator time of the last sample that held a joint
};

}  // namespace jle
