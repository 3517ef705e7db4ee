// The whole message path, ROS-free: raw samples (joint states, wrenches, force plates,
// each with its stamp) in, one result record out. Every front end drives it: the node,
// the nodelet, process_bag, the soaks and the fuzzers; a front end converts messages to
// its arguments and its record to messages, and decides nothing. Offline and online give
// the same loads for the same samples in the same order. Its parts, each with its own
// tests: FrameResolver (where the inputs are), Timeline (the time axis, rogue stamps and
// jumps of time), JointStateMap (joint states onto the model's coordinates), the Estimator
// of each stream, ExternalEffort, and RecordBuilder (the result record); the Pipeline
// orders them, merges the instants of split publishers, applies the plausibility rules and
// counts every message under its outcome.
#pragma once

#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/estimation/external_effort.hpp>
#include <joint_load_estimator/filters/sample_clock.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/model.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/frame_resolver.hpp>
#include <joint_load_estimator/pipeline/joint_state_map.hpp>
#include <joint_load_estimator/pipeline/plausibility.hpp>
#include <joint_load_estimator/pipeline/record_builder.hpp>
#include <joint_load_estimator/pipeline/timeline.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace jle {

/// What became of one input message. Every message is either used or counted under
/// the reason it was not (PipelineCounters).
enum class Outcome : std::uint8_t {
  kUsed,       ///< taken (a joint state entered the filters; no loads for it yet)
  kPublished,  ///< a joint state: loads computed, record() holds them
  /// A joint state carrying part of the needed joints, merged with the other publishers'
  /// messages of its instant (Settings::stamps.merge_window) into one sample, whose outcome
  /// is counted under the instant's last message. While the instant waits for a publisher
  /// its last message is counted here; when a later instant closes it incomplete, the
  /// sample is taken with the missing joints held (held_samples, kHeldJoint) and that
  /// message is counted under the sample's outcome instead.
  kMerged,
  kInvalid,     ///< sizes disagree, a name twice, or a non-finite position
  kOrder,       ///< same or older stamp than the input's previous one
  kFrame,       ///< frame neither rigid to the link in the URDF nor known to the FrameSource
  kNoBasePose,  ///< floating base: no pose of the base at the stamp
  kWaiting,     ///< a coordinate the computed loads need has had no position yet
  kStale,       ///< an input with stale_policy stop is stale: no loads
  kUnchanged,   ///< same filtered inputs as the last loads and republish_unchanged off
  /// a joint state that sets no coordinate the computed loads need (empty, or only a
  /// gripper's joints): its positions are kept, but it is not a sample
  kNoJoint,
  /// A rogue stamp (docs/node.md, "Time stamps"): far from the joint-state stream's and not
  /// (yet) a confirmed jump of time, a wrench or plate ahead of the joint states by more
  /// than its timeout, or stamp 0 on a stream that has had stamps
  kRogueStamp,
  /// A value no joint or sensor of the model produces (Settings::plausibility): a position
  /// beyond its URDF limits or moving faster than its joint can, a wrench beyond the
  /// bound; dropped before it reaches a filter
  kImplausible,
  /// Loads that are not finite: not published, the filters restarted
  kNonFinite,
  kCount
};

const char* toString(Outcome outcome);

/// The same key for two problems (Pipeline::problem()) that differ only in their
/// numbers (stamps, values, counts): what a front end throttles or says once per, so
/// that one problem repeating is not said again and again while another is still said.
std::size_t problemKey(const std::string& problem);

/// The kinds of input message, for counting and for throttling messages per kind.
enum class InputKind : std::uint8_t { kJointState, kWrench, kPlate, kCount };

/// Counts per kind of input and per outcome, plus the events.
struct PipelineCounters {
  std::array<std::array<long, static_cast<int>(Outcome::kCount)>,
             static_cast<int>(InputKind::kCount)>
      outcomes{};
  long unknown_joints = 0;  ///< joint states naming a joint the model does not have
  long resets = 0;          ///< jumps of time, back or confirmed forward (the filters were reset)
  long forward_jumps = 0;   ///< of the resets, the confirmed jumps forward
  long backJumps() const { return resets - forward_jumps; }
  /// joint states with a non-finite effort (that joint's measured effort is none; the
  /// loads are computed)
  long nonfinite_efforts = 0;
  /// joint states with a non-finite velocity (that joint's velocity is none at the sample:
  /// Estimator::addJointSample takes its velocity filter's prediction; the loads are
  /// computed)
  long nonfinite_velocities = 0;
  /// joint states with a mimic joint's position contradicting its leader's (beyond
  /// plausibility/mimic_tolerance; the model's value is used)
  long mimic_contradictions = 0;
  /// samples taken with a coordinate the loads need held from an earlier message: an
  /// instant of joint states split over publishers that a later one closed before every
  /// publisher spoke (a slower or dead publisher; docs/node.md "Never silently wrong")
  long held_samples = 0;

