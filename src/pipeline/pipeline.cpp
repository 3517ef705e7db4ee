#include <joint_load_estimator/model/frames.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>
#include <joint_load_estimator/pipeline/plausibility.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

namespace jle {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool allFinite(const std::vector<double>& v, std::size_t& bad) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) {
      bad = i;
      return false;
    }
  return true;
}

// A stamp out of order, in the words of the estimator's refusals.
SampleStatus sampleStatus(StampVerdict order) {
  return order == StampVerdict::kDuplicate ? SampleStatus::kDuplicate : SampleStatus::kOutOfOrder;
}

const char* const kZeroStamp = ": stamp 0 on a stream that has had stamps: dropped";

}  // namespace

const char* toString(Outcome outcome) {
  switch (outcome) {
    case Outcome::kUsed: return "used";
    case Outcome::kPublished: return "published";
    case Outcome::kMerged: return "merged";
    case Outcome::kInvalid: return "invalid";
    case Outcome::kOrder: return "stamp order";
    case Outcome::kFrame: return "unresolved frame";
    case Outcome::kNoBasePose: return "no base pose";
    case Outcome::kWaiting: return "waiting for a joint";
    case Outcome::kStale: return "stale input";
    case Outcome::kUnchanged: return "unchanged";
    case Outcome::kNoJoint: return "no needed joint";
    case Outcome::kRogueStamp: return "rogue stamp";
    case Outcome::kImplausible: return "implausible";
    case Outcome::kNonFinite: return "non-finite loads";
    case Outcome::kCount: break;
  }
  return "?";
}

std::size_t problemKey(const std::string& problem) {
  // Numbers (stamps, values, counts) do not make another problem; names do, with their
  // digits: '/ft2' is not '/ft'. A digit belongs to a name when it follows a letter,
  // '_' or a digit of that name.
  std::size_t h = 1469598103934665603ull;
  bool in_name = false;
  for (char c : problem) {
    const bool digit = c >= '0' && c <= '9';
    in_name = std::isalpha(static_cast<unsigned char>(c)) || c == '_' || (digit && in_name);
    if (!digit || in_name) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  }
  return h;
}

long PipelineCounters::received(InputKind kind) const {
  long n = 0;
  for (long c : outcomes[static_cast<int>(kind)]) n += c;
  return n;
}

long PipelineCounters::count(Outcome outcome) const {
  long n = 0;
  for (const auto& kind : outcomes) n += kind[static_cast<int>(outcome)];
  return n;
}

ModelOptions modelOptions(const Settings& settings) {
  ModelOptions options;
  options.floating_base = settings.floating_base;
  options.keep_fixed_joints = settings.keep_fixed_joints;
  options.accept_nonphysical_inertia = settings.accept_nonphysical_inertia;
  for (const WrenchInputConfig& input : settings.estimator.wrenches)
    if (!input.sensor_joint.empty() &&
        std::find(options.keep_fixed_joints.begin(), options.keep_fixed_joints.end(),
                  input.sensor_joint) == options.keep_fixed_joints.end())
      options.keep_fixed_joints.push_back(input.sensor_joint);
  return options;
}

namespace {

// The link of every force/torque sensor input (sensor_joint set, link empty) is its
// joint's child link. Joints the model does not keep are left for the Estimator to
// refuse by name.
Settings checkedSettings(const Model<double>& model, Settings settings) {
  validate(settings);
  for (WrenchInputConfig& input : settings.estimator.wrenches) {
    if (input.sensor_joint.empty() || !input.link.empty()) continue;
    for (int s = 1; s < model.nsegments(); ++s)
      if (model.joint_name[static_cast<std::size_t>(s)] == input.sensor_joint)
        input.link = model.link_name[static_cast<std::size_t>(s)];
  }
  if (model.floating_base && settings.base_frame.empty()) settings.base_frame = model.link_name[0];
  return settings;
}

}  // namespace

Pipeline::Pipeline(const Model<double>& model, const Settings& settings, FrameSource* frames)
    : settings_(checkedSettings(model, settings)),
      estimator_(model, settings_.estimator),
      frame_resolver_(estimator_.model(), settings_, frames),
      timeline_(settings_),
      builder_(estimator_.model(), settings_, frame_resolver_, timeline_),
      joints_(estimator_.model(), publishedSegments(estimator_.model(), settings_.estimator.joints),
              settings_.plausibility.mimic_tolerance),
      record_(builder_.sizedRecord()),
      wrenches_(settings_.estimator.wrenches.size()),
      plates_(settings_.estimator.plates.size()) {
  const Model<double>& m = estimator_.model();
  coordinate_segment_ = coordinateSegments(m);
  for (int s : coordinate_segment_)
    coordinate_range_.push_back(
        plausibleRange(m, settings_.plausibility, static_cast<std::size_t>(s)));
  for (int i = 0; i < m.nq; ++i)
    any_needed_ = any_needed_ || estimator_.layout().coordinateNeeded(i);
  if (settings_.smoothed.enabled) {
    smoothed_ = std::make_unique<Stream>(model, smoothedEstimatorConfig(settings_));
    smoothed_->record = record_;  // sized; no external outputs
  }
  if (settings_.external_effort.enabled) setUpExternal();
}

