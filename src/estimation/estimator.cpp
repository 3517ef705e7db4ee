// The orchestrator: the joint samples and the bank of filters, composed with the input
// buffers (input_buffer.hpp), the plates (plate_inputs.hpp), the sensor joints
// (sensor_joints.hpp), a floating base's channels (base_channels.hpp), the covariance
// (covariance.hpp) and the planar path (planar.hpp).
#include <joint_load_estimator/estimation/estimator.hpp>

#include <joint_load_estimator/model/kinematics.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace jle {
namespace {

// The model with the flags of the disabled savings set to "compute everything".
Model<double> withSavings(Model<double> model, const Savings& savings) {
  if (model.has_inertia.empty()) model.analyze();
  if (!savings.massless_chains) model.has_inertia.assign(model.has_inertia.size(), 1);
  if (!savings.gyroscopic) model.gyroscopic.assign(model.gyroscopic.size(), 1);
  return model;
}

// The bank's channels: q (nq), a floating base's pose (7), six per wrench input and
// six per plate.
int channelCount(const Model<double>& model, const EstimatorConfig& config) {
  return model.nq + (model.floating_base ? 7 : 0) + 6 * static_cast<int>(config.wrenches.size()) +
         6 * static_cast<int>(config.plates.size());
}

}  // namespace

const char* toString(SampleStatus status) {
  switch (status) {
    case SampleStatus::kPublished: return "published";
    case SampleStatus::kWarmingUp: return "warming up";
    case SampleStatus::kDecimated: return "decimated";
    case SampleStatus::kDuplicate: return "duplicate stamp";
    case SampleStatus::kOutOfOrder: return "out-of-order stamp";
    case SampleStatus::kNonFinite: return "non-finite value";
    case SampleStatus::kStale: return "stale wrench input";
  }
  return "?";
}

Estimator::SinglePrecision::SinglePrecision(const Model<double>& model_double)
    : model(model_double.cast<float>()),
      data(model),
      q(VectorX<float>::Zero(model_double.nq)),
      qd(VectorX<float>::Zero(model_double.nq)),
      qdd(VectorX<float>::Zero(model_double.nq)) {}

Estimator::Estimator(const Model<double>& model, const EstimatorConfig& config)
    : model_(withSavings(model, config.savings)),
      config_(config),
      data_(model_),
      single_(model_),
      bank_(config.differentiator, channelCount(model, config)),
      velocity_bank_(config.differentiator, model.nq),
      q_(VectorX<double>::Zero(model.nq)),
      qd_(VectorX<double>::Zero(model.nq)),
      qdd_(VectorX<double>::Zero(model.nq)),
      cov_nominal_(model_) {
  validate(config_);  // what the model cannot tell; links and joints are checked below
  base_channel_ = model_.nq;
  wrench_channel_ = base_channel_ + (model_.floating_base ? 7 : 0);
  setUpWrenchInputs();
  plates_ =
      PlateInputs(model_, config_.plates, wrench_channel_ + 6 * static_cast<int>(inputs_.size()));
  channels_.assign(static_cast<std::size_t>(bank_.channels()), 0.0);
  velocity_channels_.assign(static_cast<std::size_t>(model_.nq), 0.0);
  velocity_used_.assign(static_cast<std::size_t>(model_.nq), 0);
  bank_.chooseBandwidthFrom(model_.nq);  // the joints, not the base pose or the wrenches
  velocity_bank_.raiseOnly(true);
  held_.q.assign(static_cast<std::size_t>(model_.nq), 0.0);
  held_.qd.assign(static_cast<std::size_t>(model_.nq), 0.0);
  hold_inputs_ = config_.differentiator.lag > 0.0 && (!inputs_.empty() || plates_.size() > 0);
  last_inputs_.assign(channels_.size() * 3 + 2 * static_cast<std::size_t>(model_.nq), 0.0);
  const std::vector<char> dynamics = selectSegments();
  markNeeded(dynamics);
  setUpPlanar();
}