  long received(InputKind kind) const;
  long count(InputKind kind, Outcome outcome) const {
    return outcomes[static_cast<int>(kind)][static_cast<int>(outcome)];
  }
  /// Over every kind of input.
  long count(Outcome outcome) const;
};

/// The ModelOptions that `settings` ask for (floating_base, keep_fixed_joints,
/// accept_nonphysical_inertia).
ModelOptions modelOptions(const Settings& settings);

class Pipeline {
 public:
  /// `model` as modelOptions(settings) asks. `frames` may be null (only the URDF's own
  /// frames are known) and must outlive the pipeline. Throws SettingsError or
  /// std::invalid_argument naming the key, link or joint.
  Pipeline(const Model<double>& model, const Settings& settings, FrameSource* frames);
  Pipeline(const Pipeline&) = delete;  // its parts refer to its model and settings
  Pipeline& operator=(const Pipeline&) = delete;

  /// A joint state: names, positions (same size), velocities and efforts (empty or the
  /// same size; a non-finite velocity or effort only drops that joint's measured value).
  /// Messages of several publishers within stamps/merge_window are one sample, stamped with
  /// the newest stamp among them, taken when every needed joint has come (kMerged). `clock` is
  /// the front end's clock when the message arrived (the node: ros::Time::now(); a bag: the
  /// message's bag time): it going back confirms a backward jump of time (a looping bag), and it
  /// stands for stamp 0 on a stream that never had a stamp (docs/node.md, "Time stamps"). The
  /// estimator is fed the sample's instant (the stamp, or with stamps/regularize the SampleClock's
  /// estimate); the loads keep the message's own stamp.
  Outcome onJointState(Stamp stamp, Stamp clock, const std::vector<std::string>& names,
                       const std::vector<double>& position, const std::vector<double>& velocity,
                       const std::vector<double>& effort);
  /// The end of a stream (process_bag, joint_loads, a replay's last message): an instant
  /// still waiting for a publisher is taken (its missing joints held); with a
  /// smoother (differentiator/lag > 0) the joint states whose loads are still to come are
  /// smoothed with the data there is; each call that returns true puts the next one's
  /// loads in record(), false when none is left (each was counted when it came).
  bool flush();
  /// With a smoother: the joint states whose loads were still to come when the timeline
  /// restarted (a jump back of time, as a looping bag makes) or retune() replaced the
  /// filter, smoothed with the data there was, before it was forgotten; then those due
  /// at the newest joint state besides the one it published (the delay is
  /// differentiator/lag in seconds: where the rate drops, or after a gap, several are
  /// due at once; made when taken, estimator() holds their loads). Call after every
  /// input call and retune() until it returns false: each true puts the next of them,
  /// oldest first, in record() (each was counted when it came). The call that restarted
  /// the timeline publishes nothing itself (the new filter is warming up).
  bool takeDrained();
  /// A wrench of input k (settings.wrenches[k]) as the message carries it: force [N]
  /// and torque [N m] in `frame_id` (the configured frame, when set, wins), moment about
  /// its origin. Its stamp follows the rules of docs/node.md, "Time stamps": stamp 0, and a
  /// reading ahead of the joint states by more than its timeout, are rogue stamps.
  Outcome onWrench(int k, Stamp stamp, Stamp clock, const std::string& frame_id,
                   const Eigen::Vector3d& force, const Eigen::Vector3d& torque);
  /// A sample of force plate k (settings.force_plates[k]): what the foot applies to
  /// the plate, plate frame, moment about the plate origin.
  Outcome onPlate(int k, Stamp stamp, Stamp clock, const std::string& frame_id,
                  const Eigen::Vector3d& force, const Eigen::Vector3d& moment);

  /// The sensor offset of wrench input k in the reading's own frame and sign,
  /// subtracted from every later reading (bias_file, ~calibrate_bias).
  void setSensorBias(int k, const Eigen::Vector3d& force, const Eigen::Vector3d& torque);
  /// Live tuning of the differentiator and the decimation (Estimator::retune: the
  /// decimation in place, a new differentiator restarts the filters); settings() follows.
  /// Returns false when the filters were restarted. Throws std::invalid_argument naming
  /// the parameter, changing nothing, on a bad value.
  bool retune(const DifferentiatorConfig& differentiator, int decimation);
  const Eigen::Vector3d& sensorBiasForce(int k) const { return wrenches_[ix(k)].bias_force; }
  const Eigen::Vector3d& sensorBiasTorque(int k) const { return wrenches_[ix(k)].bias_torque; }