void Pipeline::setUpExternal() {
  const std::size_t n = record_.segment.size();
  external_ = std::make_unique<ExternalEffort>(
      estimator_.model(), settings_.external_effort, record_.segment,
      settings_.estimator.gravity_world,
      settings_.friction.enabled ? settings_.friction.velocity_scale : 0.0,
      settings_.estimator.uncertainty.enabled);
  record_.external_effort.assign(n, kNaN);
  if (settings_.estimator.uncertainty.enabled) record_.external_effort_stddev.assign(n, 0.0);
  record_.contacts = external_->contacts();
  external_variance_.assign(n, 0.0);
}

void Pipeline::fillExternal() {
  const bool uncertainty = settings_.estimator.uncertainty.enabled;
  if (uncertainty)
    for (std::size_t i = 0; i < external_variance_.size(); ++i)
      external_variance_[i] = record_.effort_stddev[i] * record_.effort_stddev[i];
  const Estimator::LastSample last = estimator_.last();
  BaseState<double> base;
  if (model().floating_base) {
    base.R_world_base = last.data().R_world[0];
    base.p_world_base = last.data().p_world[0];
  }
  external_->update(last.stamp(), last.q(), last.qd(), base, record_.effort,
                    record_.measured_effort, uncertainty ? &external_variance_ : nullptr);
  record_.external_effort = external_->external();
  if (uncertainty) record_.external_effort_stddev = external_->stddev();
  record_.contacts = external_->contacts();
  record_.in_contact = external_->inContact();
  record_.contact_started = external_->contactStarted();
  record_.contact_ended = external_->contactEnded();
  record_.contact_changed = external_->contactChanged();
  record_.contact_joint = external_->contactJoint();
  record_.contact_link = external_->contactLink();
}

std::string Pipeline::smoothedBandwidthBound() const {
  if (!smoothed_) return "";
  const Estimator& e = smoothed_->estimator;
  const double chosen = e.filters().spectralCutoff(), used = e.filters().bandwidth();
  if (!(chosen > 0.0)) return "";
  char text[200];
  if (!(e.filters().noiseFloor() > 0.0)) {
    std::snprintf(text, sizeof text,
                  "the positions' spectrum shows no noise floor: the highest bandwidth, %.3g Hz",
                  used);
    return text;
  }
  if (!(used > 1.001 * chosen)) return "";
  std::snprintf(text, sizeof text,
                "the positions' spectrum chooses %.3g Hz, below the lag's floor %.3g Hz "
                "(%.3g / lag): the smoother is wider than the data ask; a longer lag allows less",
                chosen, used, DifferentiatorBank::kLagFloor);
  return text;
}

Outcome Pipeline::count(InputKind kind, Outcome outcome) {
  ++counters_.outcomes[static_cast<int>(kind)][static_cast<int>(outcome)];
  return outcome;
}

Outcome Pipeline::fail(InputKind kind, Outcome outcome, const std::string& why) {
  problem_ = why;
  return count(kind, outcome);
}

Outcome Pipeline::stampOutcome(InputKind kind, StampVerdict verdict) {
  if (verdict == StampVerdict::kRogue) return count(kind, Outcome::kRogueStamp);
  if (verdict == StampVerdict::kJump) resetTimeline();
  return Outcome::kUsed;
}

void Pipeline::resetTimeline() {
  // A looping bag (rosbag play -l), a restarted simulation, a driver's clock set: the
  // filters' memory belongs to another timeline, and so does the time axis. An instant
  // still waiting for a publisher is taken first, on its own timeline.
  if (group_.open) {
    closeGroup();
    stashGroupRecords();
    stashed_ = stashed_smoothed_ = false;
  }
  builder_.clearHeld();
  drainSmoother();
  estimator_.reset();
  if (smoothed_) smoothed_->estimator.reset();
  settle_.restarted = true;
  if (smoothed_) smoothed_->settle.restarted = true;
  implausible_run_ = 0;
  if (external_) external_->reset();
  builder_.forget();
  timeline_.restart();
  ++counters_.resets;
  if (timeline_.jumpedForward()) ++counters_.forward_jumps;
}