void Estimator::setUpWrenchInputs() {
  sensors_ = SensorJoints(model_.nsegments());
  for (const WrenchInputConfig& c : config_.wrenches) {
    WrenchInput input;
    input.channel = wrench_channel_ + 6 * static_cast<int>(inputs_.size());
    const int sensor_segment = sensors_.add(model_, c, input.channel);  // throws naming the input
    // A sensor's link is its joint's child link (sensors_ checked a non-empty one).
    const std::string& link = sensor_segment >= 0 ? model_.link_name[sensor_segment] : c.link;
    try {
      input.frame = model_.frameIndex(link);
    } catch (const std::invalid_argument&) {
      throw SettingsError("parameter 'wrenches[" + std::to_string(inputs_.size()) + "]/link': '" +
                          link + "' is not a link of the model");
    }
    input.sign = c.sign;
    input.samples = InputBuffer(c.timeout, c.stale_policy, c.max_hold);
    inputs_.push_back(input);
  }
}

std::vector<char> Estimator::selectSegments() {
  // What the wanted joints need: the subtrees below them (dynamics) and the paths
  // from the root to those (kinematics). A floating base's residual needs everything.
  const int n = model_.nsegments();
  std::vector<char> dyn(static_cast<std::size_t>(n), 0), kin(static_cast<std::size_t>(n), 0);
  if (config_.joints.empty() || model_.floating_base || !config_.savings.prune) {
    dyn.assign(dyn.size(), 1);
  } else {
    for (const std::string& j : config_.joints) dyn[model_.segmentOfJoint(j)] = 1;
    // A sensor's prediction needs its distal subtree, whatever is published.
    for (std::size_t k = 0; k < inputs_.size(); ++k)
      if (sensors_.segment(static_cast<int>(k)) >= 0)
        dyn[sensors_.segment(static_cast<int>(k))] = 1;
    for (int i = 1; i < n; ++i)
      if (dyn[model_.parent[i]]) dyn[i] = 1;
  }
  for (const std::string& j : config_.joints) model_.segmentOfJoint(j);  // names checked
  for (int i = n - 1; i >= 0; --i) {
    if (dyn[i]) kin[i] = 1;
    if (kin[i] && i > 0) kin[model_.parent[i]] = 1;
  }
  coordinate_needed_.assign(static_cast<std::size_t>(model_.nq), 0);
  for (int i = 0; i < n; ++i) {
    if (kin[i]) kinematics_segments_.push_back(i);
    if (dyn[i]) dynamics_segments_.push_back(i);
    if (kin[i] && model_.coordinate[i] >= 0) coordinate_needed_[model_.coordinate[i]] = 1;
  }
  return dyn;
}

void Estimator::markNeeded(const std::vector<char>& dynamics) {
  std::vector<int> input_frames;  // for the covariance: -1 where not needed
  for (WrenchInput& input : inputs_) {
    input.needed = dynamics[model_.frames[input.frame].segment] != 0;
    input_frames.push_back(input.needed ? input.frame : -1);
  }
  covariance_model_ = CovarianceModel(model_, config_.uncertainty, config_.wrenches, input_frames,
                                      kinematics_segments_, dynamics_segments_);
  covariance_ = CovarianceWorkspace(covariance_model_, model_.nsegments());
  plates_.setNeeded(model_, dynamics);
}

