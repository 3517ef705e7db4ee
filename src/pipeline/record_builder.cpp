#include <joint_load_estimator/estimation/sensor_bias.hpp>
#include <joint_load_estimator/model/friction.hpp>
#include <joint_load_estimator/pipeline/plausibility.hpp>
#include <joint_load_estimator/pipeline/record_builder.hpp>

#include <cmath>
#include <limits>
#include <utility>

namespace jle {
namespace {

// Joint samples remembered (to publish a delayed estimate with its own stamp): more than
// any Savitzky-Golay delay; a smoother grows the ring to its own (remember()).
constexpr std::size_t kRing = 128;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

std::vector<int> publishedSegments(const Model<double>& model,
                                   const std::vector<std::string>& joints) {
  if (joints.empty()) return model.moving_segments;
  std::vector<int> segments;
  for (const std::string& j : joints) {
    int segment = -1;
    for (int s = 1; s < model.nsegments(); ++s) {
      const JointType type = model.joint_type[static_cast<std::size_t>(s)];
      if (model.joint_name[static_cast<std::size_t>(s)] == j &&
          (isMoving(type) || type == JointType::kFixed))
        segment = s;
    }
    if (segment < 0)
      throw SettingsError("parameter 'joints': '" + j + "' is not a joint of the model");
    segments.push_back(segment);
  }
  return segments;
}

std::string describeStatus(std::uint8_t status) {
  if (status == kTrusted) return "trusted";
  std::string words;
  const auto add = [&](std::uint8_t bit, const char* word) {
    if (status & bit) words += (words.empty() ? "" : ", ") + std::string(word);
  };
  add(kSettling, "settling");
  add(kStaleInput, "stale input");
  add(kImplausibleLoad, "implausible load");
  add(kHeldJoint, "held joint");
  return words;
}

RecordBuilder::RecordBuilder(const Model<double>& model, const Settings& settings,
                             const FrameResolver& frames, const Timeline& timeline)
    : model_(model),
      settings_(settings),
      frames_(frames),
      timeline_(timeline),
      segments_(publishedSegments(model, settings.estimator.joints)),
      ring_(kRing) {
  if (settings_.body_mass != 0.0) {
    body_mass_ = settings_.body_mass > 0.0 ? settings_.body_mass : model_.totalMass();
    if (!(body_mass_ > 0.0))
      throw SettingsError("parameter 'body_mass' is -1 but the URDF's total mass is " +
                          std::to_string(body_mass_) + " kg");
  }
  for (Sample& s : ring_) s.effort.assign(segments_.size(), kNaN);
}

LoadsRecord RecordBuilder::sizedRecord() const {
  LoadsRecord rec;
  rec.segment = segments_;
  const std::size_t n = segments_.size();
  for (int s : segments_) {
    rec.joint.push_back(model_.joint_name[static_cast<std::size_t>(s)]);
    rec.link.push_back(model_.link_name[static_cast<std::size_t>(s)]);
  }
  rec.force.assign(n, Eigen::Vector3d::Zero());
  rec.moment.assign(n, Eigen::Vector3d::Zero());
  rec.effort.assign(n, 0.0);
  rec.measured_effort.assign(n, kNaN);
  rec.position.assign(n, 0.0);
  rec.velocity.assign(n, 0.0);
  rec.acceleration.assign(n, 0.0);
  if (settings_.friction.enabled) rec.motor_effort.assign(n, 0.0);
  const UncertaintyConfig& u = settings_.estimator.uncertainty;
  if (u.enabled) {
    rec.effort_stddev.assign(n, 0.0);
    rec.covariance.assign((u.diagonal_only ? 6 : 36) * n, 0.0);
  }
  if (body_mass_ > 0.0) rec.effort_per_kg.assign(n, 0.0);
  rec.q.setZero(model_.nq);
  rec.qd.setZero(model_.nq);
  rec.qdd.setZero(model_.nq);
  const std::vector<WrenchInputConfig>& wrenches = settings_.estimator.wrenches;
  rec.inputs.resize(wrenches.size());
  for (std::size_t k = 0; k < wrenches.size(); ++k) rec.inputs[k].frame = wrenches[k].link;
  rec.plates.resize(settings_.estimator.plates.size());
  return rec;
}

void RecordBuilder::remember(double t, Stamp stamp, const std::vector<double>* effort, int delay) {
  // The estimates still to come are of the newest sample and the `delay` before it (a
  // smoother's pending samples, its carry over a gap included).
  const std::size_t needed = static_cast<std::size_t>(delay) + 1;
  if (needed > ring_.size()) growRing(2 * needed);
  Sample& s = ring_[ring_head_];
  s.t = t;
  s.stamp = stamp;
  s.has_effort = effort != nullptr;
  if (effort) s.effort = *effort;  // same size: no allocation
  ring_head_ = (ring_head_ + 1) % ring_.size();
  if (ring_count_ < ring_.size()) ++ring_count_;
}

void RecordBuilder::growRing(std::size_t size) {
  // Every slot's effort at its size now: none allocated when first used.
  std::vector<Sample> grown(size);
  for (Sample& slot : grown) slot.effort.assign(ring_.front().effort.size(), kNaN);
  for (std::size_t i = 0; i < ring_count_; ++i)  // oldest first
    grown[i] = std::move(ring_[(ring_head_ + ring_.size() - ring_count_ + i) % ring_.size()]);
  ring_head_ = ring_count_;
  ring_.swap(grown);
}

const RecordBuilder::Sample* RecordBuilder::sampleAt(double t) const {
  // The estimate's time is one of the samples' own times (the filter's delay is a whole
  // number of samples); half a nanosecond separates it from any other. The newest first
  // (the immediate stream's); the times increase from the oldest (the filters take samples
  // in order, and forget() goes with every restart): a bisection for a smoother's, a
  // hundred samples back; should that find none, every sample.
  if (ring_count_ == 0) return nullptr;
  const std::size_t size = ring_.size();
  const std::size_t first = (ring_head_ + size - ring_count_) % size;
  const auto oldest = [&](std::size_t i) -> const Sample& {
    return ring_[first + i < size ? first + i : first + i - size];
  };
  const auto at = [&](std::size_t i) { return std::abs(oldest(i).t - t) < 0.5e-9; };
  if (at(ring_count_ - 1)) return &oldest(ring_count_ - 1);
  std::size_t lo = 0, hi = ring_count_ - 1;
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    if (oldest(mid).t < t - 0.5e-9)
      lo = mid + 1;
    else
      hi = mid;
  }
  if (at(lo)) return &oldest(lo);
  for (std::size_t i = 0; i < ring_count_; ++i)
    if (at(i)) return &oldest(i);
  return nullptr;
}

Stamp RecordBuilder::stampAt(double t) const {
  const Sample* s = sampleAt(t);
  return s ? s->stamp : timeline_.absolute(t);
}

bool RecordBuilder::fill(const Estimator& estimator, double settle_from, LoadsRecord& rec) const {
  const Estimator::LastSample last = estimator.last();
  const Data<double>& data = last.data();
  const Sample* s = sampleAt(last.stamp());
  rec.stamp = s ? s->stamp : timeline_.absolute(last.stamp());
  const bool measured = s && s->has_effort;
  const UncertaintyConfig& u = settings_.estimator.uncertainty;
  const std::size_t per_joint = u.diagonal_only ? 6 : 36;
  for (std::size_t i = 0; i < rec.segment.size(); ++i) {
    const int segment = rec.segment[i];
    const std::size_t j = static_cast<std::size_t>(segment);
    rec.force[i] = data.force[j];
    rec.moment[i] = data.moment[j];
    rec.effort[i] = data.effort[j];
    rec.measured_effort[i] = measured ? s->effort[i] : kNaN;
    if (!rec.effort_per_kg.empty()) rec.effort_per_kg[i] = data.effort[j] / body_mass_;
    fillCoordinates(estimator, rec, i, j);
    if (!u.enabled) continue;
    const Eigen::Matrix<double, 6, 6>& C = last.covariance(segment);
    double* cov = &rec.covariance[per_joint * i];
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c)
        if (!u.diagonal_only)
          cov[6 * r + c] = C(r, c);
        else if (r == c)
          cov[r] = C(r, r);
    rec.effort_stddev[i] = std::sqrt(last.effortVariance(segment));
  }
  fillSideOutputs(estimator, rec);
  rec.status = status(estimator, settle_from, rec);
  return finiteLoads(rec);
}