bool Pipeline::checkJointState(const std::vector<std::string>& names,
                               const std::vector<double>& position,
                               const std::vector<double>& velocity,
                               const std::vector<double>& effort) {
  const std::string& topic = settings_.joint_states_topic;
  const std::size_t n = names.size();
  struct Field {
    const char *name, *plural;
    const std::vector<double>& values;
  };
  const Field fields[] = {{"position", "positions", position},
                          {"velocity", "velocities", velocity},
                          {"effort", "efforts", effort}};
  for (const Field& field : fields) {
    const std::size_t size = field.values.size();
    if (size != n && (size != 0 || &field.values == &position)) {
      problem_ = topic + ": " + std::to_string(n) + " names but " + std::to_string(size) + " " +
                 field.plural + ": message dropped";
      return false;
    }
  }
  // A non-finite velocity or effort costs only that value (mapJointState counts it).
  std::size_t bad = 0;
  if (!allFinite(position, bad)) {
    problem_ = topic + ": position of joint '" + names[bad] + "' is " +
               std::to_string(position[bad]) + ": message dropped";
    return false;
  }
  const int twice = joints_.bind(names);
  if (twice >= 0) {
    problem_ = topic + ": joint '" + names[static_cast<std::size_t>(twice)] +
               "' is named twice: message dropped";
    return false;
  }
  return true;
}

bool Pipeline::movesNeeded() const {
  if (!any_needed_) return true;  // a floating base alone: every message is a sample
  for (int k : joints_.coordinates())
    if (k >= 0 && estimator_.layout().coordinateNeeded(k)) return true;
  return false;
}

void Pipeline::mapJointState(const std::vector<std::string>& names,
                             const std::vector<double>& position,
                             const std::vector<double>& velocity,
                             const std::vector<double>& effort) {
  const int unknown = joints_.update(position, velocity, effort);  // names bound by checkJointState
  std::size_t bad = 0;
  if (!allFinite(effort, bad)) {
    nonfinite_effort_ = names[bad];
    ++counters_.nonfinite_efforts;
  }
  if (!allFinite(velocity, bad)) {
    nonfinite_velocity_ = names[bad];
    ++counters_.nonfinite_velocities;
  }
  mimic_contradiction_.clear();
  if (joints_.mimicContradiction() >= 0) {
    const std::size_t i = static_cast<std::size_t>(joints_.mimicContradiction());
    char text[160];
    std::snprintf(text, sizeof text,
                  "' is %.6g, but its leader makes it %.6g (URDF <mimic>): ", position[i],
                  joints_.mimicExpected());
    mimic_contradiction_ = "mimic joint '" + names[i] + text + "the model's value is used";
    ++counters_.mimic_contradictions;
  }
  if (unknown < 0) {
    unknown_joint_.clear();
    return;
  }
  unknown_joint_ = names[static_cast<std::size_t>(unknown)];
  ++counters_.unknown_joints;
}

Outcome Pipeline::onJointState(Stamp stamp, Stamp clock, const std::vector<std::string>& names,
                               const std::vector<double>& position,
                               const std::vector<double>& velocity,
                               const std::vector<double>& effort) {
  constexpr InputKind kind = InputKind::kJointState;
  problem_.clear();
  smoothed_published_ = group_record_ = stashed_ = stashed_smoothed_ = false;
  unknown_joint_.clear();
  nonfinite_effort_.clear();
  nonfinite_velocity_.clear();
  mimic_contradiction_.clear();
  if (!checkJointState(names, position, velocity, effort)) return count(kind, Outcome::kInvalid);
  timeline_.clearJump();
  // Neither a sample nor a time: its stamp and clock are not the stream's.
  if (!movesNeeded()) {
    mapJointState(names, position, velocity, effort);
    return fail(kind, Outcome::kNoJoint,
                settings_.joint_states_topic +
                    ": a message with none of the joints the loads need: not a sample");
  }
  if (!Timeline::zeroStamp(joints_stamped_, stamp, clock))
    return fail(kind, Outcome::kRogueStamp, settings_.joint_states_topic + kZeroStamp);
  const Outcome timeline = stampOutcome(
      kind, timeline_.checkJointStamp(stamp, clock, settings_.joint_states_topic, problem_));
  if (timeline != Outcome::kUsed) return timeline;
  // The order before anything is stored: a message of an instant already taken, or older
  // than the one being assembled, is dropped whole.
  const bool joins = joinsGroup(stamp);
  const Stamp assembling = group_.open && !joins ? group_.newest : Stamp{0};
  const StampVerdict order = timeline_.order(stamp, assembling);
  if (order != StampVerdict::kOnTime)
    return fail(kind, Outcome::kOrder,
                settings_.joint_states_topic + ": " + toString(sampleStatus(order)) + " " +
                    secondsText(stamp) + " (previous " +
                    secondsText(std::max(timeline_.lastStamp(), assembling)) +
                    "): message dropped");
  if (!plausibleJointState(stamp, names, position)) return count(kind, Outcome::kImplausible);
  if (group_.open && !joins) closeGroup();  // a later instant: the open one is complete as is
  mapJointState(names, position, plausibleVelocities(velocity), effort);
  timeline_.anchor(stamp);
  group_.oldest = group_.open ? std::min(group_.oldest, stamp) : stamp;
  group_.newest = group_.open ? std::max(group_.newest, stamp) : stamp;
  group_.has_effort = (group_.open && group_.has_effort) || !effort.empty();
  group_.open = true;
  group_.last_merged = false;
  const std::string& missing = missingJoint();
  if (!missing.empty())
    return fail(kind, Outcome::kWaiting,
                settings_.joint_states_topic + ": no position received yet for joint '" + missing +
                    "': not publishing");
  if (!groupComplete()) {
    group_.last_merged = true;
    return count(kind, Outcome::kMerged);
  }
  const bool stashed = stashGroupRecords();
  const Outcome outcome = takeGroup();
  if (stashed) unstash(outcome == Outcome::kPublished);
  return outcome;
}