void Estimator::setUpPlanar() {
  // savings.planar: detected over the segments computed (a joint pruned away does not
  // matter); gravity is in the root frame, which is the world for a fixed base.
  if (config_.savings.planar == PlanarMode::kOff) {
    planar_reason_ = "savings/planar is off";
  } else if (config_.precision == Precision::kFloat) {
    planar_reason_ = "precision float keeps the 6x6 path";
  } else if (config_.uncertainty.enabled) {
    // The covariance reads the 3-D kinematics, which the planar path does not compute.
    planar_reason_ = "the covariance needs the 6x6 path";
  } else if (sensors_.any()) {
    planar_reason_ = "a force/torque sensor at a joint needs the 6x6 path";
  } else if (plates_.size() > 0) {
    planar_reason_ = "force plates need the 6x6 path (the feet's 3-D positions)";
  } else {
    const PlanarCheck<double> check =
        detectPlanar(model_, config_.gravity_world, kinematics_segments_);
    planar_ = check.planar;
    planar_reason_ = check.reason;
    if (!planar_ && config_.savings.planar == PlanarMode::kOn) {
      if (model_.floating_base || check.normal.isZero())
        throw std::invalid_argument("parameter 'savings/planar' is on but " + check.reason);
      planar_ = true;  // the user's assertion: out-of-plane parts are dropped
    }
    if (planar_) {
      planar_model_ = planarModel(model_, check.normal);
      planar_data_ = PlanarData<double>(model_.nsegments());
    }
  }
}

void Estimator::reset() {
  bank_.reset();
  velocity_bank_.reset();
  covariance_.history = 0;
  for (WrenchInput& input : inputs_) input.samples.reset();
  plates_.reset();
  have_last_ = false;
  have_result_ = false;
  sample_count_ = 0;
  velocities_open_ = true;
  holding_ = false;
}

bool Estimator::retune(const DifferentiatorConfig& differentiator, int decimation) {
  EstimatorConfig config = config_;
  config.differentiator = differentiator;
  config.decimation = decimation;
  validate(config);  // throws naming the key; nothing changed yet
  config_.decimation = decimation;
  if (sameDifferentiator(differentiator, config_.differentiator)) return true;
  bank_ = DifferentiatorBank(differentiator, bank_.channels());
  bank_.chooseBandwidthFrom(model_.nq);
  velocity_bank_ = DifferentiatorBank(differentiator, model_.nq);
  velocity_bank_.raiseOnly(true);
  config_.differentiator = differentiator;
  hold_inputs_ = differentiator.lag > 0.0 && (!inputs_.empty() || plates_.size() > 0);
  holding_ = false;
  covariance_.history = 0;
  have_last_ = false;
  have_result_ = false;
  sample_count_ = 0;
  velocities_open_ = true;
  return false;
}

bool Estimator::addPlateSample(int k, double t, const Eigen::Vector3d& force_plate,
                               const Eigen::Vector3d& moment_plate) {
  return plates_.add(k, t, force_plate, moment_plate);
}

void Estimator::setPlatePose(int k, const Eigen::Matrix3d& R_world_plate,
                             const Eigen::Vector3d& p_world_plate) {
  plates_.setPose(k, R_world_plate, p_world_plate);  // throws naming the plate
  ForcePlateConfig& plate = config_.plates[static_cast<std::size_t>(k)].plate;
  plate.R_world_plate = R_world_plate;
  plate.p_world_plate = p_world_plate;
}

bool Estimator::addWrench(int k, double t, const Eigen::Vector3d& force,
                          const Eigen::Vector3d& moment) {
  WrenchInput& input = inputs_.at(static_cast<std::size_t>(k));
  InputBuffer::Vector6 value;
  value << input.sign * force, input.sign * moment;
  return input.samples.add(t, value);
}

SampleStatus Estimator::addJointSample(double t, const double* q, const BasePose* base,
                                       const double* qd) {
  SampleStatus refused = SampleStatus::kPublished;
  if (!accept(t, q, base, refused)) return refused;
  if (velocities_open_) chooseVelocities(qd);
  if (!hold_inputs_) return feed(t, q, base, qd, 0.0);
  const SampleStatus status = holding_ ? feedHeld(t) : SampleStatus::kWarmingUp;
  hold(t, q, base, qd);
  return status;
}

