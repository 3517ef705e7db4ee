// The ROS outputs of the external-effort estimator (external_effort/enabled): one
// geometry_msgs/WrenchStamped topic ~external_wrench/<link> per contact link, the latched
// ~contact event (joint_load_estimator/Contact) and the diagnostics' contact state. It
// only converts the Pipeline's record (LoadsRecord::contacts, in_contact, ...).
#pragma once

#include <joint_load_estimator/Contact.h>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/WrenchStamped.h>
#include <ros/ros.h>

#include <string>
#include <vector>

namespace jle {

/// The wrench of `contact` (link frame, moment about the link origin) as a message.
void toWrenchMessage(const ContactEstimate& contact, Stamp stamp,
                     geometry_msgs::WrenchStamped& msg);

/// Whether `record` is a contact event (~contact): its contact started, changed its joint
/// or ended at this sample.
inline bool isContactEvent(const LoadsRecord& record) {
  return record.contact_started || record.contact_changed || record.contact_ended;
}

/// The contact event of `record` as a message: its stamp, whether in contact, the
/// contact's joint and link, and the configured contacts whose wrench is reported
/// (ContactEstimate::active) while in contact. The node and process_bag publish it.
void toContactMessage(const LoadsRecord& record, joint_load_estimator::Contact& msg);

class ExternalOutputs {
 public:
  /// Advertises on `private_nh` for the record's contacts; nothing when `record` has no
  /// external effort (external_effort/enabled false).
  void advertise(ros::NodeHandle& private_nh, const LoadsRecord& record);
  /// After each published record.
  void publish(const LoadsRecord& record);
  /// WARN while in contact (naming the joint and link), and the contacts since the last call.
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

 private:
  bool enabled_ = false;
  std::vector<ros::Publisher> wrench_pubs_;
  ros::Publisher contact_pub_;
  geometry_msgs::WrenchStamped wrench_msg_;
  joint_load_estimator::Contact contact_msg_;
  bool in_contact_ = false;
  std::string joint_, link_;
  long contacts_ = 0;
  double worst_conditioning_ = 1.0;  // since the last diagnosis
};

}  // namespace jle