bool Pipeline::joinsGroup(Stamp stamp) const {
  // One instant: within the window, and no needed joint twice (that is the next instant
  // of its publisher).
  if (!group_.open) return false;
  const double span =
      1e-9 * static_cast<double>(std::max(group_.newest, stamp) - std::min(group_.oldest, stamp));
  if (span > settings_.stamps.merge_window) return false;
  for (int k : joints_.coordinates())
    if (k >= 0 && estimator_.layout().coordinateNeeded(k) && joints_.fresh(k)) return false;
  return true;
}

bool Pipeline::groupComplete() const {
  for (int k = 0; k < model().nq; ++k)
    if (estimator_.layout().coordinateNeeded(k) && !joints_.fresh(k)) return false;
  return true;
}

Outcome Pipeline::takeGroup() {
  // Stamped with the newest of its messages: every position in the sample is known then,
  // so a later instant's stamp is after it and a front end that publishes at once never
  // stamps the past; the oldest message's joints are up to merge_window old in it.
  group_.open = false;
  BasePose base;
  if (model().floating_base && !basePose(group_.newest, base)) {
    joints_.clearFresh();
    return count(InputKind::kJointState, Outcome::kNoBasePose);
  }
  const Outcome outcome = sample(group_.newest, group_.has_effort, &base);
  joints_.clearFresh();  // also where the estimator refused the sample: the next instant's own
  return outcome;
}

void Pipeline::closeGroup() {
  // An instant that a later one closes before every publisher spoke. While a joint has
  // never been received it is forgotten (its last message was counted waiting); else it
  // is taken with the missing joints held (counted, the records flagged kHeldJoint), and
  // its last message is counted under the sample's outcome instead of kMerged.
  if (!group_.open) return;
  if (!group_.last_merged) {
    group_.open = false;
    joints_.clearFresh();
    return;
  }
  --counters_
        .outcomes[static_cast<int>(InputKind::kJointState)][static_cast<int>(Outcome::kMerged)];
  if (takeGroup() == Outcome::kPublished) group_record_ = true;
}

bool Pipeline::stashGroupRecords() {
  // Rare (a message completing a sample right after it closed another, a reset, the end
  // of a stream): copies of the records are fine here.
  if (group_record_) {
    drained_.push_back(record_);
    group_record_ = false;
    stashed_ = true;
  }
  if (smoothed_published_) {
    smoothed_->drained.push_back(smoothed_->record);
    smoothed_published_ = false;
    stashed_smoothed_ = true;
  }
  return stashed_ || stashed_smoothed_;
}

void Pipeline::unstash(bool immediate_published) {
  // The closed instant's loads first (record() and smoothedRecord(), as the front end
  // publishes them), the message's own next (takeDrained).
  if (stashed_ && immediate_published) std::swap(record_, drained_.back());
  if (stashed_smoothed_ && smoothed_published_)
    std::swap(smoothed_->record, smoothed_->drained.back());
  else if (stashed_smoothed_ && !smoothed_published_) {
    // Its own made none: the closed one's is the call's smoothed record again.
    std::swap(smoothed_->record, smoothed_->drained.back());
    smoothed_->drained.pop_back();
    smoothed_published_ = true;
  }
  stashed_ = stashed_smoothed_ = false;
}