SampleStatus Estimator::feed(double t, const double* q, const BasePose* base, const double* qd,
                             double half) {
  fillChannels(t, q, base, half);
  if (velocity_active_) {
    // The same filter at the same times as the positions': ready, restarted and delayed
    // alike (its result is read only when bank_'s is).
    fillVelocityChannels(t, qd);
    velocity_bank_.update(t, velocity_channels_.data());
  }
  // A gap restarts the bank inside update(); the decimation phase restarts with it.
  if (!bank_.update(t, channels_.data())) {
    sample_count_ = 0;
    covariance_.history = 0;  // the filter restarts: its noise gain too (uncertainty.period)
    return SampleStatus::kWarmingUp;
  }
  return publish();
}

void Estimator::hold(double t, const double* q, const BasePose* base, const double* qd) {
  held_.before = holding_ ? held_.t : -std::numeric_limits<double>::infinity();
  held_.t = t;
  std::copy(q, q + model_.nq, held_.q.begin());
  held_.has_qd = qd != nullptr;
  if (qd) std::copy(qd, qd + model_.nq, held_.qd.begin());
  held_.has_base = base != nullptr;
  if (base) held_.base = *base;
  holding_ = true;
}

// The held sample, its inputs read within half the shorter interval to its neighbours
// (next_t: the next sample's time; +inf at the end of a stream).
SampleStatus Estimator::feedHeld(double next_t) {
  holding_ = false;
  const double half = 0.5 * std::min(next_t - held_.t, held_.t - held_.before);
  return feed(held_.t, held_.q.data(), held_.has_base ? &held_.base : nullptr,
              held_.has_qd ? held_.qd.data() : nullptr, std::isfinite(half) ? half : 0.0);
}

bool Estimator::flush(SampleStatus& status) {
  if (holding_) {
    status = feedHeld(std::numeric_limits<double>::infinity());
    if (status != SampleStatus::kWarmingUp) return true;
  }
  bank_.finish();
  if (velocity_active_) velocity_bank_.finish();
  if (!bank_.next()) return false;
  if (velocity_active_) velocity_bank_.next();
  status = publish();
  return true;
}

bool Estimator::takeDue(SampleStatus& status) {
  if (!bank_.next()) return false;
  if (velocity_active_) velocity_bank_.next();  // due alike: the same times
  status = publish();
  return true;
}

// The loads of the bank's estimate (a sample taken now, or earlier for a delayed one).
inline SampleStatus Estimator::publish() {
  if (sample_count_++ % config_.decimation != 0) return SampleStatus::kDecimated;
  for (const WrenchInput& input : inputs_)
    if (input.samples.stopped()) return SampleStatus::kStale;
  if (plates_.stopped()) return SampleStatus::kStale;

  stamp_ = bank_.stamp();
  const BaseState<double> base_state = readEstimate();
  const bool contacts_changed = plates_.size() > 0 && plates_.updateContacts(stamp_);
  // Same filtered inputs as the last computation: same loads (exact by construction).
  reused_ = config_.savings.reuse_unchanged && sameFilteredInputs(contacts_changed);
  if (!reused_) {
    compute(base_state);
    have_result_ = true;
  }
  return SampleStatus::kPublished;
}

// The steps of addJointSample, inline in it (out of line they cost 2% of a still sample).
inline bool Estimator::accept(double t, const double* q, const BasePose* base,
                              SampleStatus& refused) {
  if (model_.floating_base && base == nullptr)
    throw std::invalid_argument("a floating-base model needs the base pose with each sample");
  refused = SampleStatus::kNonFinite;
  if (!std::isfinite(t)) return false;
  for (int i = 0; i < model_.nq; ++i)
    if (!std::isfinite(q[i])) return false;
  if (base && !(base->position.allFinite() && base->orientation.coeffs().allFinite() &&
                base->orientation.norm() > 0.0))
    return false;
  if (have_last_ && !(t > last_t_)) {
    refused = t == last_t_ ? SampleStatus::kDuplicate : SampleStatus::kOutOfOrder;
    return false;
  }
  have_last_ = true;
  last_t_ = t;
  return true;
}

