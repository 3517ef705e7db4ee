#include <joint_load_estimator/estimator.hpp>

#include <joint_load_estimator/kinematics.hpp>

#include <cmath>
#include <stdexcept>

namespace jle {
namespace {

constexpr int kWrenchHistory = 512;  // samples kept per wrench input for resampling

// Vector part of a quaternion product a * b.
Eigen::Vector3d productVector(const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
  // (w, x, y, z) layout.
  const Eigen::Vector3d av = a.tail<3>(), bv = b.tail<3>();
  return a[0] * bv + b[0] * av + av.cross(bv);
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

namespace {

// The model with the flags of the disabled savings set to "compute everything".
Model<double> withSavings(Model<double> model, const Savings& savings) {
  if (model.has_inertia.empty()) model.analyze();
  if (!savings.massless_chains) model.has_inertia.assign(model.has_inertia.size(), 1);
  if (!savings.gyroscopic) model.gyroscopic.assign(model.gyroscopic.size(), 1);
  return model;
}

}  // namespace

Estimator::Estimator(const Model<double>& model, const EstimatorConfig& config)
    : model_(withSavings(model, config.savings)),
      config_(config),
      data_(model_),
      model_f_(model_.cast<float>()),
      data_f_(model_f_),
      q_f_(VectorX<float>::Zero(model.nq)),
      qd_f_(VectorX<float>::Zero(model.nq)),
      qdd_f_(VectorX<float>::Zero(model.nq)),
      bank_(config.differentiator,
            model.nq + (model.floating_base ? 7 : 0) + 6 * static_cast<int>(config.wrenches.size()) +
                6 * static_cast<int>(config.plates.size())),
      q_(VectorX<double>::Zero(model.nq)),
      qd_(VectorX<double>::Zero(model.nq)),
      qdd_(VectorX<double>::Zero(model.nq)),
      cov_nominal_(model_) {
  validate(config_);  // what the model cannot tell; links and joints are checked below
  base_channel_ = model_.nq;
  wrench_channel_ = base_channel_ + (model_.floating_base ? 7 : 0);
  sensor_of_segment_.assign(static_cast<std::size_t>(model_.nsegments()), -1);
  for (const WrenchInputConfig& c : config_.wrenches) {
    Input input;
    input.config = c;
    if (!c.sensor_joint.empty()) {
      const std::string what = "wrench input '" + c.name + "': sensor_joint '" + c.sensor_joint + "'";
      int s = -1;
      try {
        s = model_.segmentOfJoint(c.sensor_joint);
      } catch (const std::invalid_argument&) {
        throw std::invalid_argument(what + " is not a joint kept as a segment (keep_fixed_joints)");
      }
      if (model_.joint_type[s] != JointType::kFixed)
        throw std::invalid_argument(what + " is not a fixed joint");
      if (c.link.empty()) input.config.link = model_.link_name[s];
      if (input.config.link != model_.link_name[s])
        throw std::invalid_argument(what + ": link must be its child link '" +
                                    model_.link_name[s] + "', not '" + c.link + "'");
      if (sensor_of_segment_[s] >= 0)
        throw std::invalid_argument(what + " has two sensor inputs");
      input.sensor_segment = s;
      sensor_of_segment_[s] = static_cast<int>(inputs_.size());
      have_sensors_ = true;
    }
    input.frame = model_.frameIndex(input.config.link);  // throws naming the link
    input.times.assign(kWrenchHistory, 0.0);
    input.values.assign(kWrenchHistory, Eigen::Matrix<double, 6, 1>::Zero());
    inputs_.push_back(input);
  }
  plate_channel_ = wrench_channel_ + 6 * static_cast<int>(inputs_.size());
  for (const PlateInputConfig& c : config_.plates) {
    Plate plate;
    plate.config = c;
    plate.filtered = c.plate;
    plate.filtered.contact_threshold = 0.0;
    const std::string what = "force plate '" + c.plate.name + "'";
    try {
      plate.input.frame = model_.frameIndex(c.plate.link);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(what + ": " + e.what());
    }
    plate.input.config.name = c.plate.name;
    plate.input.config.link = c.plate.link;
    plate.input.config.timeout = c.timeout;
    plate.input.config.stale_policy = c.stale_policy;
    plate.input.times.assign(kWrenchHistory, 0.0);
    plate.input.values.assign(kWrenchHistory, Eigen::Matrix<double, 6, 1>::Zero());
    plates_.push_back(plate);
    setPlatePose(static_cast<int>(plates_.size()) - 1, c.plate.R_world_plate, c.plate.p_world_plate);
  }
  channels_.assign(static_cast<std::size_t>(bank_.channels()), 0.0);
  last_inputs_.assign(channels_.size() * 3, 0.0);

  // What the wanted joints need: the subtrees below them (dynamics) and the paths
  // from the root to those (kinematics). A floating base's residual needs everything.
  const int n = model_.nsegments();
  std::vector<char> dyn(static_cast<std::size_t>(n), 0), kin(static_cast<std::size_t>(n), 0);
  if (config_.joints.empty() || model_.floating_base || !config_.savings.prune) {
    dyn.assign(dyn.size(), 1);
  } else {
    for (const std::string& j : config_.joints) dyn[model_.segmentOfJoint(j)] = 1;
    // A sensor's prediction needs its distal subtree, whatever is published.
    for (const Input& input : inputs_)
      if (input.sensor_segment >= 0) dyn[input.sensor_segment] = 1;
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
  prune_ = static_cast<int>(dynamics_segments_.size()) < n;
  for (Input& input : inputs_) input.needed = dyn[model_.frames[input.frame].segment] != 0;
  setUpCovariance();
  for (Plate& p : plates_) p.input.needed = dyn[model_.frames[p.input.frame].segment] != 0;

  // savings.planar: detected over the segments computed (a joint pruned away does not
  // matter); gravity is in the root frame, which is the world for a fixed base.
  if (config_.savings.planar == PlanarMode::kOff) {
    planar_reason_ = "savings.planar is off";
  } else if (config_.precision == Precision::kFloat) {
    planar_reason_ = "precision float keeps the 6x6 path";
  } else if (config_.uncertainty.enabled) {
    // The covariance reads the 3-D kinematics, which the planar path does not compute.
    planar_reason_ = "the covariance needs the 6x6 path";
  } else if (have_sensors_) {
    planar_reason_ = "a force/torque sensor at a joint needs the 6x6 path";
  } else if (!plates_.empty()) {
    planar_reason_ = "force plates need the 6x6 path (the feet's 3-D positions)";
  } else {
    const PlanarCheck<double> check = detectPlanar(model_, config_.gravity_world, kinematics_segments_);
    planar_ = check.planar;
    planar_reason_ = check.reason;
    if (!planar_ && config_.savings.planar == PlanarMode::kOn) {
      if (model_.floating_base || check.normal.isZero())
        throw std::invalid_argument("savings.planar is on but " + check.reason);
      planar_ = true;  // the user's assertion: out-of-plane parts are dropped
    }
    if (planar_) {
      planar_model_ = planarModel(model_, check.normal);
      planar_data_ = PlanarData<double>(n);
    }
  }
}

void Estimator::reset() {
  bank_.reset();
  cov_history_ = 0;
  for (Input& input : inputs_) {
    input.count = 0;
    input.head = 0;
    input.stale = true;
  }
  for (Plate& p : plates_) {
    p.input.count = 0;
    p.input.head = 0;
    p.input.stale = true;
    p.contact = false;
    p.reading = PlateReading();
  }
  have_last_ = false;
  have_result_ = false;
  sample_count_ = 0;
}

bool Estimator::addPlateSample(int k, double t, const Eigen::Vector3d& force_plate,
                               const Eigen::Vector3d& moment_plate) {
  Plate& plate = plates_.at(static_cast<std::size_t>(k));
  Input& input = plate.input;
  if (!std::isfinite(t) || !force_plate.allFinite() || !moment_plate.allFinite()) return false;
  if (input.count > 0) {
    const double newest = input.times[(input.head + kWrenchHistory - 1) % kWrenchHistory];
    if (!(t > newest)) return false;
  }
  // Below the threshold (noise, a foot above the plate): zero, so that the filters hold
  // no phantom load between contacts.
  const bool contact = readForcePlate(plate.config.plate, force_plate, moment_plate).contact;
  input.times[input.head] = t;
  if (contact)
    input.values[input.head] << force_plate, moment_plate;
  else
    input.values[input.head].setZero();
  input.head = (input.head + 1) % kWrenchHistory;
  if (input.count < kWrenchHistory) ++input.count;
  return true;
}

void Estimator::setPlatePose(int k, const Eigen::Matrix3d& R_world_plate,
                             const Eigen::Vector3d& p_world_plate) {
  Plate& plate = plates_.at(static_cast<std::size_t>(k));
  if (!R_world_plate.allFinite() || !p_world_plate.allFinite() ||
      !(std::abs(R_world_plate.determinant() - 1.0) < 1e-6) ||
      !R_world_plate.isUnitary(1e-6))
    throw std::invalid_argument("force plate '" + plate.config.plate.name +
                                "': the pose is not a finite rotation and position");
  plate.config.plate.R_world_plate = R_world_plate;
  plate.config.plate.p_world_plate = p_world_plate;
  plate.filtered.R_world_plate = R_world_plate;
  plate.filtered.p_world_plate = p_world_plate;
}

bool Estimator::updatePlateContacts() {
  bool changed = false;
  for (Plate& p : plates_) {
    bool contact = false;
    if (p.input.needed) {
      // The raw signal at the estimate's stamp (sampleInput's staleness belongs to the
      // newest joint sample: kept).
      const bool stale = p.input.stale;
      const Eigen::Matrix<double, 6, 1> raw = sampleInput(p.input, stamp_);
      p.input.stale = stale;
      const double normal = -raw[2];
      contact = normal >= p.config.plate.contact_threshold && normal > 0.0;
    }
    changed = changed || contact != p.contact;
    p.contact = contact;
  }
  return changed;
}

void Estimator::applyPlates() {
  for (std::size_t k = 0; k < plates_.size(); ++k) {
    Plate& p = plates_[k];
    p.reading = PlateReading();
    if (!p.input.needed || !p.contact) continue;
    const int c = plate_channel_ + 6 * static_cast<int>(k);
    const Eigen::Vector3d f(bank_.value(c), bank_.value(c + 1), bank_.value(c + 2));
    const Eigen::Vector3d m(bank_.value(c + 3), bank_.value(c + 4), bank_.value(c + 5));
    // In contact at the stamp; the filtered wrench still pressing into the plate.
    p.reading = readForcePlate(p.filtered, f, m);
    if (!p.reading.contact) continue;
    const Frame<double>& frame = model_.frames[static_cast<std::size_t>(p.input.frame)];
    const int s = frame.segment;
    Eigen::Vector3d foot_world;
    if (config_.precision == Precision::kFloat)
      foot_world = (data_f_.p_world[s] + data_f_.R_world[s] * frame.p_segment_frame.cast<float>())
                       .cast<double>();
    else
      foot_world = data_.p_world[s] + data_.R_world[s] * frame.p_segment_frame;
    Eigen::Vector3d force_world, moment_world;
    plateReactionInWorld(p.filtered, p.reading, foot_world, force_world, moment_world);
    if (config_.precision == Precision::kFloat)
      addExternalWrench(model_f_, data_f_, p.input.frame, Eigen::Vector3f(force_world.cast<float>()),
                        Eigen::Vector3f(moment_world.cast<float>()), WrenchFrame::kWorld);
    else
      addExternalWrench(model_, data_, p.input.frame, force_world, moment_world, WrenchFrame::kWorld);
  }
}

bool Estimator::addWrench(int k, double t, const Eigen::Vector3d& force,
                          const Eigen::Vector3d& moment) {
  Input& input = inputs_.at(static_cast<std::size_t>(k));
  if (!std::isfinite(t) || !force.allFinite() || !moment.allFinite()) return false;
  if (input.count > 0) {
    const double newest = input.times[(input.head + kWrenchHistory - 1) % kWrenchHistory];
    if (!(t > newest)) return false;
  }
  input.times[input.head] = t;
  input.values[input.head] << input.config.sign * force, input.config.sign * moment;
  input.head = (input.head + 1) % kWrenchHistory;
  if (input.count < kWrenchHistory) ++input.count;
  return true;
}

Eigen::Matrix<double, 6, 1> Estimator::sampleInput(Input& input, double t) {
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  auto at = [&](int k) { return (input.head - 1 - k + 2 * kWrenchHistory) % kWrenchHistory; };
  if (input.count == 0) {
    input.stale = true;
    return Vector6::Zero();
  }
  const int newest = at(0);
  if (t >= input.times[newest]) {
    input.stale = t - input.times[newest] > input.config.timeout;
    if (input.stale && input.config.stale_policy == StalePolicy::kZero) return Vector6::Zero();
    return input.values[newest];
  }
  input.stale = false;
  // Newest first: the bracketing pair is almost always the first or second.
  for (int k = 1; k < input.count; ++k) {
    const int older = at(k), newer = at(k - 1);
    if (input.times[older] <= t) {
      const double s = (t - input.times[older]) / (input.times[newer] - input.times[older]);
      return (1.0 - s) * input.values[older] + s * input.values[newer];
    }
  }
  return input.values[at(input.count - 1)];  // older than all we hold
}

SampleStatus Estimator::addJointSample(double t, const double* q, const BasePose* base) {
  if (model_.floating_base && base == nullptr)
    throw std::invalid_argument("a floating-base model needs the base pose with each sample");
  if (!std::isfinite(t)) return SampleStatus::kNonFinite;
  for (int i = 0; i < model_.nq; ++i)
    if (!std::isfinite(q[i])) return SampleStatus::kNonFinite;
  if (base && !(base->position.allFinite() && base->orientation.coeffs().allFinite() &&
                base->orientation.norm() > 0.0))
    return SampleStatus::kNonFinite;
  if (have_last_) {
    if (t == last_t_) return SampleStatus::kDuplicate;
    if (t < last_t_) return SampleStatus::kOutOfOrder;
  }
  have_last_ = true;
  last_t_ = t;

  for (int i = 0; i < model_.nq; ++i) channels_[static_cast<std::size_t>(i)] = q[i];
  if (model_.floating_base) {
    // Quaternion components are smooth in time once the sign is kept continuous.
    Eigen::Quaterniond o = base->orientation.normalized();
    if (o.coeffs().dot(last_orientation_.coeffs()) < 0.0) o.coeffs() *= -1.0;
    last_orientation_ = o;
    double* b = &channels_[static_cast<std::size_t>(base_channel_)];
    b[0] = base->position.x();
    b[1] = base->position.y();
    b[2] = base->position.z();
    b[3] = o.w();
    b[4] = o.x();
    b[5] = o.y();
    b[6] = o.z();
  }
  for (std::size_t k = 0; k < inputs_.size(); ++k) {
    if (!inputs_[k].needed) {  // pruned away: never stale, never read
      inputs_[k].stale = false;
      continue;
    }
    const Eigen::Matrix<double, 6, 1> w = sampleInput(inputs_[k], t);
    for (int j = 0; j < 6; ++j)
      channels_[static_cast<std::size_t>(wrench_channel_) + 6 * k + static_cast<std::size_t>(j)] = w[j];
  }
  for (std::size_t k = 0; k < plates_.size(); ++k) {
    Input& input = plates_[k].input;
    if (!input.needed) {
      input.stale = false;
      continue;
    }
    const Eigen::Matrix<double, 6, 1> w = sampleInput(input, t);
    for (int j = 0; j < 6; ++j)
      channels_[static_cast<std::size_t>(plate_channel_) + 6 * k + static_cast<std::size_t>(j)] = w[j];
  }
  // A gap restarts the bank inside update(); the decimation phase restarts with it.
  const bool ready = bank_.update(t, channels_.data());
  if (!ready) {
    sample_count_ = 0;
    cov_history_ = 0;  // the filter restarts: its noise gain too (uncertainty.period)
    return SampleStatus::kWarmingUp;
  }
  if (sample_count_++ % config_.decimation != 0) return SampleStatus::kDecimated;
  for (const Input& input : inputs_)
    if (input.stale && input.config.stale_policy == StalePolicy::kStop) return SampleStatus::kStale;
  for (const Plate& p : plates_)
    if (p.input.stale && p.config.stale_policy == StalePolicy::kStop) return SampleStatus::kStale;

  stamp_ = bank_.stamp();
  for (int i = 0; i < model_.nq; ++i) {
    q_[i] = bank_.value(i);
    qd_[i] = bank_.rate(i);
    qdd_[i] = bank_.accel(i);
  }
  BaseState<double> base_state;
  if (model_.floating_base) {
    const int b = base_channel_;
    base_state.p_world_base << bank_.value(b), bank_.value(b + 1), bank_.value(b + 2);
    base_state.v_world << bank_.rate(b), bank_.rate(b + 1), bank_.rate(b + 2);
    base_state.a_world << bank_.accel(b), bank_.accel(b + 1), bank_.accel(b + 2);
    Eigen::Vector4d quat, quat_rate, quat_accel;
    for (int j = 0; j < 4; ++j) {
      quat[j] = bank_.value(b + 3 + j);
      quat_rate[j] = bank_.rate(b + 3 + j);
      quat_accel[j] = bank_.accel(b + 3 + j);
    }
    const double norm = quat.norm();
    quat /= norm;
    quat_rate /= norm;
    quat_accel /= norm;
    const Eigen::Vector4d conj(quat[0], -quat[1], -quat[2], -quat[3]);
    // q' = 1/2 w q  =>  w = 2 vec(q' q*);  alpha = 2 vec(q'' q*) (the rest is scalar).
    base_state.omega_world = 2.0 * productVector(quat_rate, conj);
    base_state.alpha_world = 2.0 * productVector(quat_accel, conj);
    base_state.R_world_base =
        Eigen::Quaterniond(quat[0], quat[1], quat[2], quat[3]).toRotationMatrix();
  }

  const bool contacts_changed = updatePlateContacts();
  // Same filtered inputs as the last computation: same loads (exact by construction).
  reused_ = false;
  if (config_.savings.reuse_unchanged) {
    bool same = have_result_ && !contacts_changed;
    const std::size_t c = channels_.size();
    for (std::size_t i = 0; i < c && same; ++i)
      same = bank_.value(static_cast<int>(i)) == last_inputs_[i] &&
             bank_.rate(static_cast<int>(i)) == last_inputs_[c + i] &&
             bank_.accel(static_cast<int>(i)) == last_inputs_[2 * c + i];
    if (same) {
      reused_ = true;
      return SampleStatus::kPublished;
    }
    for (std::size_t i = 0; i < c; ++i) {
      last_inputs_[i] = bank_.value(static_cast<int>(i));
      last_inputs_[c + i] = bank_.rate(static_cast<int>(i));
      last_inputs_[2 * c + i] = bank_.accel(static_cast<int>(i));
    }
  }
  compute(base_state);
  have_result_ = true;
  return SampleStatus::kPublished;
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
  if (config_.precision == Precision::kFloat) {
    q_f_ = q_.cast<float>();
    qd_f_ = qd_.cast<float>();
    qdd_f_ = qdd_.cast<float>();
    BaseState<float> base_f;
    base_f.R_world_base = base_state.R_world_base.cast<float>();
    base_f.p_world_base = base_state.p_world_base.cast<float>();
    base_f.v_world = base_state.v_world.cast<float>();
    base_f.omega_world = base_state.omega_world.cast<float>();
    base_f.a_world = base_state.a_world.cast<float>();
    base_f.alpha_world = base_state.alpha_world.cast<float>();
    forwardKinematics(model_f_, data_f_, q_f_, qd_f_, qdd_f_,
                      Eigen::Vector3f(config_.gravity_world.cast<float>()), base_f,
                      kinematics_segments_, static_);
  } else {
    forwardKinematics(model_, data_, q_, qd_, qdd_, config_.gravity_world, base_state,
                      kinematics_segments_, static_);
  }
  for (std::size_t k = 0; k < inputs_.size(); ++k) {
    if (!inputs_[k].needed || inputs_[k].sensor_segment >= 0) continue;  // sensors: atSensor
    const int c = wrench_channel_ + 6 * static_cast<int>(k);
    const Eigen::Vector3d f(bank_.value(c), bank_.value(c + 1), bank_.value(c + 2));
    const Eigen::Vector3d m(bank_.value(c + 3), bank_.value(c + 4), bank_.value(c + 5));
    if (config_.precision == Precision::kFloat)
      addExternalWrench(model_f_, data_f_, inputs_[k].frame, Eigen::Vector3f(f.cast<float>()),
                        Eigen::Vector3f(m.cast<float>()), WrenchFrame::kLocal);
    else
      addExternalWrench(model_, data_, inputs_[k].frame, f, m, WrenchFrame::kLocal);
  }
  applyPlates();
  if (config_.precision == Precision::kFloat) {
    if (have_sensors_)
      inverseDynamics(model_f_, data_f_, dynamics_segments_,
                      [this](int i) { atSensor(data_f_, model_f_, i); });
    else
      inverseDynamics(model_f_, data_f_, dynamics_segments_);
    for (int i : dynamics_segments_) {
      data_.force[i] = data_f_.force[i].cast<double>();
      data_.moment[i] = data_f_.moment[i].cast<double>();
      data_.effort[i] = data_f_.effort[i];
    }
    for (int i : kinematics_segments_) {
      data_.R_world[i] = data_f_.R_world[i].cast<double>();
      data_.p_world[i] = data_f_.p_world[i].cast<double>();
    }
  } else if (have_sensors_) {
    inverseDynamics(model_, data_, dynamics_segments_, [this](int i) { atSensor(data_, model_, i); });
  } else {
    inverseDynamics(model_, data_, dynamics_segments_);
  }
  if (config_.uncertainty.enabled) computeCovariance(base_state);
}

template <typename Scalar>
void Estimator::atSensor(Data<Scalar>& data, const Model<Scalar>& model, int segment) {
  const int k = sensor_of_segment_[static_cast<std::size_t>(segment)];
  if (k < 0) return;
  Input& input = inputs_[static_cast<std::size_t>(k)];
  input.predicted.force = data.force[segment].template cast<double>();
  input.predicted.moment = data.moment[segment].template cast<double>();
  // A stale sensor read as zero would claim the distal side weighs nothing: unused.
  input.used = !(input.stale && input.config.stale_policy == StalePolicy::kZero);
  if (!input.used) return;
  // The filtered measurement, from the child link frame (identity for the segment's own
  // link, kept general) to the segment frame about the joint origin.
  const Wrench<double> w = appliedWrench(k);
  const Frame<Scalar>& fr = model.frames[static_cast<std::size_t>(input.frame)];
  const Eigen::Matrix<Scalar, 3, 1> f = fr.R_segment_frame * w.force.cast<Scalar>();
  data.force[segment] = f;
  data.moment[segment] = fr.R_segment_frame * w.moment.cast<Scalar>() + fr.p_segment_frame.cross(f);
}

Wrench<double> Estimator::sensorResidual(int k) const {
  const Input& input = inputs_.at(static_cast<std::size_t>(k));
  Wrench<double> r;
  if (input.sensor_segment < 0 || !input.used) return r;
  const int s = input.sensor_segment;
  r.force = data_.force[s] - input.predicted.force;
  r.moment = data_.moment[s] - input.predicted.moment;
  return r;
}

bool Estimator::computePlanar() {
  // kAuto: a filtered wrench with out-of-plane components sends this sample to the
  // 6x6 path (checked before any work); kOn drops those components.
  const bool check = config_.savings.planar == PlanarMode::kAuto;
  for (std::size_t k = 0; k < inputs_.size() && check; ++k) {
    if (!inputs_[k].needed) continue;
    const int c = wrench_channel_ + 6 * static_cast<int>(k);
    const Eigen::Vector3d f(bank_.value(c), bank_.value(c + 1), bank_.value(c + 2));
    const Eigen::Vector3d m(bank_.value(c + 3), bank_.value(c + 4), bank_.value(c + 5));
    if (!planarWrenchInPlane(planar_model_, inputs_[k].frame, f, m)) return false;
  }
  planarKinematics(model_, planar_model_, planar_data_, q_, qd_, qdd_, config_.gravity_world,
                   kinematics_segments_);
  for (std::size_t k = 0; k < inputs_.size(); ++k) {
    if (!inputs_[k].needed) continue;
    const int c = wrench_channel_ + 6 * static_cast<int>(k);
    const Eigen::Vector3d f(bank_.value(c), bank_.value(c + 1), bank_.value(c + 2));
    const Eigen::Vector3d m(bank_.value(c + 3), bank_.value(c + 4), bank_.value(c + 5));
    planarAddExternalWrench(model_, planar_model_, planar_data_, inputs_[k].frame, f, m);
  }
  planarInverseDynamics(model_, planar_model_, planar_data_, data_, dynamics_segments_);
  return true;
}

Wrench<double> Estimator::appliedWrench(int k) const {
  Wrench<double> w;
  const int c = wrench_channel_ + 6 * k;
  w.force << bank_.value(c), bank_.value(c + 1), bank_.value(c + 2);
  w.moment << bank_.value(c + 3), bank_.value(c + 4), bank_.value(c + 5);
  return w;
}

}  // namespace jle