bool Pipeline::basePose(Stamp stamp, BasePose& base) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  if (!frame_resolver_.basePose(stamp, X, problem_)) return false;
  base.position = X.translation();
  base.orientation = Eigen::Quaterniond(X.rotation());
  return true;
}

Outcome Pipeline::sample(Stamp stamp, bool has_effort, const BasePose* base) {
  constexpr InputKind kind = InputKind::kJointState;
  const auto order = [&](SampleStatus status) {
    return fail(kind, Outcome::kOrder,
                settings_.joint_states_topic + ": " + toString(status) + " " + secondsText(stamp) +
                    " (previous " + secondsText(timeline_.lastStamp()) + "): message dropped");
  };
  // The order of the stamps, not of the instants (which the sample clock makes increase).
  const StampVerdict in_order = timeline_.order(stamp);
  if (in_order != StampVerdict::kOnTime) return order(sampleStatus(in_order));
  const double t = timeline_.sampleTime(stamp);
  const SampleStatus status =
      estimator_.addJointSample(t, joints_.q().data(), base, joints_.qd().data());
  noteStart(settle_, status, t);
  switch (status) {
    case SampleStatus::kDuplicate:
    case SampleStatus::kOutOfOrder: return order(status);
    case SampleStatus::kNonFinite:
      return fail(kind, Outcome::kInvalid,
                  settings_.joint_states_topic + ": non-finite stamp or base pose: dropped");
    default: break;
  }
  timeline_.taken(stamp);
  remember(t, stamp, has_effort);
  countHeld(t);
  if (smoothed_) sampleSmoothed(t, base);
  if (status == SampleStatus::kStale) return staleProblem();
  if (status != SampleStatus::kPublished) return count(kind, Outcome::kUsed);
  if (estimator_.last().reused() && !settings_.estimator.savings.republish_unchanged)
    return count(kind, Outcome::kUnchanged);
  if (!fillRecord(estimator_, record_)) {
    restartFilters(false);  // what made them not finite is in the filters' state
    return fail(kind, Outcome::kNonFinite,
                settings_.joint_states_topic + ": the loads at " + secondsText(stamp) +
                    " are not finite: not published, the filters restart");
  }
  return count(kind, Outcome::kPublished);
}

// The sample the immediate stream took, into the smoothed stream (the same checks passed:
// the same time, positions, velocities and base pose).
void Pipeline::sampleSmoothed(double t, const BasePose* base) {
  Stream& stream = *smoothed_;
  Estimator& e = stream.estimator;
  const SampleStatus status = e.addJointSample(t, joints_.q().data(), base, joints_.qd().data());
  noteStart(stream.settle, status, t);
  smoothed_published_ = status == SampleStatus::kPublished &&
                        !(e.last().reused() && !settings_.estimator.savings.republish_unchanged);
  if (smoothed_published_ && !fillRecord(e, stream.record)) {  // counted by the immediate stream
    e.reset();
    stream.settle.restarted = true;
    smoothed_published_ = false;
  }
}

void Pipeline::drainSmoother() {
  // Rare (a reset with a smoother): copies of the record are fine here.
  if (estimator_.filters().pendingSamples() > 0)
    while (nextRecord(estimator_, record_, true)) drained_.push_back(record_);
  if (smoothed_ && smoothed_->estimator.filters().pendingSamples() > 0)
    while (nextRecord(smoothed_->estimator, smoothed_->record, true))
      smoothed_->drained.push_back(smoothed_->record);
}

bool Pipeline::takeFrom(LoadsRecord& record, std::vector<LoadsRecord>& drained, std::size_t& next) {
  if (next == drained.size()) return false;
  std::swap(record, drained[next++]);
  if (next == drained.size()) {
    drained.clear();
    next = 0;
  }
  return true;
}

bool Pipeline::takeDrained() {
  if (group_record_) {  // record_ holds the loads of an instant this call closed
    group_record_ = false;
    return true;
  }
  return takeFrom(record_, drained_, drained_next_) || nextRecord(estimator_, record_, false);
}

bool Pipeline::takeDrainedSmoothed() {
  if (!smoothed_) return false;
  Stream& s = *smoothed_;
  return takeFrom(s.record, s.drained, s.drained_next) || nextRecord(s.estimator, s.record, false);
}

bool Pipeline::flush() {
  if (group_.open) {  // the last instant, complete as it is
    smoothed_published_ = group_record_ = false;
    closeGroup();
    stashGroupRecords();
    stashed_ = stashed_smoothed_ = false;
  }
  return takeFrom(record_, drained_, drained_next_) || nextRecord(estimator_, record_, true);
}