  /// Why the last message was not used (its outcome's explanation, naming the joint,
  /// input or frame); empty after a used message.
  const std::string& problem() const { return problem_; }
  /// The first joint of the last joint state that the model does not have (ignored,
  /// the others used), or empty.
  const std::string& unknownJoint() const { return unknown_joint_; }
  /// The first joint of the last joint state whose effort was not finite, or empty.
  const std::string& nonFiniteEffort() const { return nonfinite_effort_; }
  /// The first joint of the last joint state whose velocity was not finite, or empty.
  const std::string& nonFiniteVelocity() const { return nonfinite_velocity_; }
  /// The last joint state's first mimic joint whose position contradicts its leader's, in
  /// words ("joint 'b' is 0.5, its leader 'a' gives 0.3"), or empty.
  const std::string& mimicContradiction() const { return mimic_contradiction_; }
  /// The first coordinate the computed loads need that has had no position yet, or empty.
  const std::string& missingJoint() const;
  /// The topics of the inputs with stale_policy stop that were stale at the last joint
  /// sample (no loads while there is one), ", " between them; empty if none.
  std::string stoppingInputs() const;
  /// Whether the last message reset the filters (a confirmed jump of time, back or
  /// forward, or the clock going back), and from when to when [ns].
  bool jumped() const { return timeline_.jumped(); }
  Stamp jumpFrom() const { return timeline_.jumpFrom(); }
  Stamp jumpTo() const { return timeline_.jumpTo(); }
  /// Whether that jump went forward (stamps far ahead, confirmed), not back.
  bool jumpedForward() const { return timeline_.jumpedForward(); }

  /// The immediate stream's record: the loads of the last joint state that returned
  /// kPublished (or of flush(), takeDrained()).
  const LoadsRecord& record() const { return record_; }

  /// The smoothed stream (settings.smoothed; docs/how_it_works.md, "Two streams"): the loads of the
  /// same samples, taken through the same checks, by a second estimator whose filter is the
  /// smoother of settings.smoothed, its loads `lag` seconds of stamps behind the newest
  /// joint state. Its records carry no external efforts or contacts (the immediate
  /// stream's). False when smoothed/enabled is false, and then nothing below applies.
  bool hasSmoothed() const { return smoothed_ != nullptr; }
  /// Whether the last input call put a sample's smoothed loads in smoothedRecord().
  bool smoothedPublished() const { return smoothed_published_; }
  const LoadsRecord& smoothedRecord() const { return smoothed_->record; }
  /// As flush() and takeDrained(), for the smoothed stream (call both after the
  /// immediate stream's: each puts the next of its records in smoothedRecord()).
  bool flushSmoothed();
  bool takeDrainedSmoothed();
  /// The smoothed stream's bandwidth [Hz] (its smoother's gain is 1/2 there): chosen from
  /// the joint positions' spectrum where smoothed.differentiator.auto_bandwidth (before
  /// the first choice, process_noise's); 0 without one.
  double smoothedBandwidth() const {
    return smoothed_ ? smoothed_->estimator.filters().bandwidth() : 0.0;
  }
  /// What a user must hear when the smoothed stream's bandwidth sits on a bound of its
  /// search (issue 37: never a silent choice): the lag's floor above the data's choice, or
  /// the highest where the positions' spectrum shows no noise floor; empty otherwise (and
  /// before the spectrum's first choice).
  std::string smoothedBandwidthBound() const;
  /// Whether the smoothed stream takes q-dot and q-ddot from the measured velocities where
  /// the joint states carry them (Estimator::velocitiesBetter), or from the positions.
  bool smoothedVelocities() const {
    return smoothed_ && smoothed_->estimator.filters().velocitiesUsed() > 0 &&
           smoothed_->estimator.filters().velocitiesBetter();
  }
  const PipelineCounters& counters() const { return counters_; }
  const Settings& settings() const { return settings_; }
  /// What the computed loads need, fixed at construction: coordinate i, wrench input k,
  /// force plate k (an input on no computed segment is not needed: a front end need not
  /// subscribe to it).
  bool coordinateNeeded(int i) const { return estimator_.layout().coordinateNeeded(i); }
  bool inputNeeded(int k) const { return estimator_.layout().inputNeeded(k); }
  bool plateNeeded(int k) const { return estimator_.layout().plateNeeded(k); }
  /// How many coordinates take their q-dot from the measured velocities, and whether
  /// coordinate i does (decided at the first sample after a start, reset or retune).
  int velocitiesUsed() const { return estimator_.filters().velocitiesUsed(); }
  bool velocityUsed(int i) const { return estimator_.filters().velocityUsed(i); }
  /// The immediate stream's delay behind the newest joint state in samples, and the
  /// samples taken whose loads are still to come (a smoother's; Estimator::Filters::delaySamples,
  /// pendingSamples).
  int delaySamples() const { return estimator_.filters().delaySamples(); }
  int pendingSamples() const { return estimator_.filters().pendingSamples(); }
  /// Whether the planar 3x3 path is in use (savings.planar), and why not if it is not.
  bool planar() const { return estimator_.layout().planar(); }
  const std::string& planarReason() const { return estimator_.layout().planarReason(); }
  /// The topics of every wrench input and force plate that was stale at the last joint
  /// sample, whatever its policy, ", " between them; empty if none.
  std::string staleInputs() const;
  /// The external-effort estimator (external_effort/enabled), or null.
  const ExternalEffort* externalEffort() const { return external_.get(); }
  /// The joint-state stream's sample clock (stamps/regularize).
  const SampleClock& sampleClock() const { return timeline_.sampleClock(); }
  const Model<double>& model() const { return estimator_.model(); }
  /// The origin of the estimator's time axis [ns]: the first stamp after the start, after
  /// a reset, or after a stamp more than 2^52 ns (52 days) away from the previous origin.
  /// None until a message has been taken.
  bool hasTimeOrigin() const { return timeline_.hasOrigin(); }
  Stamp timeOrigin() const { return timeline_.origin(); }