bool RecordBuilder::finiteLoads(const LoadsRecord& rec) {
  // x - x is 0 for a finite x and NaN for an infinite or NaN one: one sum, no branch a
  // value.
  double zero = (rec.base_force - rec.base_force).sum() + (rec.base_moment - rec.base_moment).sum();
  for (std::size_t i = 0; i < rec.effort.size(); ++i)
    zero += (rec.effort[i] - rec.effort[i]) + (rec.force[i] - rec.force[i]).sum() +
            (rec.moment[i] - rec.moment[i]).sum();
  return zero == 0.0;
}

std::uint8_t RecordBuilder::status(const Estimator& estimator, double settle_from,
                                   const LoadsRecord& rec) const {
  const Estimator::LastSample last = estimator.last();
  const PlausibilityConfig& p = settings_.plausibility;
  std::uint8_t status = kTrusted;
  if (last.stamp() < settle_from + p.settle_time) status |= kSettling;
  if (std::abs(last.stamp() - held_t_) <= p.settle_time) status |= kHeldJoint;
  for (const InputRecord& in : rec.inputs) status |= in.stale ? kStaleInput : 0;
  for (std::size_t k = 0; k < rec.plates.size(); ++k)
    if (rec.plates[k].stale && estimator.layout().plateNeeded(static_cast<int>(k)))
      status |= kStaleInput;
  for (std::size_t i = 0; i < rec.segment.size(); ++i)
    if (implausibleEffort(model_, p, static_cast<std::size_t>(rec.segment[i]), rec.effort[i]))
      status |= kImplausibleLoad;
  return status;
}