bool Pipeline::flushSmoothed() {
  if (!smoothed_) return false;
  Stream& s = *smoothed_;
  return takeFrom(s.record, s.drained, s.drained_next) || nextRecord(s.estimator, s.record, true);
}

bool Pipeline::nextRecord(Estimator& estimator, LoadsRecord& record, bool end) {
  SampleStatus status = SampleStatus::kPublished;
  while (end ? estimator.flush(status) : estimator.takeDue(status)) {
    if (status != SampleStatus::kPublished) continue;
    if (estimator.last().reused() && !settings_.estimator.savings.republish_unchanged) continue;
    if (!fillRecord(estimator, record)) continue;  // never published
    return true;
  }
  return false;
}

std::string Pipeline::staleInputs() const {
  std::string stale;
  for (std::size_t k = 0; k < wrenches_.size(); ++k)
    if (estimator_.last().stale(static_cast<int>(k)))
      stale += (stale.empty() ? "" : ", ") + settings_.wrenches[k].topic;
  for (std::size_t k = 0; k < plates_.size(); ++k)
    if (estimator_.last().plateStale(static_cast<int>(k)))
      stale += (stale.empty() ? "" : ", ") + settings_.force_plates[k].topic;
  return stale;
}

std::string Pipeline::stoppingInputs() const {
  // Only the inputs with the stop policy stop the loads; a stale hold or zero input
  // does not.
  std::string stale;
  const EstimatorConfig& c = settings_.estimator;
  for (std::size_t k = 0; k < wrenches_.size(); ++k)
    if (estimator_.last().stale(static_cast<int>(k)) &&
        c.wrenches[k].stale_policy == StalePolicy::kStop)
      stale += (stale.empty() ? "" : ", ") + settings_.wrenches[k].topic;
  for (std::size_t k = 0; k < plates_.size(); ++k)
    if (estimator_.last().plateStale(static_cast<int>(k)) &&
        c.plates[k].stale_policy == StalePolicy::kStop)
      stale += (stale.empty() ? "" : ", ") + settings_.force_plates[k].topic;
  return stale;
}

const std::string& Pipeline::missingJoint() const {
  static const std::string kNoJointMissing;
  for (int i = 0; i < model().nq; ++i)
    if (!joints_.received(i) && estimator_.layout().coordinateNeeded(i))
      return model().coordinate_names[static_cast<std::size_t>(i)];
  return kNoJointMissing;
}

Outcome Pipeline::staleProblem() {
  return fail(InputKind::kJointState, Outcome::kStale,
              "stale inputs (stale_policy stop): " + stoppingInputs() + ": not publishing");
}

void Pipeline::remember(double t, Stamp stamp, bool has_effort) {
  // The estimates still to come are of the newest sample and the delaySamples() before
  // it (a smoother's pending samples, its carry over a gap included), in either stream.
  const int delay = std::max(estimator_.filters().delaySamples(),
                             smoothed_ ? smoothed_->estimator.filters().delaySamples() : 0);
  builder_.remember(t, stamp, has_effort ? &joints_.effort() : nullptr, delay);
}

bool Pipeline::fillRecord(const Estimator& estimator, LoadsRecord& rec) {
  const Settle& settle = &estimator == &estimator_ ? settle_ : smoothed_->settle;
  const bool finite = builder_.fill(estimator, settle.from, rec);
  if (external_ && &rec == &record_) fillExternal();
  return finite;
}

void Pipeline::countHeld(double t) {
  // A needed coordinate no message since the last sample set: this sample holds it.
  bool held = false;
  for (int k = 0; k < model().nq && !held; ++k)
    held = estimator_.layout().coordinateNeeded(k) && !joints_.fresh(k);
  if (held) {
    ++counters_.held_samples;
    builder_.heldAt(t);
  }
  joints_.clearFresh();
}

void Pipeline::noteStart(Settle& settle, SampleStatus status, double t) {
  if (status == SampleStatus::kDuplicate || status == SampleStatus::kOutOfOrder ||
      status == SampleStatus::kNonFinite)
    return;  // not taken
  // The settling time counts from the filters' first sample, not from their first
  // estimate: the warm-up (or the smoother's lag) is part of it.
  const bool warming = status == SampleStatus::kWarmingUp;
  if (settle.restarted || (warming && !settle.warming)) settle.from = t;
  settle.restarted = false;
  settle.warming = warming;
}

void Pipeline::restartFilters(bool drain) {
  // The wrench and plate readings are forgotten too (Estimator::reset): the next ones
  // refill them.
  if (drain) drainSmoother();
  estimator_.reset();
  if (smoothed_) smoothed_->estimator.reset();
  settle_.restarted = true;
  if (smoothed_) smoothed_->settle.restarted = true;
  builder_.forget();  // the samples the filters held; the stamps' order stays
}