  /// Wrench input k's last resolved frame (the frame of its sensor residual), or empty.
  const std::string& wrenchFrame(int k) const { return frame_resolver_.wrenchFrame(k); }

 private:
  struct WrenchInput {
    Eigen::Vector3d bias_force = Eigen::Vector3d::Zero(), bias_torque = Eigen::Vector3d::Zero();
    bool stamped = false;  // has had a non-zero stamp
  };
  struct PlateInput {
    bool stamped = false;
  };
  // The smoothed stream: its estimator, its record, and its loads drained by a reset.
  // When a stream's filters last (re)started: at the first sample after a reset (a
  // start, a jump of time, a restart for non-finite loads), or at the first of a warm-up
  // (a gap or a retune restarts them inside the estimator).
  struct Settle {
    double from = 0.0;      // estimator time [s] of that sample
    bool restarted = true;  // the next sample taken starts the filters
    bool warming = false;   // the last sample taken was a warm-up one
  };
  struct Stream {
    Stream(const Model<double>& model, const EstimatorConfig& config) : estimator(model, config) {}
    Estimator estimator;
    LoadsRecord record;
    std::vector<LoadsRecord> drained;
    std::size_t drained_next = 0;
    Settle settle;
  };
  // The instant being assembled from the joint states of several publishers: the
  // stamps of its oldest and newest message, whether one had efforts, and whether its last
  // message was counted kMerged (not kWaiting).
  struct Group {
    bool open = false;
    Stamp oldest = 0, newest = 0;
    bool has_effort = false;
    bool last_merged = false;
  };