inline void Estimator::fillChannels(double t, const double* q, const BasePose* base, double half) {
  for (int i = 0; i < model_.nq; ++i) channels_[static_cast<std::size_t>(i)] = q[i];
  if (model_.floating_base)
    writeBasePose(*base, last_orientation_, &channels_[static_cast<std::size_t>(base_channel_)]);
  for (WrenchInput& input : inputs_)
    input.samples.resample(t, input.needed, &channels_[static_cast<std::size_t>(input.channel)],
                           half);
  plates_.resample(t, channels_.data(), half);
}

// MeasuredVelocity: per coordinate, whether this first sample (after a start, a reset or a
// retune) brings a finite velocity; then held until the next such sample.
void Estimator::chooseVelocities(const double* qd) {
  velocities_open_ = false;
  const MeasuredVelocity mode = config_.measured_velocity;
  const bool auto_on = mode == MeasuredVelocity::kAuto && !config_.uncertainty.enabled;
  velocity_active_ = false;
  for (int i = 0; i < model_.nq; ++i) {
    const bool measured = qd != nullptr && std::isfinite(qd[i]);
    const bool used = mode == MeasuredVelocity::kAlways || (auto_on && measured);
    velocity_used_[static_cast<std::size_t>(i)] = used;
    velocity_active_ = velocity_active_ || used;
  }
}

// The velocity channels at time t [s]: the measured velocity, or where it is missing what
// the velocity filter predicts (no news: the estimate follows its model).
inline void Estimator::fillVelocityChannels(double t, const double* qd) {
  for (int i = 0; i < model_.nq; ++i) {
    const double v = qd != nullptr ? qd[i] : std::nan("");
    velocity_channels_[static_cast<std::size_t>(i)] =
        std::isfinite(v) ? v : velocity_bank_.predict(i, t);
  }
}

int Estimator::velocitiesUsed() const {
  int n = 0;
  for (char used : velocity_used_) n += used != 0;
  return n;
}

bool Estimator::velocitiesBetter() const {
  // The causal filter takes them wherever measured (accuracy study, the immediate default
  // with this rule: panda 0.049 -> 0.063 N m, the positions chosen over the velocities).
  if (!(config_.differentiator.lag > 0.0) || !config_.differentiator.auto_bandwidth) return true;
  double floor_q = bank_.noiseFloor(), floor_v = velocity_bank_.noiseFloor();
  if (!(bank_.spectralCutoff() > 0.0) || !(velocity_bank_.spectralCutoff() > 0.0)) {
    // Before the spectra's first choice (4 s), the probes' (0.5 s blocks); before theirs,
    // the positions (accuracy study, smoothed default + velocities / offline: panda_sines
    // 1.56 -> 1.32, talos 1.71 -> 1.41, with the velocities until the spectra's choice;
    // panda_stamp_jitter and arm_coloured_* kept at 1.09, 0.56, 1.19).
    if (!(bank_.probeCutoff() > 0.0) || !(velocity_bank_.probeCutoff() > 0.0)) return false;
    floor_q = bank_.probeFloor();
    floor_v = velocity_bank_.probeFloor();
    if (!(floor_q > 0.0) || !(floor_v > 0.0)) return true;  // a probe found none: no evidence
  }
  const double f = bank_.bandwidth();
  if (!(floor_q > 0.0)) return false;  // positions without noise: nothing is better
  const double w = 2.0 * M_PI * f;
  return floor_v < floor_q * w * w;
}

inline BaseState<double> Estimator::readEstimate() {
  const bool velocities = velocity_active_ && velocitiesBetter();
  for (int i = 0; i < model_.nq; ++i) {
    q_[i] = bank_.value(i);
    if (velocities && velocity_used_[static_cast<std::size_t>(i)]) {
      qd_[i] = velocity_bank_.value(i);
      qdd_[i] = velocity_bank_.rate(i);
    } else {
      qd_[i] = bank_.rate(i);
      qdd_[i] = bank_.accel(i);
    }
  }
  if (!model_.floating_base) return BaseState<double>();
  return baseStateFromBank(bank_, base_channel_);
}