bool Pipeline::plausibleWrench(InputKind kind, const std::string& input,
                               const Eigen::Vector3d& force, const Eigen::Vector3d& moment) {
  (void)kind;
  const PlausibilityConfig& p = settings_.plausibility;
  // stableNorm: the norm of (0, 0, 1e300) is 1e300, not the inf of its square's root.
  const double f = force.stableNorm(), m = moment.stableNorm();
  if (f <= p.max_force && m <= p.max_moment) return true;
  char text[160];
  std::snprintf(text, sizeof text,
                ": |force| %.6g N, |moment| %.6g N m beyond plausibility/max_force %.6g N or "
                "max_moment %.6g N m: dropped",
                f, m, p.max_force, p.max_moment);
  problem_ = input + text;
  return false;
}

bool Pipeline::plausibleJointState(Stamp stamp, const std::vector<std::string>& names,
                                   const std::vector<double>& position) {
  const PlausibilityConfig& p = settings_.plausibility;
  const Model<double>& m = model();
  const std::vector<int>& coordinate = joints_.coordinates();  // bound by checkJointState
  const Stamp last = timeline_.lastStamp();
  const double dt = last != 0 ? 1e-9 * static_cast<double>(stamp - last) : -1.0;
  bool too_fast = false;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const int c = coordinate[i];
    if (c < 0) continue;
    const PlausibleRange& range = coordinate_range_[static_cast<std::size_t>(c)];
    const std::size_t s =
        static_cast<std::size_t>(coordinate_segment_[static_cast<std::size_t>(c)]);
    if (!plausiblePosition(range, position[i])) {
      problem_ = settings_.joint_states_topic + ": " + positionProblem(m, p, s, position[i]) +
                 ": message dropped";
      return false;
    }
    if (dt <= 0.0 || !joints_.received(c) || too_fast) continue;
    const double step = position[i] - joints_.q()[static_cast<std::size_t>(c)];
    if (plausibleStep(range, p, step, dt)) continue;
    too_fast = true;
    problem_ =
        settings_.joint_states_topic + ": " + stepProblem(m, p, s, step, dt) + ": message dropped";
  }
  if (!too_fast) {
    implausible_run_ = 0;
    return true;
  }
  // The same jump in jump_confirm joint states in a row is the joint's own: taken, the
  // filters restart from it.
  if (++implausible_run_ < settings_.stamps.jump_confirm) return false;
  implausible_run_ = 0;
  problem_.clear();
  restartFilters(true);  // the samples before the jump are good
  return true;
}

const std::vector<double>& Pipeline::plausibleVelocities(const std::vector<double>& velocity) {
  const std::vector<int>& coordinate = joints_.coordinates();
  bool any = false;
  for (std::size_t i = 0; i < velocity.size() && i < coordinate.size(); ++i) {
    if (coordinate[i] < 0 || !std::isfinite(velocity[i])) continue;
    const PlausibleRange& range = coordinate_range_[static_cast<std::size_t>(coordinate[i])];
    if (!implausibleVelocity(range, velocity[i])) continue;
    if (!any) velocity_checked_ = velocity;  // same size after the first: no allocation
    velocity_checked_[i] = kNaN;             // counted and named as a non-finite one
    any = true;
  }
  return any ? velocity_checked_ : velocity;
}

bool Pipeline::retune(const DifferentiatorConfig& differentiator, int decimation) {
  // A new differentiator restarts the filters: a smoother's pending loads come first.
  EstimatorConfig next = estimator_.config();
  next.differentiator = differentiator;
  next.decimation = decimation;
  validate(next);  // throws naming the key, changing nothing
  if (!sameDifferentiator(differentiator, estimator_.config().differentiator)) drainSmoother();
  const bool kept = estimator_.retune(differentiator, decimation);
  if (smoothed_)  // its own filter kept; the decimation is the node's
    smoothed_->estimator.retune(smoothed_->estimator.config().differentiator, decimation);
  settings_.estimator.differentiator = differentiator;
  settings_.estimator.decimation = decimation;
  return kept;
}

void Pipeline::setSensorBias(int k, const Eigen::Vector3d& force, const Eigen::Vector3d& torque) {
  wrenches_.at(ix(k)).bias_force = force;
  wrenches_[ix(k)].bias_torque = torque;
}

