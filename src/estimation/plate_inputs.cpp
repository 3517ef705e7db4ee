#include <joint_load_estimator/estimation/plate_inputs.hpp>

#include <joint_load_estimator/estimation/estimator.hpp>  // PlateInputConfig

#include <cmath>
#include <stdexcept>
#include <string>

namespace jle {

PlateInputs::PlateInputs(const Model<double>& model, const std::vector<PlateInputConfig>& configs,
                         int first_channel) {
  for (const PlateInputConfig& c : configs) {
    Plate plate;
    plate.raw = c.plate;
    plate.filtered = c.plate;
    plate.filtered.contact_threshold = 0.0;
    const std::string what = "force plate '" + c.plate.name + "'";
    try {
      plate.frame = model.frameIndex(c.plate.link);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(what + ": " + e.what());
    }
    // timeout, contact_threshold, surface_height: validate(EstimatorConfig).
    plate.samples = InputBuffer(c.timeout, c.stale_policy);
    plate.channel = first_channel + 6 * size();
    plates_.push_back(plate);
    setPose(size() - 1, c.plate.R_world_plate, c.plate.p_world_plate);
  }
}

bool PlateInputs::add(int k, double t, const Eigen::Vector3d& force_plate,
                      const Eigen::Vector3d& moment_plate) {
  Plate& plate = plates_.at(static_cast<std::size_t>(k));
  InputBuffer::Vector6 value;
  value << force_plate, moment_plate;
  if (!value.allFinite()) return false;
  // Every sample enters the filters as measured: a force rising from zero at heel strike
  // is filtered like the kinematics, without a step at the threshold.
  return plate.samples.add(t, value);
}

void PlateInputs::setPose(int k, const Eigen::Matrix3d& R_world_plate,
                          const Eigen::Vector3d& p_world_plate) {
  Plate& plate = plates_.at(static_cast<std::size_t>(k));
  if (!R_world_plate.allFinite() || !p_world_plate.allFinite() ||
      !(std::abs(R_world_plate.determinant() - 1.0) < 1e-6) || !R_world_plate.isUnitary(1e-6))
    throw std::invalid_argument("force plate '" + plate.raw.name +
                                "': the pose is not a finite rotation and position");
  for (ForcePlateConfig* c : {&plate.raw, &plate.filtered}) {
    c->R_world_plate = R_world_plate;
    c->p_world_plate = p_world_plate;
  }
}

void PlateInputs::setNeeded(const Model<double>& model, const std::vector<char>& dynamics) {
  for (Plate& p : plates_)
    p.needed = dynamics[static_cast<std::size_t>(
                   model.frames[static_cast<std::size_t>(p.frame)].segment)] != 0;
}

bool PlateInputs::updateContacts(double stamp) {
  bool changed = false;
  for (Plate& p : plates_) {
    bool contact = false;
    InputBuffer::Vector6 value = InputBuffer::Vector6::Zero();
    if (p.needed) {
      // The raw signal at the estimate's stamp (the staleness of the newest joint sample
      // is kept).
      value = p.samples.valueAt(stamp);
      const double normal = -value[2];
      contact = normal >= p.raw.contact_threshold && normal > 0.0;
    }
    // Out of contact the raw value itself is applied: a new value is a new input.
    changed = changed || contact != p.contact || (!contact && value != p.raw_at_stamp);
    p.contact = contact;
    p.raw_at_stamp = value;
  }
  return changed;
}

void PlateInputs::reset() {
  for (Plate& p : plates_) {
    p.samples.reset();
    p.contact = false;
    p.raw_at_stamp.setZero();
    p.reading = PlateReading();
  }
}

}  // namespace jle