inline bool Estimator::sameFilteredInputs(bool contacts_changed) {
  bool same = have_result_ && !contacts_changed;
  const std::size_t c = channels_.size();
  for (std::size_t i = 0; i < c && same; ++i)
    same = bank_.value(static_cast<int>(i)) == last_inputs_[i] &&
           bank_.rate(static_cast<int>(i)) == last_inputs_[c + i] &&
           bank_.accel(static_cast<int>(i)) == last_inputs_[2 * c + i];
  // The measured velocities' q-dot and q-ddot (qd_, qdd_ hold them; 0 where unused).
  const std::size_t v = 3 * c, nq = static_cast<std::size_t>(model_.nq);
  for (std::size_t i = 0; i < nq && same && velocity_active_; ++i)
    same = qd_[static_cast<int>(i)] == last_inputs_[v + i] &&
           qdd_[static_cast<int>(i)] == last_inputs_[v + nq + i];
  if (same) return true;
  for (std::size_t i = 0; i < c; ++i) {
    last_inputs_[i] = bank_.value(static_cast<int>(i));
    last_inputs_[c + i] = bank_.rate(static_cast<int>(i));
    last_inputs_[2 * c + i] = bank_.accel(static_cast<int>(i));
  }
  for (std::size_t i = 0; i < nq && velocity_active_; ++i) {
    last_inputs_[v + i] = qd_[static_cast<int>(i)];
    last_inputs_[v + nq + i] = qdd_[static_cast<int>(i)];
  }
  return false;
}

void Estimator::compute(const BaseState<double>& base_state) {
  // Quasi-static scene: below the user's thresholds the velocity terms are dropped.
  static_ = false;
  const Savings& sv = config_.savings;
  if (sv.static_velocity > 0.0 && sv.static_acceleration > 0.0 && !model_.floating_base) {
    static_ = true;
    for (int i = 0; i < model_.nq && static_; ++i)
      static_ = std::abs(qd_[i]) < sv.static_velocity && std::abs(qdd_[i]) < sv.static_acceleration;
    if (static_) {
      qd_.setZero();
      qdd_.setZero();
    }
  }
  last_planar_ = planar_ && computePlanar();
  if (last_planar_) return;
  if (config_.precision == Precision::kFloat)
    computeInFloat(base_state);
  else
    computeLoads(model_, data_, q_, qd_, qdd_, base_state);
  if (config_.uncertainty.enabled) updateCovariance(base_state);
}

template <typename Scalar>
void Estimator::computeLoads(const Model<Scalar>& model, Data<Scalar>& data,
                             const VectorX<Scalar>& q, const VectorX<Scalar>& qd,
                             const VectorX<Scalar>& qdd, const BaseState<Scalar>& base) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  const Vector3 gravity(config_.gravity_world.template cast<Scalar>());
  const bool all = static_cast<int>(dynamics_segments_.size()) == model.nsegments();
  if (all && !static_)  // every segment: the loops without the index lists
    localKinematics(model, data, q, qd, qdd, gravity, base);
  else
    localKinematics(model, data, q, qd, qdd, gravity, base, kinematics_segments_, static_);
  // World poses: only the force plates read them (the feet's positions).
  if (plates_.size() > 0) worldPoses(model, data, kinematics_segments_);
  for (std::size_t k = 0; k < inputs_.size(); ++k) {
    const WrenchInput& input = inputs_[k];
    if (!input.needed || sensors_.segment(static_cast<int>(k)) >= 0) continue;  // sensors: below
    const Wrench<double> w = filteredWrench(bank_, input.channel);
    addExternalWrench(model, data, input.frame, Vector3(w.force.template cast<Scalar>()),
                      Vector3(w.moment.template cast<Scalar>()), WrenchFrame::kLocal);
  }
  if (plates_.size() > 0) plates_.apply(model, data, bank_);
  if (!sensors_.any()) {
    if (all)
      inverseDynamics(model, data);
    else
      inverseDynamics(model, data, dynamics_segments_);
    return;
  }
  for (std::size_t k = 0; k < inputs_.size(); ++k)
    if (sensors_.segment(static_cast<int>(k)) >= 0)
      sensors_.setUsed(static_cast<int>(k), !inputs_[k].samples.zeroed());
  inverseDynamics(model, data, dynamics_segments_,
                  [&](int i) { sensors_.atSegment(data, model, i, bank_); });
}