void RecordBuilder::fillSideOutputs(const Estimator& estimator, LoadsRecord& rec) const {
  const Estimator::LastSample last = estimator.last();
  rec.q = last.q();  // same sizes: no allocation
  rec.qd = last.qd();
  rec.qdd = last.qdd();
  rec.planar = last.planar();
  for (std::size_t k = 0; k < rec.inputs.size(); ++k) {
    const int input = static_cast<int>(k);
    InputRecord& in = rec.inputs[k];
    in.stale = last.stale(input);
    in.used = estimator.layout().sensorSegment(input) >= 0 && last.sensorUsed(input);
    const std::string& frame = frames_.wrenchFrame(input);
    if (!frame.empty() && in.frame != frame) in.frame = frame;  // rare: a new frame
    const Eigen::Isometry3d& X = frames_.wrenchPose(input);
    in.residual = in.used
                      ? residualInReading(last.sensorResidual(input), X.linear(), X.translation())
                      : Wrench<double>();
    in.predicted = in.used
                       ? residualInReading(last.predictedWrench(input), X.linear(), X.translation())
                       : Wrench<double>();
  }
  for (std::size_t k = 0; k < rec.plates.size(); ++k) {
    PlateRecord& p = rec.plates[k];
    p.stale = last.plateStale(static_cast<int>(k));
    p.reading = last.plateReading(static_cast<int>(k));
    const std::string& frame = frames_.plateFrame(static_cast<int>(k));
    if (p.frame != frame) p.frame = frame;  // rare: a new frame
  }
  if (model_.floating_base) {
    rec.base_force = last.data().force[0];
    rec.base_moment = last.data().moment[0];
  }
}

void RecordBuilder::fillCoordinates(const Estimator& estimator, LoadsRecord& rec, std::size_t i,
                                    std::size_t segment) const {
  const Estimator::LastSample last = estimator.last();
  const Model<double>& m = model_;
  const int c = m.coordinate[segment];
  if (c < 0) return;  // a fixed joint kept as a segment: 0 from the constructor
  // As forwardKinematics maps them (a mimic joint follows its leader).
  const double k = m.multiplier[segment];
  rec.position[i] = k * last.q()[c] + m.offset[segment];
  rec.velocity[i] = k * last.qd()[c];
  rec.acceleration[i] = k * last.qdd()[c];
  if (!rec.motor_effort.empty())
    rec.motor_effort[i] =
        rec.effort[i] + frictionEffort(m.damping[segment], m.friction[segment], rec.velocity[i],
                                       settings_.friction.velocity_scale);
}

}  // namespace jle