Outcome Pipeline::admitReading(InputKind kind, const std::string& what, bool has_frame,
                               bool& stamped, Stamp& stamp, Stamp clock, double timeout,
                               const Eigen::Vector3d& force, const Eigen::Vector3d& moment) {
  if (!force.allFinite() || !moment.allFinite())
    return fail(kind, Outcome::kInvalid, what + ": non-finite force or torque: dropped");
  if (!has_frame)
    return fail(kind, Outcome::kFrame,
                what + ": empty header.frame_id and no 'frame' configured: dropped");
  timeline_.clearJump();
  if (!Timeline::zeroStamp(stamped, stamp, clock))
    return fail(kind, Outcome::kRogueStamp, what + kZeroStamp);
  // The stamps first, as for a joint state: the clock is followed whatever the values.
  const Outcome timeline =
      stampOutcome(kind, timeline_.checkInputStamp(stamp, clock, timeout, what, problem_));
  if (timeline != Outcome::kUsed) return timeline;
  if (!plausibleWrench(kind, what, force, moment)) return count(kind, Outcome::kImplausible);
  return Outcome::kUsed;
}

Outcome Pipeline::notNewer(InputKind kind, const std::string& what, Stamp stamp) {
  return fail(kind, Outcome::kOrder,
              what + ": stamp " + secondsText(stamp) + " not newer than the last: dropped");
}

Outcome Pipeline::onWrench(int k, Stamp stamp, Stamp clock, const std::string& frame_id,
                           const Eigen::Vector3d& force, const Eigen::Vector3d& torque) {
  constexpr InputKind kind = InputKind::kWrench;
  problem_.clear();
  smoothed_published_ = group_record_ = false;
  const std::string what = "wrench '" + settings_.wrenches.at(ix(k)).topic + "'";
  const std::string& configured = settings_.wrenches[ix(k)].frame;
  const std::string& frame = configured.empty() ? frame_id : configured;
  const Outcome admitted =
      admitReading(kind, what, !frame.empty(), wrenches_[ix(k)].stamped, stamp, clock,
                   settings_.estimator.wrenches[ix(k)].timeout, force, torque);
  if (admitted != Outcome::kUsed) return admitted;
  if (!frame_resolver_.resolveWrench(k, frame, stamp, problem_))
    return count(kind, Outcome::kFrame);
  const WrenchInput& input = wrenches_[ix(k)];
  // The sensor's offset is in its own frame and sign: removed before anything else.
  const Eigen::Vector3d f = force - input.bias_force, m = torque - input.bias_torque;
  const Eigen::Isometry3d& X = frame_resolver_.wrenchPose(k);
  Eigen::Vector3d f_link, m_link;
  wrenchInLink(X.linear(), X.translation(), f, m, f_link, m_link);
  const double t = timeline_.relative(stamp);
  if (smoothed_) smoothed_->estimator.addWrench(k, t, f_link, m_link);  // the same order
  if (!estimator_.addWrench(k, t, f_link, m_link)) return notNewer(kind, what, stamp);
  return count(kind, Outcome::kUsed);
}

bool Pipeline::resolvePlatePose(int k, const std::string& frame) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  switch (frame_resolver_.resolvePlate(k, frame, X, problem_)) {
    case FrameResolver::PlatePose::kKnown: return true;
    case FrameResolver::PlatePose::kFound:  // a lab plate is fixed: set once
      estimator_.setPlatePose(k, X.rotation(), X.translation());
      if (smoothed_) smoothed_->estimator.setPlatePose(k, X.rotation(), X.translation());
      return true;
    case FrameResolver::PlatePose::kUnknown: break;
  }
  return false;
}

Outcome Pipeline::onPlate(int k, Stamp stamp, Stamp clock, const std::string& frame_id,
                          const Eigen::Vector3d& force, const Eigen::Vector3d& moment) {
  constexpr InputKind kind = InputKind::kPlate;
  problem_.clear();
  smoothed_published_ = group_record_ = false;
  const std::string what = "force plate '" + settings_.estimator.plates.at(ix(k)).plate.name + "'";
  const PlateTopicSettings& configured = settings_.force_plates[ix(k)];
  const std::string& frame = configured.frame.empty() ? frame_id : configured.frame;
  const Outcome admitted =
      admitReading(kind, what, !frame.empty() || configured.pose_configured, plates_[ix(k)].stamped,
                   stamp, clock, settings_.estimator.plates[ix(k)].timeout, force, moment);
  if (admitted != Outcome::kUsed) return admitted;
  if (!resolvePlatePose(k, frame)) return count(kind, Outcome::kFrame);
  const double t = timeline_.relative(stamp);
  if (smoothed_) smoothed_->estimator.addPlateSample(k, t, force, moment);  // the same order
  if (!estimator_.addPlateSample(k, t, force, moment)) return notNewer(kind, what, stamp);
  return count(kind, Outcome::kUsed);
}

}  // namespace jle