void Estimator::computeInFloat(const BaseState<double>& base_state) {
  single_.q = q_.cast<float>();
  single_.qd = qd_.cast<float>();
  single_.qdd = qdd_.cast<float>();
  computeLoads(single_.model, single_.data, single_.q, single_.qd, single_.qdd,
               base_state.cast<float>());
  const Data<float>& d = single_.data;
  for (int i : dynamics_segments_) {
    data_.force[i] = d.force[i].cast<double>();
    data_.moment[i] = d.moment[i].cast<double>();
    data_.effort[i] = d.effort[i];
  }
  if (plates_.size() == 0) return;  // no world poses computed (computeLoads)
  for (int i : kinematics_segments_) {
    data_.R_world[i] = d.R_world[i].cast<double>();
    data_.p_world[i] = d.p_world[i].cast<double>();
  }
}

bool Estimator::computePlanar() {
  // kAuto: a filtered wrench with out-of-plane components sends this sample to the
  // 6x6 path (checked before any work); kOn drops those components.
  if (config_.savings.planar == PlanarMode::kAuto) {
    for (const WrenchInput& input : inputs_) {
      if (!input.needed) continue;
      const Wrench<double> w = filteredWrench(bank_, input.channel);
      if (!planarWrenchInPlane(planar_model_, input.frame, w.force, w.moment)) return false;
    }
  }
  planarKinematics(model_, planar_model_, planar_data_, q_, qd_, qdd_, config_.gravity_world,
                   kinematics_segments_);
  for (const WrenchInput& input : inputs_) {
    if (!input.needed) continue;
    const Wrench<double> w = filteredWrench(bank_, input.channel);
    planarAddExternalWrench(model_, planar_model_, planar_data_, input.frame, w.force, w.moment);
  }
  planarInverseDynamics(model_, planar_model_, planar_data_, data_, dynamics_segments_);
  return true;
}

void Estimator::updateCovariance(const BaseState<double>& base_state) {
  const Eigen::Matrix3d gain = bank_.noiseGain();
  if (extrapolateCovariance(covariance_model_, covariance_, gain, stamp_)) return;
  // The kinematics in double: data_ itself, or a double pass beside the float one.
  const bool single = config_.precision == Precision::kFloat;
  if (single) loadsPass(cov_nominal_, base_state);
  computeCovariance(covariance_model_, covariance_, model_, single ? cov_nominal_ : data_, gain,
                    stamp_);
}

void Estimator::loadsPass(Data<double>& data, const BaseState<double>& base_state) {
  forwardKinematics(model_, data, q_, qd_, qdd_, config_.gravity_world, base_state,
                    kinematics_segments_, false);
  for (const WrenchInput& input : inputs_) {
    if (!input.needed) continue;
    const Wrench<double> w = filteredWrench(bank_, input.channel);
    addExternalWrench(model_, data, input.frame, w.force, w.moment, WrenchFrame::kLocal);
  }
  inverseDynamics(model_, data, dynamics_segments_);
}

Wrench<double> Estimator::appliedWrench(int k) const {
  return filteredWrench(bank_, inputs_[static_cast<std::size_t>(k)].channel);
}

Wrench<double> Estimator::sensorResidual(int k) const { return sensors_.residual(k, data_); }

double Estimator::effortVariance(int segment) const {
  return jle::effortVariance(model_, covariance_.covariance[static_cast<std::size_t>(segment)],
                             segment);
}

}  // namespace jle