  static std::size_t ix(int k) { return static_cast<std::size_t>(k); }
  Outcome count(InputKind kind, Outcome outcome);
  Outcome fail(InputKind kind, Outcome outcome, const std::string& why);
  bool movesNeeded() const;
  // A message's stamp as the timeline found it: kUsed to go on (after a jump, the filters
  // reset first), or the rogue stamp counted.
  Outcome stampOutcome(InputKind kind, StampVerdict verdict);
  // A jump of time: what holds the old timeline's samples taken or forgotten, then the
  // timeline restarted.
  void resetTimeline();
  bool checkJointState(const std::vector<std::string>& names, const std::vector<double>& position,
                       const std::vector<double>& velocity, const std::vector<double>& effort);
  void mapJointState(const std::vector<std::string>& names, const std::vector<double>& position,
                     const std::vector<double>& velocity, const std::vector<double>& effort);
  bool basePose(Stamp stamp, BasePose& base);
  Outcome sample(Stamp stamp, bool has_effort, const BasePose* base);
  // Split publishers: whether the last bound message joins the open instant, whether the
  // instant has every needed joint, the instant taken (its sample's outcome), and an
  // incomplete one closed (taken with the missing joints held, or forgotten while a
  // joint was never received).
  bool joinsGroup(Stamp stamp) const;
  bool groupComplete() const;
  Outcome takeGroup();
  void closeGroup();
  // A closed instant's loads (record_, the smoothed record) into the drained lists before
  // another sample overwrites them (true if any was); unstash: the message's own loads
  // after them, so that a front end publishes them in order.
  bool stashGroupRecords();
  void unstash(bool immediate_published);
  Outcome staleProblem();
  void remember(double t, Stamp stamp, bool has_effort);
  bool resolvePlatePose(int k, const std::string& frame);
  // The record of the loads `estimator` (either stream's) published last, with the
  // external outputs in the immediate stream's record_; whether its loads are finite.
  bool fillRecord(const Estimator& estimator, LoadsRecord& rec);
  static void noteStart(Settle& settle, SampleStatus status, double t);
  void countHeld(double t);
  // Plausibility at the door (Settings::plausibility); false with problem_ set.
  bool plausibleJointState(Stamp stamp, const std::vector<std::string>& names,
                           const std::vector<double>& position);
  const std::vector<double>& plausibleVelocities(const std::vector<double>& velocity);
  bool plausibleWrench(InputKind kind, const std::string& topic, const Eigen::Vector3d& force,
                       const Eigen::Vector3d& moment);
  // What a wrench or plate reading (`what`: "wrench 'topic'", "force plate 'name'") passes
  // before its frame is resolved: finite values, a frame (has_frame), a stamp that is not
  // zero (`stamped` and `stamp` as Timeline::zeroStamp: a zero stamp on a stream that never had one
  // becomes the clock), the time axis (timeout [s]) and plausible values. kUsed when it passes,
  // else the outcome counted with problem_ set.
  Outcome admitReading(InputKind kind, const std::string& what, bool has_frame, bool& stamped,
                       Stamp& stamp, Stamp clock, double timeout, const Eigen::Vector3d& force,
                       const Eigen::Vector3d& moment);
  // An input's sample refused by the estimator as not newer than its last.
  Outcome notNewer(InputKind kind, const std::string& what, Stamp stamp);
  // The filters start again from the next sample. drain: the smoother's pending samples
  // are published first (their state is good); else they are dropped (poisoned).
  void restartFilters(bool drain);
  void setUpExternal();
  void fillExternal();
  void drainSmoother();
  static bool takeFrom(LoadsRecord& record, std::vector<LoadsRecord>& drained, std::size_t& next);
  void sampleSmoothed(double t, const BasePose* base);
  // The next loads `estimator` has (end: flush() at the end of a stream, else those due
  // now) into `record`, skipping the decimated, stale and unchanged ones.
  bool nextRecord(Estimator& estimator, LoadsRecord& record, bool end);

  Settings settings_;
  Estimator estimator_;
  FrameResolver frame_resolver_;
  Timeline timeline_;
  RecordBuilder builder_;
  std::unique_ptr<ExternalEffort> external_;  // external_effort/enabled
  std::vector<double> external_variance_;     // the model efforts' variances, per joint
  JointStateMap joints_;
  LoadsRecord record_;
  // A smoother's loads made before a reset or a retune (takeDrained), and the next one.
  std::vector<LoadsRecord> drained_;
  std::size_t drained_next_ = 0;
  std::unique_ptr<Stream> smoothed_;  // settings.smoothed.enabled
  bool smoothed_published_ = false;
  PipelineCounters counters_;
  std::vector<WrenchInput> wrenches_;
  std::vector<PlateInput> plates_;
  bool joints_stamped_ = false;
  std::string problem_, unknown_joint_, nonfinite_effort_, nonfinite_velocity_;
  std::string mimic_contradiction_;
  bool any_needed_ = false;  // the loads need at least one coordinate
  // Plausibility: per coordinate its joint's segment and range, the joint states refused
  // in a row for moving too fast, and the velocities with the implausible ones as NaN.
  std::vector<int> coordinate_segment_;
  std::vector<PlausibleRange> coordinate_range_;
  int implausible_run_ = 0;
  std::vector<double> velocity_checked_;
  Settle settle_;  // the immediate stream's
  Group group_;
  bool group_record_ = false;  // record_ holds a closed instant's loads (takeDrained)
  bool stashed_ = false, stashed_smoothed_ = false;  // by stashGroupRecords, this call
};

}  // namespace jle
